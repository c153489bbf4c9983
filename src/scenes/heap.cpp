/// @file heap.cpp
/// @brief The `heap` scene: many small boxes falling into a pile on a static floor.

#include "scenes/generated_scene.hpp"

#include <kdet/scenes.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace kdet {
namespace {

constexpr int kFrames = 120;
constexpr double kBody = 1.0;            // a body's side (2 x 2 x 2 cubes, 48 tets)
constexpr double kPitch = kBody;         // columns this far apart: neighbours touch sideways, some a little inside
constexpr double kRest = 0.96 * kBody;   // layers rest this far apart: each sinks a little into the one below
constexpr double kGravity = 0.012;       // per frame squared, in body sides
constexpr int kReleaseEvery = 6;         // frames between the releases of two layers

/// @brief A deterministic number in [-1, 1] for a body and a salt.
double jitter(std::size_t body, std::uint32_t salt) {
    std::uint32_t h = static_cast<std::uint32_t>(body) * 2654435761u ^ salt * 40503u;
    h ^= h >> 15;
    h *= 2246822519u;
    h ^= h >> 13;
    return static_cast<double>(h % 20001u) / 10000.0 - 1.0;
}

} // namespace

std::unique_ptr<Scene> make_heap_scene(int resolution) {
    if (resolution < 1 || resolution > 4) throw Error("heap: resolution " + std::to_string(resolution) + " out of range [1, 4]");
    // 5, 7, 9 and 10 bodies a side: 125, 343, 729 and 1000 bodies.
    const int side = resolution == 4 ? 10 : 2 * resolution + 3;
    const std::size_t bodies = static_cast<std::size_t>(side) * side * side;
    // The floor: 2 cells thick, a margin of one body around the columns, its top at z = 0.
    const int floor_cells = 2 * (side + 2);
    const double cell = (side + 2) * kPitch / floor_cells;
    TetMesh floor = make_box_mesh(floor_cells, floor_cells, 2, cell);
    for (std::size_t v = 0; v < floor.num_vertices(); ++v) {
        floor.positions[3 * v] -= kPitch;
        floor.positions[3 * v + 1] -= kPitch;
        floor.positions[3 * v + 2] -= 2 * cell;
    }
    TetMesh body = make_box_mesh(2, 2, 2, kBody / 2);
    for (double& x : body.positions) x -= kBody / 2; // centred on the origin
    std::vector<std::size_t> mesh_of(bodies + 1, 1);
    mesh_of[0] = 0;
    std::vector<bool> is_static(bodies + 1, false);
    is_static[0] = true;
    auto motion = [floor_positions = floor.positions, body_ref = body, side](std::size_t o, int frame, std::vector<double>& out) {
        if (o == 0) {
            out = floor_positions;
            return;
        }
        const std::size_t b = o - 1;
        const int i = static_cast<int>(b % side), j = static_cast<int>(b / side % side), k = static_cast<int>(b / side / side);
        // Each body lands on its column's pile (a little off the column's centre) and rests there; it
        // turns about z as it falls and lands square.
        const double x = (i + 0.5) * kPitch + 0.03 * jitter(b, 1), y = (j + 0.5) * kPitch + 0.03 * jitter(b, 2);
        const double rest = 0.5 * kBody - 0.07 * kBody + k * kRest;
        const double start = rest + 4.0 * kBody + 0.5 * k * kBody;
        const double t = std::max(0, frame - k * kReleaseEvery);
        const double z = std::max(rest, start - 0.5 * kGravity * t * t);
        const double angle = 0.6 * jitter(b, 3) * (z - rest) / (start - rest);
        const double c = std::cos(angle), s = std::sin(angle);
        out.resize(body_ref.positions.size());
        for (std::size_t v = 0; v < body_ref.num_vertices(); ++v) {
            const double px = body_ref.positions[3 * v], py = body_ref.positions[3 * v + 1], pz = body_ref.positions[3 * v + 2];
            out[3 * v] = x + c * px - s * py;
            out[3 * v + 1] = y + s * px + c * py;
            out[3 * v + 2] = z + pz;
        }
    };
    // The floor keeps the default filter (group 1, every mask bit); a body is in its layer's group and
    // collides with the floor and the other layers' group, so bodies side by side in one layer do not
    // collide (as debris of one kind set not to collide with itself).
    std::vector<CollisionFilter> filters(bodies + 1);
    for (std::size_t b = 0; b < bodies; ++b) {
        const std::uint32_t layer = static_cast<std::uint32_t>(b / side / side) % 2;
        filters[b + 1] = CollisionFilter{2u << layer, 1u | (4u >> layer)};
    }
    auto scene = std::make_unique<scenes::GeneratedScene>("heap", resolution, kFrames, std::vector<TetMesh>{std::move(floor), std::move(body)},
                                                          std::move(mesh_of), std::move(is_static),
                                                          std::vector<bool>(bodies + 1, false), std::move(motion));
    scene->set_filters(std::move(filters));
    return scene;
}

} // namespace kdet
