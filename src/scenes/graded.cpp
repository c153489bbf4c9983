/// @file graded.cpp
/// @brief The `graded` scene: a static block whose cubes halve in size toward a point, down to a
/// thousandth of the largest, and a uniformly meshed torus passing through that point.

#include "scenes/generated_scene.hpp"

#include <kdet/scenes.hpp>

#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace kdet {
namespace {

constexpr int kFrames = 120;

/// @brief The leaves of an octree over the unit cube refined toward `feature`: a cube is split while
/// its centre lies within its own diagonal of the feature and it is above `levels` halvings. Each
/// leaf is split into 6 tets as make_box_mesh splits a cube; vertices are shared where leaves share
/// corners (the mesh is not conforming where a large leaf meets smaller ones: nothing here needs it).
class GradedBlock {
public:
    GradedBlock(int levels, const double (&feature)[3]) : levels_(levels), cube_(make_box_mesh(1, 1, 1, 1.0)) {
        for (int a = 0; a < 3; ++a) feature_[a] = feature[a];
        refine(0, 0, 0, 0);
    }
    TetMesh take() { return std::move(mesh_); }

private:
    void refine(std::uint64_t x, std::uint64_t y, std::uint64_t z, int level) {
        const double size = std::ldexp(1.0, -level);
        double distance = 0;
        const std::uint64_t at[3] = {x, y, z};
        for (int a = 0; a < 3; ++a) {
            const double d = (static_cast<double>(at[a]) + 0.5) * size - feature_[a];
            distance += d * d;
        }
        if (level < levels_ && std::sqrt(distance) < std::sqrt(3.0) * size) {
            for (int child = 0; child < 8; ++child)
                refine(2 * x + (child & 1), 2 * y + (child >> 1 & 1), 2 * z + (child >> 2 & 1), level + 1);
            return;
        }
        // Corners in units of the finest cube, which key the shared vertices.
        const std::uint64_t scale = std::uint64_t{1} << (levels_ - level);
        std::uint32_t ids[8];
        for (std::size_t c = 0; c < 8; ++c) {
            std::uint64_t corner[3];
            for (int a = 0; a < 3; ++a) corner[a] = (at[a] + static_cast<std::uint64_t>(cube_.positions[3 * c + a])) * scale;
            const std::uint64_t key = corner[0] << 42 | corner[1] << 21 | corner[2];
            const auto found = vertex_.emplace(key, static_cast<std::uint32_t>(mesh_.num_vertices()));
            if (found.second)
                for (int a = 0; a < 3; ++a) mesh_.positions.push_back(std::ldexp(static_cast<double>(corner[a]), -levels_));
            ids[c] = found.first->second;
        }
        for (std::uint32_t v : cube_.tets) mesh_.tets.push_back(ids[v]);
    }

    int levels_;
    double feature_[3];
    TetMesh cube_, mesh_;
    std::unordered_map<std::uint64_t, std::uint32_t> vertex_;
};

} // namespace

std::unique_ptr<Scene> make_graded_scene(int resolution) {
    if (resolution < 1 || resolution > 4) throw Error("graded: resolution " + std::to_string(resolution) + " out of range [1, 4]");
    // 12 to 15 halvings; the feature splits the first two everywhere, so the largest cubes are a
    // quarter of the block and the smallest 2^-10 to 2^-13 of them (3 to 3.9 decades).
    const double feature[3] = {0.4, 0.55, 0.5};
    TetMesh block = GradedBlock(11 + resolution, feature).take();
    const TetMesh torus = make_torus_mesh(0.25, 0.08, 10000 * static_cast<std::size_t>(resolution));
    auto motion = [block_positions = block.positions, torus, feature](std::size_t o, int frame, std::vector<double>& out) {
        if (o == 0) {
            out = block_positions;
            return;
        }
        // The torus stands upright and rolls along x through the feature, its tube crossing it at the
        // middle frame.
        const double t = static_cast<double>(frame) / (kFrames - 1);
        const double x = feature[0] - 0.25 - 0.8 + 1.6 * t, angle = 2.0 * t;
        const double c = std::cos(angle), s = std::sin(angle);
        out.resize(torus.positions.size());
        for (std::size_t v = 0; v < torus.num_vertices(); ++v) {
            const double px = torus.positions[3 * v], py = torus.positions[3 * v + 1], pz = torus.positions[3 * v + 2];
            out[3 * v] = x + c * px - s * pz;
            out[3 * v + 1] = feature[1] + s * px + c * pz;
            out[3 * v + 2] = feature[2] + py;
        }
    };
    return std::make_unique<scenes::GeneratedScene>("graded", resolution, kFrames, std::vector<TetMesh>{std::move(block), torus},
                                                    std::vector<std::size_t>{0, 1}, std::vector<bool>{true, false},
                                                    std::vector<bool>{false, false}, std::move(motion));
}

} // namespace kdet
