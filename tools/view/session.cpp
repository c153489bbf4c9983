#include "session.hpp"

#include "cli_args.hpp"

#include <kdet/error.hpp>

#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>

namespace kdet::view {

namespace {

/// @brief One or two meshes read from files, standing still: a scene of one frame.
class MeshScene final : public Scene {
public:
    MeshScene(const std::vector<std::string>& paths, const ReadOptions& options) {
        for (const std::string& path : paths) {
            meshes_.push_back(read_tet_mesh(path, options));
            if (!name_.empty()) name_ += "+";
            name_ += std::filesystem::path(path).stem().string();
        }
    }
    std::string name() const override { return name_; }
    std::size_t num_objects() const override { return meshes_.size(); }
    int num_frames() const override { return 1; }
    const TetMesh& rest_mesh(std::size_t object) const override { return meshes_.at(object); }
    void positions(std::size_t object, int, std::vector<float>& out) const override {
        const std::vector<double>& p = meshes_.at(object).positions;
        out.assign(p.begin(), p.end());
    }
    void positions(std::size_t object, int, std::vector<double>& out) const override {
        out = meshes_.at(object).positions;
    }

private:
    std::vector<TetMesh> meshes_;
    std::string name_;
};

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

} // namespace

std::unique_ptr<Scene> open_view_source(const ViewSource& source) {
    if (!source.meshes.empty()) return std::make_unique<MeshScene>(source.meshes, source.read_options);
    return open_scene(source.scene, source.request);
}

std::size_t resident_bytes() {
    std::ifstream statm("/proc/self/statm");
    std::size_t total_pages = 0, resident_pages = 0;
    if (!(statm >> total_pages >> resident_pages)) return 0;
    return resident_pages * static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
}

double process_cpu_ms() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

int point_status(const LocateResult& located, std::size_t p) {
    const std::uint64_t first = located.offsets[p];
    if (first == located.offsets[p + 1]) return 2;
    return located.distances[first] > 0 ? 1 : 0;
}

PointCounts count_points(const LocateResult& located) {
    PointCounts counts;
    for (std::size_t p = 0; p < located.point_count; ++p) {
        const int status = point_status(located, p);
        counts.held += status == 0;
        counts.near += status == 1;
        counts.missed += status == 2;
    }
    return counts;
}

ViewSession::ViewSession(const ViewSource& source, const DetectorOptions& options, SceneSelfCollision self)
    : options_(options), self_(self) {
    open(source);
}

void ViewSession::open(const ViewSource& source) {
    std::unique_ptr<Scene> scene = open_view_source(source);
    std::vector<MeshFaces> faces;
    for (std::size_t o = 0; o < scene->num_objects(); ++o) faces.push_back(analyse_faces(scene->rest_mesh(o)));
    std::vector<TetMesh> meshes;
    if (scene->changes_tets())
        for (std::size_t o = 0; o < scene->num_objects(); ++o) meshes.push_back(scene->rest_mesh(o));
    // Release the old detector before the new scene's buffers are made.
    detector_.reset();
    scene_ = std::move(scene);
    meshes_ = std::move(meshes);
    faces_ = std::move(faces);
    source_ = source;
    positions_.assign(scene_->num_objects(), {});
    static_.clear();
    for (std::size_t o = 0; o < scene_->num_objects(); ++o) static_.push_back(scene_->is_static(o) ? 1 : 0);
    if (frame_ >= scene_->num_frames()) frame_ = 0;
    positions_frame_ = -1;
    results_stale_ = true;
    has_result_ = false;
    result_ = FrameResult{};
    ++scene_version_;
}

void ViewSession::set_options(const DetectorOptions& options) {
    options_ = options;
    detector_.reset();
    results_stale_ = true;
}

void ViewSession::set_self(SceneSelfCollision self) {
    if (self == self_) return;
    self_ = self;
    detector_.reset();
    results_stale_ = true;
}

void ViewSession::set_exclusion_rings(int rings) {
    if (rings == exclusion_rings_) return;
    exclusion_rings_ = rings;
    detector_.reset();
    results_stale_ = true;
}

void ViewSession::set_static(std::size_t object, bool is_static) {
    // Only a scene's static objects keep their positions in every frame, so only they can be static.
    const char flag = is_static && scene_->is_static(object) ? 1 : 0;
    if (static_[object] == flag) return;
    static_[object] = flag;
    detector_.reset();
    results_stale_ = true;
}

CollisionFilter ViewSession::collision_filter(std::size_t object) const {
    return detector_ ? detector_->collision_filter(static_cast<ObjectId>(object)) : CollisionFilter{};
}

void ViewSession::set_points(std::vector<double> xyz, double within) {
    points_ = std::move(xyz);
    locate_options_.within = within;
    points_stale_ = true;
}

void ViewSession::set_frame(int frame) { frame_ = std::clamp(frame, 0, scene_->num_frames() - 1); }

void ViewSession::build_detector() {
    DetectorOptions options = options_;
    options.distances = options.distances || options.margin > 0.0f;
    auto detector = std::make_unique<Detector>(options);
    add_scene_objects(*detector, *scene_, self_);
    if (self_ != SceneSelfCollision::none)
        for (std::size_t o = 0; o < scene_->num_objects(); ++o)
            detector->set_self_exclusion_rings(static_cast<ObjectId>(o), exclusion_rings_);
    for (std::size_t o = 0; o < scene_->num_objects(); ++o) detector->set_static(static_cast<ObjectId>(o), static_[o] != 0);
    detector_tets_.clear();
    if (scene_->changes_tets())
        for (std::size_t o = 0; o < scene_->num_objects(); ++o) detector_tets_.push_back(scene_->rest_mesh(o).tets);
    detector_ = std::move(detector);
}

bool ViewSession::read_tets() {
    bool changed = false;
    std::vector<std::uint32_t> tets;
    for (std::size_t o = 0; o < meshes_.size(); ++o) {
        scene_->tets(o, frame_, tets);
        if (tets == meshes_[o].tets) continue;
        meshes_[o].tets.swap(tets);
        faces_[o] = analyse_faces(meshes_[o]);
        changed = true;
    }
    return changed;
}

bool ViewSession::update() {
    bool changed = false;
    if (positions_frame_ != frame_) {
        const auto start = std::chrono::steady_clock::now();
        // The points' tets move only with a scene's first positions, new tets or a moving object.
        bool moved = positions_frame_ < 0;
        for (std::size_t o = 0; o < scene_->num_objects(); ++o) {
            scene_->positions(o, frame_, positions_[o]);
            moved = moved || !scene_->is_static(o);
        }
        if (read_tets()) {
            ++topology_version_;
            moved = true;
        }
        tets_moved_ = tets_moved_ || moved;
        positions_ms_ = milliseconds_since(start);
        positions_frame_ = frame_;
        ++positions_version_;
        results_stale_ = true;
        changed = true;
    }
    if (results_stale_) {
        const bool fresh = !detector_;
        if (fresh) build_detector();
        set_scene_tets(*detector_, *scene_, frame_, detector_tets_);
        // A static object's positions are the same in every frame: given once, it stays placed.
        for (std::size_t o = 0; o < scene_->num_objects(); ++o)
            if (fresh || !static_[o])
                detector_->set_positions(static_cast<ObjectId>(o), positions_[o].data(), positions_[o].size() / 3);
        const auto start = std::chrono::steady_clock::now();
        const double cpu_start = process_cpu_ms();
        result_ = detector_->detect();
        detect_cpu_ms_ = process_cpu_ms() - cpu_start;
        detect_ms_ = milliseconds_since(start);
        find_margin_tets();
        has_result_ = true;
        results_stale_ = false;
        // Another detection at the same positions (settings changed, a static scene's next frame)
        // leaves the points where they were.
        if (tets_moved_) points_stale_ = !points_.empty();
        tets_moved_ = false;
        ++result_version_;
        changed = true;
    }
    if (points_stale_ && detector_) {
        // Located at this frame's positions, which the detection just placed.
        if (points_.empty()) {
            located_ = LocateResult{};
        } else {
            located_ = detector_->locate(PositionsView{points_.data(), true, points_.size() / 3}, all_objects, locate_options_);
        }
        points_stale_ = false;
        ++located_version_;
        ++result_version_;
        changed = true;
    }
    return changed;
}

void ViewSession::find_margin_tets() {
    margin_tets_.clear();
    margin_pairs_ = 0;
    if (!(options_.margin > 0.0f)) return;
    margin_pairs_ = result_.pairs.size() - static_cast<std::size_t>(cli::overlapping_pairs(result_));
    // 0: in no pair within the margin only, 1: in one, 2: in an overlapping pair (which wins).
    margin_tets_.resize(scene_->num_objects());
    for (std::size_t o = 0; o < margin_tets_.size(); ++o) margin_tets_[o].assign(mesh(o).num_tets(), 0);
    for (std::size_t p = 0; p < result_.pairs.size(); ++p) {
        const TetPair& pair = result_.pairs[p];
        const bool overlaps = result_.distances[p] == 0.0f;
        for (std::uint8_t* flag : {&margin_tets_[pair.object_a][pair.tet_a], &margin_tets_[pair.object_b][pair.tet_b]})
            *flag = overlaps ? 2 : std::max<std::uint8_t>(*flag, 1);
    }
    for (std::vector<std::uint8_t>& flags : margin_tets_)
        for (std::uint8_t& flag : flags) flag = flag == 1 ? 1 : 0;
}

std::size_t ViewSession::detector_memory() const { return detector_ ? detector_->memory_bytes() : 0; }

std::string ViewSession::device_name() const { return detector_ ? detector_->device_name() : std::string(); }

} // namespace kdet::view
