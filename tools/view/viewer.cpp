#include "viewer.hpp"

#include "png_file.hpp"

#include <kdet/error.hpp>

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace kdet::view {

namespace {

constexpr float panel_width = 390.0f;
/// Pixels from a query point within which a click selects it rather than a tet.
constexpr float point_pick_radius = 6.0f;

std::string glfw_error;

void remember_glfw_error(int, const char* description) { glfw_error = description ? description : "unknown error"; }

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

Bounds bounds_of(const ViewSession& session) {
    Bounds box;
    for (const std::vector<float>& xyz : session.positions()) box.add(xyz);
    return box;
}

double median(std::vector<double> values) {
    if (values.empty()) return 0;
    std::sort(values.begin(), values.end());
    return values[values.size() / 2];
}

} // namespace

bool wants_contacts(const DisplaySettings& display, bool tet_selected) {
    return display.contact_normals || tet_selected;
}

void Viewer::History::add(float detect, float draw) {
    detect_ms[static_cast<std::size_t>(next)] = detect;
    draw_ms[static_cast<std::size_t>(next)] = draw;
    next = (next + 1) % size;
    count = std::min(count + 1, size);
}

Viewer::Viewer(ViewSession& session, const ViewConfig& config, bool visible) : session_(session), config_(config) {
    glfwSetErrorCallback(remember_glfw_error);
    if (!glfwInit())
        throw Error("view: cannot open a window: " + glfw_error +
                    " (no display? `xvfb-run -a kdet view ...` draws without one)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_SAMPLES, visible && config.samples > 1 ? config.samples : 0);
    const std::string title = "kdet view - " + session.scene().name();
    window_ = glfwCreateWindow(config.width, config.height, title.c_str(), nullptr, nullptr);
    if (!window_) {
        glfwTerminate();
        throw Error("view: cannot create an OpenGL 3.3 window: " + glfw_error);
    }
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(1);
    if (epoxy_gl_version() < 33) {
        glfwDestroyWindow(window_);
        glfwTerminate();
        throw Error("view: OpenGL 3.3 is needed, the driver gives " + std::to_string(epoxy_gl_version() / 10) + "." +
                    std::to_string(epoxy_gl_version() % 10));
    }
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr; // no imgui.ini in the user's folder
    ImGui::StyleColorsDark();
    ImGuiStyle& style = ImGui::GetStyle();
    style.WindowRounding = 0.0f;
    style.FrameRounding = 3.0f;
    style.GrabRounding = 3.0f;
    style.WindowBorderSize = 0.0f;
    // Installed before ImGui's, which calls it first.
    glfwSetWindowUserPointer(window_, this);
    glfwSetKeyCallback(window_, on_key);
    ImGui_ImplGlfw_InitForOpenGL(window_, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
    renderer_ = std::make_unique<Renderer>();
    session_.set_frame(config.frame);
}

Viewer::~Viewer() {
    bench_job_.reset();
    renderer_.reset();
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    glfwDestroyWindow(window_);
    glfwTerminate();
}

float Viewer::scene_aspect() const {
    int width = 0, height = 0;
    glfwGetWindowSize(window_, &width, &height);
    const float scene_width = static_cast<float>(width) - (panel_shown_ ? panel_width : 0.0f);
    return std::max(scene_width, 1.0f) / static_cast<float>(std::max(height, 1));
}

void Viewer::reset_camera(float aspect) {
    camera_.set_angles(config_.camera.angles_given ? config_.camera.yaw : OrbitCamera::default_yaw,
                       config_.camera.angles_given ? config_.camera.pitch : OrbitCamera::default_pitch);
    scene_box_ = bounds_of(session_);
    camera_.frame(session_.positions(), aspect);
    camera_.zoom(config_.camera.zoom);
}

void Viewer::frame_colliding(float aspect) {
    const std::vector<std::vector<float>> points(1, vertices_of(session_, colliding_tets(session_)));
    if (points[0].empty()) {
        set_status("nothing collides in this frame");
        return;
    }
    camera_.frame(points, aspect);
}

void Viewer::set_status(const std::string& text) {
    status_ = text;
    status_time_ = std::chrono::steady_clock::now();
}

void Viewer::apply(const DetectorOptions& options) {
    DetectorOptions o = options;
    o.contacts = wants_contacts(config_.display, selected_.has_value());
    session_.set_options(o);
    config_.options = o;
}

void Viewer::sync_contacts() {
    const bool wanted = wants_contacts(config_.display, selected_.has_value());
    if (session_.options().contacts != wanted) {
        DetectorOptions o = session_.options();
        o.contacts = wanted;
        apply(o);
    }
}

void Viewer::open_source(const ViewSource& source) {
    try {
        session_.open(source);
        selected_.reset();
        config_.source = source;
        session_.update();
        reset_camera(scene_aspect());
        glfwSetWindowTitle(window_, ("kdet view - " + session_.scene().name()).c_str());
        set_status("opened " + session_.scene().name());
    } catch (const std::exception& e) {
        set_status(std::string("cannot open: ") + e.what());
    }
}

void Viewer::on_key(GLFWwindow* window, int key, int, int action, int) {
    auto* viewer = static_cast<Viewer*>(glfwGetWindowUserPointer(window));
    if (!viewer || action == GLFW_RELEASE || ImGui::GetIO().WantCaptureKeyboard) return;
    // Only the frame steps repeat while the key is held.
    if (action == GLFW_REPEAT && key != GLFW_KEY_LEFT && key != GLFW_KEY_RIGHT) return;
    viewer->pending_keys_.push_back(key);
}

void Viewer::handle_key(int key) {
    switch (key) {
    case GLFW_KEY_SPACE:
        playing_ = !playing_ && session_.num_frames() > 1;
        break;
    case GLFW_KEY_RIGHT:
    case GLFW_KEY_LEFT:
        playing_ = false;
        session_.set_frame(session_.frame() + (key == GLFW_KEY_RIGHT ? 1 : -1));
        break;
    case GLFW_KEY_R:
        config_.camera = CameraRequest{};
        reset_camera(scene_aspect());
        break;
    case GLFW_KEY_F:
        frame_colliding(scene_aspect());
        break;
    case GLFW_KEY_P:
        screenshot_requested_ = true;
        break;
    case GLFW_KEY_W:
        config_.display.wireframe = !config_.display.wireframe;
        break;
    case GLFW_KEY_C:
        config_.display.clip = !config_.display.clip;
        break;
    case GLFW_KEY_H:
        config_.display.only_colliding = !config_.display.only_colliding;
        break;
    case GLFW_KEY_N:
        config_.display.contact_normals = !config_.display.contact_normals;
        break;
    case GLFW_KEY_TAB:
        panel_shown_ = !panel_shown_;
        break;
    case GLFW_KEY_ESCAPE:
        glfwSetWindowShouldClose(window_, GLFW_TRUE);
        break;
    default:
        break;
    }
}

void Viewer::handle_click(int scene_x, int scene_width, int scene_height) {
    const ImGuiIO& io = ImGui::GetIO();
    if (io.WantCaptureMouse || !io.MouseReleased[0] || io.MouseDragMaxDistanceSqr[0] > 16.0f) return;
    const float x = io.MousePos.x - static_cast<float>(scene_x), y = io.MousePos.y;
    selected_point_ = pick_point(session_, camera_, x, y, scene_width, scene_height, point_pick_radius);
    if (selected_point_)
        selected_.reset();
    else
        selected_ = pick_tet(session_, camera_, x, y, scene_width, scene_height, config_.display, scene_box_);
    selection_version_ = 0;
    selection_topology_ = session_.topology_version();
}

void Viewer::handle_input(int scene_height) {
    for (const int key : pending_keys_) handle_key(key);
    pending_keys_.clear();
    const ImGuiIO& io = ImGui::GetIO();
    if (io.WantCaptureMouse) return;
    const bool pan = io.MouseDown[1] || io.MouseDown[2] || (io.MouseDown[0] && io.KeyShift);
    if (pan) {
        camera_.pan(io.MouseDelta.x, io.MouseDelta.y, scene_height);
    } else if (io.MouseDown[0]) {
        camera_.orbit(io.MouseDelta.x, io.MouseDelta.y, scene_height);
    }
    if (io.MouseWheel != 0.0f) camera_.zoom(std::pow(0.88f, io.MouseWheel));
}

void Viewer::build_ui(int width, int height, bool with_panel) {
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGuiIO& io = ImGui::GetIO();
    // Off-screen pictures have their own size, whatever the hidden window's.
    io.DisplaySize = ImVec2(static_cast<float>(width), static_cast<float>(height));
    io.DisplayFramebufferScale = ImVec2(1.0f, 1.0f);
    ImGui::NewFrame();
    if (with_panel) draw_panel(panel_width, static_cast<float>(height));
}

void Viewer::run() {
    session_.update();
    reset_camera(scene_aspect());
    if (config_.camera.focus_colliding) frame_colliding(scene_aspect());
    while (!glfwWindowShouldClose(window_)) {
        // Sleep until something happens unless an animation or a benchmark is running.
        if (bench_job_) {
            glfwWaitEventsTimeout(0.1);
        } else if (playing_) {
            glfwPollEvents();
        } else {
            glfwWaitEventsTimeout(0.5);
        }
        int window_width = 0, window_height = 0, fb_width = 0, fb_height = 0;
        glfwGetWindowSize(window_, &window_width, &window_height);
        glfwGetFramebufferSize(window_, &fb_width, &fb_height);
        if (fb_width == 0 || fb_height == 0) continue; // minimised
        const float scale = static_cast<float>(fb_width) / static_cast<float>(std::max(window_width, 1));

        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        if (panel_shown_) draw_panel(panel_width, static_cast<float>(window_height));
        const int scene_x = panel_shown_ ? static_cast<int>(panel_width) : 0;
        handle_input(window_height);
        handle_click(scene_x, window_width - scene_x, window_height);
        ImGui::Render();

        if (bench_job_ && bench_job_->finished()) {
            bench_outcome_ = bench_job_->outcome();
            set_status(bench_outcome_);
            bench_job_.reset();
        }
        if (playing_ && !bench_job_) {
            int next = session_.frame() + 1;
            if (next >= session_.num_frames()) {
                next = 0;
                if (!loop_) playing_ = false;
            }
            if (playing_) session_.set_frame(next);
        }
        // The benchmark has the processor to itself: the view keeps its last frame meanwhile.
        if (!bench_job_) sync_contacts();
        const bool computed = !bench_job_ && session_.update();
        renderer_->update(session_);
        if (selection_version_ != session_.result_version()) {
            // The selection follows its tet through the frames; a new scene drops it, and so do new tets
            // (a tear numbers them anew).
            if (selected_ && (selected_->object >= session_.scene().num_objects() ||
                              session_.topology_version() != selection_topology_))
                selected_.reset();
            partners_ = selected_ ? partners_of(session_.result(), *selected_) : std::vector<Partner>{};
            std::vector<TetRef> shown;
            if (selected_) shown.push_back(*selected_);
            for (const Partner& p : partners_) shown.push_back(p.tet);
            renderer_->select(session_, shown);
            if (selected_point_ && *selected_point_ >= session_.located().point_count) selected_point_.reset();
            renderer_->select_point(session_, selected_point_);
            selection_version_ = session_.result_version();
        }

        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, fb_width, fb_height);
        glClearColor(0.09f, 0.09f, 0.10f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        // Drawing is timed to its end (glFinish), which also keeps a software renderer from running
        // beside the next detection.
        const auto draw_start = std::chrono::steady_clock::now();
        const int fb_scene_x = static_cast<int>(static_cast<float>(scene_x) * scale);
        renderer_->draw(camera_, fb_scene_x, 0, fb_width - fb_scene_x, fb_height, config_.display, scene_box_);
        glFinish();
        last_draw_ms_ = static_cast<float>(milliseconds_since(draw_start));
        draw_measured_ = true;
        if (computed) history_.add(static_cast<float>(session_.detect_ms()), last_draw_ms_);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        if (screenshot_requested_) {
            screenshot_requested_ = false;
            save_window_screenshot(fb_width, fb_height);
        }
        glfwSwapBuffers(window_);
    }
}

void Viewer::save_window_screenshot(int width, int height) {
    const std::string stem = "kdet-" + session_.scene().name() + "-frame" + std::to_string(session_.frame());
    std::string path = stem + ".png";
    for (int n = 2; std::filesystem::exists(path); ++n) path = stem + "-" + std::to_string(n) + ".png";
    try {
        glReadBuffer(GL_BACK);
        write_png(path, width, height, read_framebuffer_rgb(0, 0, width, height));
        set_status("saved " + path);
        std::printf("kdet view: saved %s\n", path.c_str());
        std::fflush(stdout);
    } catch (const Error& e) {
        set_status(e.what());
    }
}

void Viewer::screenshot(const std::string& path, int width, int height, bool with_panel) {
    sync_contacts();
    session_.update();
    renderer_->update(session_);
    const int scene_x = with_panel ? static_cast<int>(panel_width) : 0;
    const float aspect = static_cast<float>(width - scene_x) / static_cast<float>(height);
    reset_camera(aspect);
    if (config_.camera.focus_colliding) frame_colliding(aspect);
    OffscreenTarget target(width, height, config_.samples);
    if (with_panel) {
        // ImGui sizes its windows from what they held the frame before: let it settle first.
        for (int warm_up = 0; warm_up < 3; ++warm_up) {
            build_ui(width, height, true);
            ImGui::Render();
        }
        build_ui(width, height, true);
        ImGui::Render();
    }
    target.bind();
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    renderer_->draw(camera_, scene_x, 0, width - scene_x, height, config_.display, scene_box_);
    if (with_panel) ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    write_png(path, width, height, target.read_rgb());
}

void Viewer::profile(int width, int height) {
    OffscreenTarget target(width, height, config_.samples);
    session_.set_frame(0);
    sync_contacts();
    session_.update();
    renderer_->update(session_);
    reset_camera(static_cast<float>(width) / static_cast<float>(height));
    std::size_t tets = 0, triangles = 0;
    for (std::size_t o = 0; o < session_.scene().num_objects(); ++o) {
        tets += session_.mesh(o).num_tets();
        triangles += session_.faces()[o].boundary.size() / 3;
    }
    std::printf("profile: scene %s, %zu objects, %zu tets, %zu surface triangles, %d frames; method %s, test %s, "
                "backend %s on %s\n",
                session_.scene().name().c_str(), session_.scene().num_objects(), tets, triangles, session_.num_frames(),
                to_string(session_.options().method), to_string(session_.options().narrow_phase),
                to_string(session_.options().backend), session_.device_name().c_str());
    std::printf("drawing: %dx%d, %d samples, %s, OpenGL %s\n", width, height, config_.samples,
                reinterpret_cast<const char*>(glGetString(GL_RENDERER)),
                reinterpret_cast<const char*>(glGetString(GL_VERSION)));
    std::printf("%6s %12s %10s %10s %10s %10s %10s %10s %14s\n", "frame", "positions_ms", "detect_ms", "upload_ms",
                "draw_ms", "detect_cpu", "draw_cpu", "ratio_cpu", "colliding_tets");
    std::vector<double> detect, draw, detect_cpu, draw_cpu;
    for (int frame = 0; frame < session_.num_frames(); ++frame) {
        session_.set_frame(frame);
        session_.update();
        // Drawing's cost: the uploads and the drawing until the driver has finished them (Mesa's
        // software renderer draws in threads of this process, which the processor time includes).
        const double cpu_start = process_cpu_ms();
        auto start = std::chrono::steady_clock::now();
        renderer_->update(session_);
        glFinish();
        const double upload_ms = milliseconds_since(start);
        start = std::chrono::steady_clock::now();
        target.bind();
        renderer_->draw(camera_, 0, 0, width, height, config_.display, scene_box_);
        glFinish();
        draw.push_back(milliseconds_since(start));
        draw_cpu.push_back(process_cpu_ms() - cpu_start);
        detect.push_back(session_.detect_ms());
        detect_cpu.push_back(session_.detect_cpu_ms());
        std::printf("%6d %12.3f %10.3f %10.3f %10.3f %10.3f %10.3f %10.3f %14llu\n", frame, session_.positions_ms(),
                    detect.back(), upload_ms, draw.back(), detect_cpu.back(), draw_cpu.back(),
                    draw_cpu.back() / std::max(detect_cpu.back(), 1e-3),
                    static_cast<unsigned long long>(session_.result().counts.colliding_tets));
    }
    std::printf("median per frame: detect %.3f ms (processor %.3f ms), draw %.3f ms (processor %.3f ms, uploads "
                "included)\n",
                median(detect), median(detect_cpu), median(draw), median(draw_cpu));
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

} // namespace kdet::view
