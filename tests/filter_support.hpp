#pragma once
/// Helpers of the filter and topology tests: meshes that touch themselves near and far, and the
/// oracle's pairs (brute force, every object pair and every self pair on) filtered in plain code.

#include <kdet/detector.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <cstdint>
#include <map>
#include <queue>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace kdet::test {

/// A box mesh whose inner vertices are moved at random by up to `jitter` cells: neighbouring tets
/// that share no vertex then overlap here and there, as in a mesh crumpled by a simulation.
inline TetMesh jittered_box(int nx, int ny, int nz, double cell, double jitter, unsigned seed, double dx = 0) {
    TetMesh mesh = make_box_mesh(nx, ny, nz, cell);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) mesh.positions[i] += jitter * cell * unit(rng);
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) mesh.positions[3 * v] += dx;
    return mesh;
}

/// A bar of nx x 3 x 3 cubes wound 1.15 times around (fold_bar), so that its ends overlap, then
/// jittered as jittered_box does: contacts between near neighbours and between far parts.
inline TetMesh crumpled_bar(int nx, double jitter, unsigned seed) {
    const TetMesh bar = make_box_mesh(nx, 3, 3, 0.1);
    TetMesh folded = bar;
    fold_bar(bar, 2.0 * 3.14159265358979 * 1.15, folded.positions);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (double& x : folded.positions) x += jitter * 0.1 * unit(rng);
    return folded;
}

/// Every colliding pair of the meshes, each object checked against every other and itself.
inline std::vector<TetPair> brute_force_everything(const std::vector<TetMesh>& meshes, Backend backend = Backend::cpu) {
    DetectorOptions options;
    options.method = Method::brute_force_loop;
    options.backend = backend;
    Detector detector(options);
    for (const TetMesh& m : meshes) detector.set_self_collision(detector.add_object(m), true);
    return detector.detect().pairs;
}

/// Pairs of tets i < j of `mesh` with a vertex of one within `rings` mesh edges of a vertex of the
/// other, sharing none: a breadth-first search over the vertices, as the definition reads.
inline std::set<std::pair<std::uint32_t, std::uint32_t>> ring_pairs(const TetMesh& mesh, int rings) {
    const std::size_t n = mesh.num_vertices(), tets = mesh.num_tets();
    std::vector<std::set<std::uint32_t>> neighbours(n);
    std::vector<std::vector<std::uint32_t>> tets_of(n);
    for (std::size_t t = 0; t < tets; ++t)
        for (int a = 0; a < 4; ++a) {
            tets_of[mesh.tets[4 * t + a]].push_back(static_cast<std::uint32_t>(t));
            for (int b = 0; b < 4; ++b)
                if (a != b) neighbours[mesh.tets[4 * t + a]].insert(mesh.tets[4 * t + b]);
        }
    std::set<std::pair<std::uint32_t, std::uint32_t>> out;
    for (std::uint32_t t = 0; t < tets; ++t) {
        std::map<std::uint32_t, int> distance;
        std::queue<std::uint32_t> queue;
        for (int k = 0; k < 4; ++k)
            if (distance.emplace(mesh.tets[4 * t + k], 0).second) queue.push(mesh.tets[4 * t + k]);
        while (!queue.empty()) {
            const std::uint32_t v = queue.front();
            queue.pop();
            if (distance[v] == rings) continue;
            for (std::uint32_t w : neighbours[v])
                if (distance.emplace(w, distance[v] + 1).second) queue.push(w);
        }
        for (const auto& [v, d] : distance)
            for (std::uint32_t u : tets_of[v]) {
                bool shares = false;
                for (int a = 0; a < 4; ++a)
                    for (int b = 0; b < 4; ++b) shares = shares || mesh.tets[4 * t + a] == mesh.tets[4 * std::size_t{u} + b];
                if (t < u && !shares) out.emplace(t, u);
            }
    }
    return out;
}

} // namespace kdet::test
