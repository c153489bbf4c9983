// The side panel of the viewer (Dear ImGui): every setting, the results and the benchmark button.

#include "viewer.hpp"

#include <kdet/scenes.hpp>

#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace kdet::view {

namespace {

/// @brief Whether the panel lets @p option change under @p options: the hash is the grid's, the block
/// size the GPU's, the thread count the CPU's.
bool applies(const OptionInfo& option, const DetectorOptions& options) {
    const std::string name = option.name;
    if (name == "hash") return options.method == Method::kdet || options.method == Method::kdet_no_pairs;
    if (name == "block_size") return options.backend == Backend::cuda;
    if (name == "threads") return options.backend == Backend::cpu;
    return true;
}

/// @brief Whether this machine can run value @p index of a choice; @p reason says why not.
bool usable(const OptionInfo& option, long long index, std::string* reason) {
    return std::string(option.name) != "backend" || static_cast<Backend>(index) != Backend::cuda || cuda_available(reason);
}

/// @brief The widget of one option of the library's table: a combo box of a choice's names (those this
/// machine cannot run greyed out, the reason as a tooltip), an integer or real input, or a checkbox.
bool option_widget(const OptionInfo& option, DetectorOptions& options) {
    const long long current = option.get(options);
    switch (option.type) {
    case OptionType::choice: {
        bool changed = false;
        if (ImGui::BeginCombo(option.label, option.text(options).c_str())) {
            const std::vector<std::string>& names = option.names();
            for (long long i = 0; i < static_cast<long long>(names.size()); ++i) {
                std::string reason;
                const bool enabled = usable(option, i, &reason);
                const std::string& name = names[static_cast<std::size_t>(i)];
                if (ImGui::Selectable(name.c_str(), i == current, enabled ? 0 : ImGuiSelectableFlags_Disabled) && i != current) {
                    option.put(options, i);
                    changed = true;
                }
                if (!enabled && ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("%s", reason.c_str());
            }
            ImGui::EndCombo();
        }
        return changed;
    }
    case OptionType::boolean: {
        bool on = current != 0;
        if (!ImGui::Checkbox(option.label, &on)) return false;
        option.put(options, on);
        return true;
    }
    case OptionType::real: {
        float value = static_cast<float>(option.real(options));
        if (!ImGui::InputFloat(option.label, &value, 0.0f, 0.0f, "%g", ImGuiInputTextFlags_EnterReturnsTrue)) return false;
        if (!(value >= 0.0f) || !std::isfinite(value)) return false; // refused: the value stays
        option.set_real(options, value);
        return option.get(options) != current;
    }
    case OptionType::integer: break;
    }
    // An unset number (threads: OpenMP's default) shows as 0, and 0 sets it back.
    const bool unset = current < option.min || current > option.max;
    int value = unset ? 0 : static_cast<int>(current);
    if (!ImGui::InputInt(option.label, &value, 1, 16, ImGuiInputTextFlags_EnterReturnsTrue)) return false;
    if (value == 0 && option.unset_by_default()) {
        option.put(options, option.get(DetectorOptions{}));
    } else {
        const long long max = std::min<long long>(option.max, std::numeric_limits<int>::max());
        option.put(options, std::clamp<long long>(value, option.min, max));
    }
    return option.get(options) != current;
}

std::string mebibytes(std::size_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
    return text;
}

void row(const char* name, const std::string& value) {
    ImGui::TableNextRow();
    ImGui::TableSetColumnIndex(0);
    ImGui::TextUnformatted(name);
    ImGui::TableSetColumnIndex(1);
    ImGui::TextUnformatted(value.c_str());
}

void row(const char* name, std::uint64_t value) { row(name, std::to_string(value)); }

void row_ms(const char* name, double ms) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3f ms", ms);
    row(name, text);
}


} // namespace

void Viewer::draw_panel(float width, float height) {
    ImGui::SetNextWindowPos(ImVec2(0, 0));
    ImGui::SetNextWindowSize(ImVec2(width, height));
    ImGui::Begin("kdet view", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
    ImGui::PushItemWidth(-120.0f);
    if (!status_.empty() &&
        std::chrono::steady_clock::now() - status_time_ < std::chrono::seconds(8)) {
        ImGui::TextWrapped("%s", status_.c_str());
        ImGui::Separator();
    }
    panel_scene();
    panel_playback();
    panel_detection();
    panel_results();
    panel_selection();
    panel_display();
    panel_benchmark();
    if (ImGui::CollapsingHeader("Mouse and keys")) ImGui::TextWrapped("%s", controls_help());
    ImGui::PopItemWidth();
    ImGui::End();
}

void Viewer::panel_scene() {
    if (!ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const bool busy = bench_job_ != nullptr;
    ImGui::BeginDisabled(busy);
    ViewSource source = config_.source;
    const std::string current = source.meshes.empty() ? source.scene : session_.scene().name() + " (files)";
    if (ImGui::BeginCombo("scene", current.c_str())) {
        for (const std::string& name : scene_names()) {
            if (ImGui::Selectable(name.c_str(), source.meshes.empty() && name == source.scene)) {
                source.scene = name;
                source.meshes.clear();
                open_source(source);
            }
        }
        ImGui::EndCombo();
    }
    ImGui::InputTextWithHint("##path", ".scene, .kdetrec, folder or mesh", &open_path_);
    ImGui::SameLine();
    if (ImGui::Button("open") && !open_path_.empty()) {
        ViewSource opened = config_.source;
        opened.meshes.clear();
        if (names_a_scene(open_path_)) {
            opened.scene = open_path_;
        } else {
            opened.meshes = {open_path_};
        }
        open_source(opened);
    }
    if (source.meshes.empty() && source.scene == "procedural") {
        int tets = static_cast<int>(source.request.procedural.total_tets);
        ImGui::SliderInt("tets", &tets, 1000, 2000000, "%d", ImGuiSliderFlags_Logarithmic);
        if (ImGui::IsItemDeactivatedAfterEdit()) {
            source.request.procedural.total_tets = static_cast<std::size_t>(tets);
            open_source(source);
        }
        int frames = source.request.procedural.frames;
        ImGui::SliderInt("frames", &frames, 1, 600);
        if (ImGui::IsItemDeactivatedAfterEdit()) {
            source.request.procedural.frames = frames;
            open_source(source);
        }
    } else if (session_.scene().resolution() != 0 && session_.scene().resolution() == source.request.resolution) {
        // A scene built at the requested resolution follows it; one that fixes its own (the
        // pass-through scenes) or has none shows no slider.
        int resolution = source.request.resolution;
        ImGui::SliderInt("resolution", &resolution, 1, 4);
        if (ImGui::IsItemDeactivatedAfterEdit()) {
            source.request.resolution = resolution;
            open_source(source);
        }
    }
    // The order of SceneSelfCollision: none, every object, those the scene marks.
    static const char* const self_choices[] = {"none", "every object", "as the scene marks"};
    int self = static_cast<int>(session_.self());
    if (ImGui::Combo("self-collision", &self, self_choices, 3)) session_.set_self(static_cast<SceneSelfCollision>(self));
    ImGui::BeginDisabled(session_.self() == SceneSelfCollision::none);
    int rings = session_.exclusion_rings();
    ImGui::SliderInt("exclusion rings", &rings, 0, max_exclusion_rings);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("also leave out tets within this many mesh edges of each other (0: sharing a vertex)");
    if (ImGui::IsItemDeactivatedAfterEdit()) session_.set_exclusion_rings(rings);
    ImGui::EndDisabled();
    ImGui::EndDisabled();
    const Scene& scene = session_.scene();
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        const Color c = object_color(o);
        ImGui::PushID(static_cast<int>(o));
        ImGui::ColorButton("##color", ImVec4(c.r, c.g, c.b, 1.0f), ImGuiColorEditFlags_NoTooltip, ImVec2(12, 12));
        ImGui::SameLine();
        ImGui::Text("object %zu: %zu tets, %zu triangles", o, session_.mesh(o).num_tets(),
                    session_.faces()[o].boundary.size() / 3);
        const CollisionFilter filter = session_.collision_filter(o);
        if (filter.group != CollisionFilter{}.group || filter.mask != CollisionFilter{}.mask) {
            ImGui::SameLine();
            ImGui::Text("group 0x%x mask 0x%x", filter.group, filter.mask);
        }
        if (scene.is_static(o)) {
            ImGui::SameLine();
            bool is_static = session_.is_static(o);
            if (ImGui::Checkbox("static", &is_static)) session_.set_static(o, is_static);
        }
        ImGui::PopID();
    }
}

void Viewer::panel_playback() {
    if (session_.num_frames() <= 1 || !ImGui::CollapsingHeader("Playback", ImGuiTreeNodeFlags_DefaultOpen)) return;
    ImGui::BeginDisabled(bench_job_ != nullptr);
    if (ImGui::Button(playing_ ? "pause" : "play", ImVec2(60, 0))) playing_ = !playing_;
    ImGui::SameLine();
    if (ImGui::ArrowButton("##back", ImGuiDir_Left)) {
        playing_ = false;
        session_.set_frame(session_.frame() - 1);
    }
    ImGui::SameLine();
    if (ImGui::ArrowButton("##forward", ImGuiDir_Right)) {
        playing_ = false;
        session_.set_frame(session_.frame() + 1);
    }
    ImGui::SameLine();
    ImGui::Checkbox("loop", &loop_);
    int frame = session_.frame();
    if (ImGui::SliderInt("frame", &frame, 0, session_.num_frames() - 1)) session_.set_frame(frame);
    ImGui::EndDisabled();
}

void Viewer::panel_detection() {
    if (!ImGui::CollapsingHeader("Detection", ImGuiTreeNodeFlags_DefaultOpen)) return;
    ImGui::BeginDisabled(bench_job_ != nullptr);
    DetectorOptions o = session_.options();
    bool changed = false;
    for (const OptionInfo& option : option_table()) {
        if (!option.shown_on(front_end_panel)) continue;
        ImGui::BeginDisabled(!applies(option, o));
        changed |= option_widget(option, o);
        if (*option.help && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", option.help);
        ImGui::EndDisabled();
    }
    if (changed) apply(o);
    ImGui::EndDisabled();
}

void Viewer::panel_display() {
    if (!ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) return;
    DisplaySettings& d = config_.display;
    ImGui::SliderFloat("surface opacity", &d.surface_opacity, 0.0f, 1.0f, "%.2f");
    ImGui::Checkbox("colliding tets only (H)", &d.only_colliding);
    ImGui::Checkbox("wireframe (W)", &d.wireframe);
    ImGui::Checkbox("clipping plane (C)", &d.clip);
    if (d.clip) {
        ImGui::RadioButton("x", &d.clip_axis, 0);
        ImGui::SameLine();
        ImGui::RadioButton("y", &d.clip_axis, 1);
        ImGui::SameLine();
        ImGui::RadioButton("z", &d.clip_axis, 2);
        ImGui::SameLine();
        ImGui::Checkbox("flip", &d.clip_flip);
        ImGui::SliderFloat("plane", &d.clip_position, 0.0f, 1.0f, "%.2f");
    }
    ImGui::Checkbox("contact normals (N)", &d.contact_normals);
    if (d.contact_normals) {
        ImGui::SliderFloat("normal length", &d.normal_length, 0.1f, 5.0f, "%.1f");
        ImGui::TextDisabled("%zu of %zu pairs", renderer_->contact_lines(), session_.result().pairs.size());
    }
    if (ImGui::Button("reset camera (R)")) {
        config_.camera = CameraRequest{};
        reset_camera(scene_aspect());
    }
    ImGui::SameLine();
    if (ImGui::Button("screenshot (P)")) screenshot_requested_ = true;
}

void Viewer::panel_results() {
    if (!ImGui::CollapsingHeader("Results", ImGuiTreeNodeFlags_DefaultOpen)) return;
    if (!session_.has_result()) {
        ImGui::TextDisabled("no detection yet");
        return;
    }
    const FrameResult& r = session_.result();
    const FrameCounts& c = r.counts;
    const StageTimes& t = r.times;
    if (ImGui::BeginTable("counts", 2, ImGuiTableFlags_SizingStretchProp)) {
        row("candidates", c.candidates);
        row("to narrow phase", c.narrow_phase_candidates);
        row("colliding pairs", session_.options().method == Method::kdet_no_pairs ? std::string("(tets only)")
                                                                                   : std::to_string(c.colliding_pairs));
        row("colliding tets", c.colliding_tets);
        if (session_.options().margin > 0.0f) {
            row("  overlapping pairs (red)", c.colliding_pairs - session_.margin_pairs());
            row("  within the margin only (yellow)", session_.margin_pairs());
        }
        row("buffer regrows", c.buffer_regrows);
        row("host waits", c.host_waits);
        if (!session_.points().empty()) {
            const PointCounts points = count_points(session_.located());
            row("points in a tet (white)", points.held);
            row("points near one (orange)", points.near);
            row("points without (magenta)", points.missed);
        }
        row_ms("boxes", t.bounding_boxes);
        row_ms("populate grid", t.populate_grid);
        row_ms("find candidates", t.find_candidates);
        row_ms("sort pairs", t.sort_pairs);
        row_ms("narrow phase", t.narrow_phase);
        row_ms("detect() total", t.total);
        if (draw_measured_) {
            row_ms("drawing", last_draw_ms_);
        } else {
            row("drawing", "not measured yet");
        }
        row("detector memory", mebibytes(r.memory_bytes));
        row("  grid / candidates", mebibytes(r.grid_bytes) + " / " + mebibytes(r.candidate_bytes));
        row("process memory", mebibytes(resident_bytes()));
        row("vertex buffers", mebibytes(renderer_->stats().bytes));
        ImGui::EndTable();
    }
    if (history_.count > 0) {
        // Both plots share one scale, so that their heights compare.
        const float most = std::max(*std::max_element(history_.detect_ms.begin(), history_.detect_ms.end()),
                                    *std::max_element(history_.draw_ms.begin(), history_.draw_ms.end()));
        const ImVec2 size(ImGui::GetContentRegionAvail().x, 56.0f);
        // The ring holds the newest `count` values; until it is full they start at 0.
        const int offset = history_.count < History::size ? 0 : history_.next;
        char label[64];
        std::snprintf(label, sizeof label, "detect() %.2f ms", t.total);
        ImGui::PlotLines("##detect", history_.detect_ms.data(), history_.count, offset, label, 0.0f,
                         std::max(most, 1.0f) * 1.1f, size);
        std::snprintf(label, sizeof label, "drawing %.2f ms", static_cast<double>(last_draw_ms_));
        ImGui::PlotLines("##draw", history_.draw_ms.data(), history_.count, offset, label, 0.0f,
                         std::max(most, 1.0f) * 1.1f, size);
    }
}

void Viewer::panel_selection() {
    if (!ImGui::CollapsingHeader("Selected tet (click one)", ImGuiTreeNodeFlags_DefaultOpen)) return;
    if (!selected_) {
        ImGui::TextDisabled("nothing selected");
        return;
    }
    const TetRef s = *selected_;
    const FrameResult& r = session_.result();
    const bool colliding = s.object < r.colliding.size() && s.tet < r.colliding[s.object].size() && r.colliding[s.object][s.tet];
    ImGui::Text("object %u, tet %u: %s", s.object, s.tet, colliding ? "colliding" : "not colliding");
    if (session_.options().method == Method::kdet_no_pairs) {
        ImGui::TextDisabled("kdet_no_pairs flags tets and builds no pairs");
    } else if (colliding) {
        ImGui::TextWrapped("collides with %zu tet(s) (teal)", partners_.size());
        constexpr std::size_t listed = 8;
        for (std::size_t k = 0; k < partners_.size() && k < listed; ++k) {
            const Partner& p = partners_[k];
            ImGui::Text("  object %u, tet %u", p.tet.object, p.tet.tet);
            if (p.has_contact)
                ImGui::TextDisabled("    depth %.3g along (%.2f, %.2f, %.2f)", static_cast<double>(p.contact.depth),
                                    static_cast<double>(p.contact.direction[0]), static_cast<double>(p.contact.direction[1]),
                                    static_cast<double>(p.contact.direction[2]));
        }
        if (partners_.size() > listed) ImGui::TextDisabled("and %zu more", partners_.size() - listed);
    }
    if (ImGui::Button("frame it")) {
        std::vector<TetRef> tets = {s};
        for (const Partner& p : partners_) tets.push_back(p.tet);
        const std::vector<std::vector<float>> points(1, vertices_of(session_, tets));
        camera_.frame(points, scene_aspect());
    }
    ImGui::SameLine();
    if (ImGui::Button("clear")) {
        selected_.reset();
        selection_version_ = 0;
    }
}

void Viewer::panel_benchmark() {
    if (!ImGui::CollapsingHeader("Benchmark")) return;
    ImGui::BeginDisabled(bench_job_ != nullptr);
    ImGui::SliderInt("runs", &bench_runs_, 1, 20);
    ImGui::InputText("folder", &bench_dir_);
    if (ImGui::Button("run benchmark")) {
        playing_ = false;
        bench_outcome_.clear();
        bench_job_ = std::make_unique<BenchJob>(session_.source(), bench_config_of(session_, bench_runs_, bench_dir_));
    }
    ImGui::EndDisabled();
    ImGui::PushTextWrapPos(0.0f);
    ImGui::TextDisabled("every frame, %d run(s), no drawing; the CSV files of kdet bench", bench_runs_);
    ImGui::PopTextWrapPos();
    if (bench_job_) {
        ImGui::ProgressBar(bench_job_->progress());
        if (ImGui::Button("stop")) bench_job_->stop();
    } else if (!bench_outcome_.empty()) {
        ImGui::TextWrapped("%s", bench_outcome_.c_str());
    }
}

} // namespace kdet::view
