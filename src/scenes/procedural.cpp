/// @file procedural.cpp
/// @brief ProceduralScene: two deforming tori that pass through each other.

#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace kdet {
namespace {

constexpr std::size_t kNumObjects = 2;
constexpr std::size_t kMinTotalTets = 100;
constexpr std::size_t kMaxTotalTets = 20'000'000;

constexpr double kMajorRadius = 1.0;
// Leaves a hole of radius 0.6 for the other tube (radius 0.4) when the rings are linked.
constexpr double kMinorRadius = 0.4;
// Gap between the two bounding boxes at the first and last frame.
constexpr double kStartGap = 0.2;

constexpr double kTwoPi = 6.283185307179586;
// Twist angle at the top of the tube (height = minor radius); its shear stays below 0.5, far from
// turning a tet inside out, and it preserves volume.
constexpr double kTwistAmplitude = 0.12;
constexpr double kTwistCycles = 2.0;
// The centre line waves along the axis with 3 lobes; shifting along the axis also preserves volume.
constexpr double kWobbleAmplitude = 0.05 * kMinorRadius;
constexpr double kWobbleLobes = 3.0;
constexpr double kWobbleCycles = 3.0;
// Half a turn over the sequence. The spin turns faster than the twist can turn back, so every vertex
// moves between any two frames.
constexpr double kSpinTurns = 0.5;
// Object 1 runs its deformations a quarter cycle behind object 0, so the two never move alike.
constexpr double kPhaseOfObject[kNumObjects] = {0.0, 0.25};

/// @brief Everything about one object at one frame that does not depend on the vertex.
struct FramePose {
    double twist_per_height;  ///< rotation about the local axis per unit height, radians
    double spin;              ///< rigid rotation about the local axis, radians
    double wobble_phase;      ///< radians
    bool upright;             ///< ring in the world xz plane instead of the xy plane
    double centre_x;          ///< world x of the torus centre
};

FramePose frame_pose(std::size_t object, int frame, int num_frames, double start_separation) {
    // 0 at the first frame, 1 at the last.
    const double time = num_frames > 1 ? static_cast<double>(frame) / static_cast<double>(num_frames - 1) : 0.0;
    const double phase = kPhaseOfObject[object];
    // The centres meet at time 0.5 and return to their start at time 1.
    const double separation = start_separation * 0.5 * (1.0 + std::cos(kTwoPi * time));
    FramePose pose;
    pose.twist_per_height = kTwistAmplitude / kMinorRadius * std::sin(kTwoPi * (kTwistCycles * time + phase));
    pose.spin = kTwoPi * kSpinTurns * time;
    pose.wobble_phase = kTwoPi * (kWobbleCycles * time + phase);
    pose.upright = object == 1;
    pose.centre_x = (object == 0 ? -0.5 : 0.5) * separation;
    return pose;
}

void check_object(std::size_t object) {
    if (object >= kNumObjects)
        throw Error("procedural scene has no object " + std::to_string(object) + " (it has 2)");
}

} // namespace

ProceduralScene::ProceduralScene(const ProceduralSceneOptions& options) : options_(options) {
    if (options.total_tets < kMinTotalTets || options.total_tets > kMaxTotalTets)
        throw Error("procedural scene needs between 100 and 20000000 tets, not " + std::to_string(options.total_tets));
    if (options.frames < 1) throw Error("procedural scene needs at least one frame");

    torus_ = make_torus_mesh(kMajorRadius, kMinorRadius, options.total_tets / kNumObjects);
    // Spin and twist keep each vertex's distance from the local axis and the wobble moves only along the
    // axis, so each object's world x extent stays within its centre +- the largest such distance.
    double max_distance_from_axis = 0.0;
    for (std::size_t v = 0; v < torus_.num_vertices(); ++v)
        max_distance_from_axis = std::max(
            max_distance_from_axis, std::hypot(torus_.positions[3 * v], torus_.positions[3 * v + 1]));
    start_separation_ = 2.0 * max_distance_from_axis + kStartGap;
}

std::string ProceduralScene::name() const { return "procedural"; }

std::size_t ProceduralScene::num_objects() const { return kNumObjects; }

int ProceduralScene::num_frames() const { return options_.frames; }

const TetMesh& ProceduralScene::rest_mesh(std::size_t object) const {
    check_object(object);
    return torus_;
}

template <typename Real>
void ProceduralScene::write_positions(std::size_t object, int frame, std::vector<Real>& out) const {
    check_object(object);
    if (frame < 0 || frame >= options_.frames)
        throw Error("procedural scene has no frame " + std::to_string(frame) + " (it has " +
                    std::to_string(options_.frames) + ")");
    const FramePose pose = frame_pose(object, frame, options_.frames, start_separation_);
    const std::vector<double>& rest = torus_.positions;
    out.resize(rest.size());
    const auto num_vertices = static_cast<long long>(torus_.num_vertices());
#pragma omp parallel for schedule(static)
    for (long long v = 0; v < num_vertices; ++v) {
        const double x = rest[3 * v], y = rest[3 * v + 1], z = rest[3 * v + 2];
        const double distance_from_axis = std::hypot(x, y);
        const double azimuth = std::atan2(y, x);
        const double angle = azimuth + pose.spin + pose.twist_per_height * z;
        const double local_x = distance_from_axis * std::cos(angle);
        const double local_y = distance_from_axis * std::sin(angle);
        const double local_z = z + kWobbleAmplitude * std::sin(kWobbleLobes * azimuth + pose.wobble_phase);
        // Standing upright is a quarter turn about x: (x, y, z) -> (x, -z, y).
        out[3 * v] = static_cast<Real>(pose.centre_x + local_x);
        out[3 * v + 1] = static_cast<Real>(pose.upright ? -local_z : local_y);
        out[3 * v + 2] = static_cast<Real>(pose.upright ? local_y : local_z);
    }
}

void ProceduralScene::positions(std::size_t object, int frame, std::vector<float>& out) const {
    write_positions(object, frame, out);
}

void ProceduralScene::positions(std::size_t object, int frame, std::vector<double>& out) const {
    write_positions(object, frame, out);
}

} // namespace kdet
