#pragma once
/// @file session.hpp
/// @brief What the viewer shows and computes, without any drawing: the open scene, the Detector
/// with the chosen options, the current frame's positions and the detection's results.

#include "surface.hpp"

#include <kdet/detector.hpp>
#include <kdet/io.hpp>
#include <kdet/locate.hpp>
#include <kdet/scenes.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace kdet::view {

/// @brief Where the viewer's objects come from: a scene (anything `kdet bench` opens) or, when
/// `meshes` is not empty, one or two mesh files as in `kdet collide` (one frame).
struct ViewSource {
    std::string scene = "procedural";
    std::vector<std::string> meshes;
    SceneRequest request;
    ReadOptions read_options;
};

/// @brief Opens @p source. Throws kdet::Error with a one-line message when it cannot.
std::unique_ptr<Scene> open_view_source(const ViewSource& source);

/// @brief The process's resident set in bytes (0 when the system does not tell).
std::size_t resident_bytes();

/// @brief Processor time used by all threads of the process so far, in milliseconds. Unlike wall
/// time it hardly changes when other programs share the processors.
double process_cpu_ms();

/// @brief How many query points a point location found in a tet (held), gave the nearest tet
/// within `within` (near), or left without a tet (missed).
struct PointCounts {
    std::size_t held = 0, near = 0, missed = 0;
};

/// @brief What @p located says of point @p p: 0 held, 1 near, 2 missed.
int point_status(const LocateResult& located, std::size_t p);
PointCounts count_points(const LocateResult& located);

/// @brief The scene, detector and current results of one viewer. Every setting may change at any
/// time, before or after the first detection: the detector is rebuilt with the new settings the next
/// time results are needed, and the old one is released.
class ViewSession {
public:
    /// @brief Opens @p source (throws kdet::Error when it cannot).
    ViewSession(const ViewSource& source, const DetectorOptions& options, SceneSelfCollision self);

    /// @brief Switches to another source. Throws kdet::Error when it cannot be opened, and then keeps
    /// the current one. The frame is kept when the new scene has it, else it becomes 0.
    void open(const ViewSource& source);
    void set_options(const DetectorOptions& options);
    /// @brief Self-collision of no object, every object, or those the scene marks (as `kdet bench -s`).
    void set_self(SceneSelfCollision self);
    /// @brief Self-exclusion rings of every object while self-collision is on
    /// (Detector::set_self_exclusion_rings).
    void set_exclusion_rings(int rings);
    /// @brief Whether a static object of the scene (Scene::is_static) is detected as static
    /// (Detector::set_static: placed once), or moving, given its positions every frame.
    void set_static(std::size_t object, bool is_static);
    bool is_static(std::size_t object) const { return static_[object] != 0; }
    /// @brief Query points (x y z each) located in every object's tets after a detection whose tets
    /// moved (or had not been located), with LocateOptions::within = @p within (`kdet view --points
    /// FILE --within D`).
    void set_points(std::vector<double> xyz, double within);
    /// @brief Selects a frame; clamped to the scene's frames.
    void set_frame(int frame);

    /// @brief Brings the current frame up to date: reads its positions if the frame changed and
    /// runs detection if positions or settings changed. Returns true when it computed anything.
    bool update();

    const ViewSource& source() const { return source_; }
    const Scene& scene() const { return *scene_; }
    const DetectorOptions& options() const { return options_; }
    SceneSelfCollision self() const { return self_; }
    int exclusion_rings() const { return exclusion_rings_; }
    /// @brief An object's collision filter in the current detector (the default before there is one).
    CollisionFilter collision_filter(std::size_t object) const;
    int frame() const { return frame_; }
    int num_frames() const { return scene_->num_frames(); }

    /// @brief Each object's tets at frame() as of the last update() (they change only in a scene
    /// whose tets change, Scene::changes_tets) with the scene's rest positions.
    const TetMesh& mesh(std::size_t object) const { return meshes_.empty() ? scene_->rest_mesh(object) : meshes_[object]; }
    /// @brief Each object's boundary and face neighbours for mesh(object), computed when the scene
    /// opens and again when its tets change.
    const std::vector<MeshFaces>& faces() const { return faces_; }
    /// @brief Positions (x y z per vertex) of each object at frame() as of the last update().
    const std::vector<std::vector<float>>& positions() const { return positions_; }
    /// @brief The last detection; empty before the first update(). With a margin its distances are
    /// on, whatever options() says: they tell the pairs that overlap (distance 0) from the others.
    const FrameResult& result() const { return result_; }
    /// @brief With a margin, per object and tet: 1 for a tet of a reported pair that does not overlap
    /// and of no pair that does (the tets within the margin only); empty without a margin.
    const std::vector<std::vector<std::uint8_t>>& margin_tets() const { return margin_tets_; }
    /// @brief Reported pairs that do not overlap (0 without a margin).
    std::size_t margin_pairs() const { return margin_pairs_; }
    bool has_result() const { return has_result_; }
    const std::vector<double>& points() const { return points_; }
    /// @brief Where the points lie at frame() as of the last update() (empty without points); it
    /// changes with result_version().
    const LocateResult& located() const { return located_; }
    /// @brief Bytes held by the current detector (0 before the first detection).
    std::size_t detector_memory() const;
    /// @brief Name of the device the detector runs on (empty before the first detection).
    std::string device_name() const;

    /// @brief Milliseconds the last update() spent computing positions and in detect() (wall
    /// clock), and the processor time of every thread of the process during detect().
    double positions_ms() const { return positions_ms_; }
    double detect_ms() const { return detect_ms_; }
    double detect_cpu_ms() const { return detect_cpu_ms_; }
    /// @brief Counters that step whenever positions or results change; a renderer compares them to
    /// know what to upload.
    std::uint64_t positions_version() const { return positions_version_; }
    std::uint64_t result_version() const { return result_version_; }
    /// @brief Steps whenever the points are located again (located() changed).
    std::uint64_t located_version() const { return located_version_; }
    /// @brief Steps whenever another scene is opened (its meshes and surfaces changed).
    std::uint64_t scene_version() const { return scene_version_; }
    /// @brief Steps whenever an object's tets (mesh() and faces()) change within the scene.
    std::uint64_t topology_version() const { return topology_version_; }

private:
    void build_detector();
    /// @brief margin_tets_ and margin_pairs_ from result_.
    void find_margin_tets();
    /// @brief Takes the tets of frame_ from a scene whose tets change; true when any changed.
    bool read_tets();

    ViewSource source_;
    std::unique_ptr<Scene> scene_;
    std::vector<TetMesh> meshes_;  ///< each object's current mesh, only for a scene whose tets change
    std::vector<MeshFaces> faces_;
    std::vector<std::vector<std::uint32_t>> detector_tets_; ///< each object's tets as the detector has them
    DetectorOptions options_;
    SceneSelfCollision self_ = SceneSelfCollision::none;
    int exclusion_rings_ = 0;
    std::vector<char> static_; ///< per object: detected as static (the scene's flag unless switched off)
    int frame_ = 0;
    int positions_frame_ = -1; ///< frame whose positions are in positions_, -1 for none
    bool results_stale_ = true;
    std::unique_ptr<Detector> detector_; ///< null until needed, and after a setting changed
    std::vector<std::vector<float>> positions_;
    FrameResult result_;
    bool has_result_ = false;
    std::vector<std::vector<std::uint8_t>> margin_tets_;
    std::size_t margin_pairs_ = 0;
    std::vector<double> points_;
    LocateOptions locate_options_;
    LocateResult located_;
    bool points_stale_ = false;
    bool tets_moved_ = false; ///< positions or tets read since the last detection may differ from those located
    double positions_ms_ = 0, detect_ms_ = 0, detect_cpu_ms_ = 0;
    std::uint64_t positions_version_ = 0, result_version_ = 0, scene_version_ = 0, topology_version_ = 0;
    std::uint64_t located_version_ = 0;
};

} // namespace kdet::view
