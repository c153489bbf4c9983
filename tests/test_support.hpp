#pragma once
/// Shared helpers for the tests: data paths, random tet soups, rigid transforms.

#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/mesh.hpp>
#include <kdet/prepare.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>

namespace kdet::test {

/// @brief The message of the kdet::Error that `action` throws (checked to be one line); fails the
/// calling test when it throws none.
inline std::string error_message(const std::function<void()>& action) {
    try {
        action();
    } catch (const Error& error) {
        const std::string message = error.what();
        EXPECT_EQ(message.find('\n'), std::string::npos) << "message is not one line: " << message;
        return message;
    }
    ADD_FAILURE() << "no kdet::Error was thrown";
    return {};
}

/// @brief Points KDET_DATA_DIR at the models beside the source tree unless the caller set it.
inline void use_default_data_dir() {
    const char* set = std::getenv("KDET_DATA_DIR");
    if (!set || !*set) setenv("KDET_DATA_DIR", KDET_DEFAULT_DATA_DIR, 1);
}

inline TetMesh load_model(const std::string& file) {
    use_default_data_dir();
    return read_tet_mesh(data_path(file));
}

/// @brief Disjoint random tets whose sizes span `decades` orders of magnitude, inside a cube of side `extent`.
/// @brief `count` copies of one tet, each with vertices of its own: every pair of them collides and
/// none is adjacent, so self-collision gives count * (count - 1) / 2 pairs, all of them candidates.
inline TetMesh identical_tets(std::uint32_t count) {
    TetMesh mesh;
    const double corners[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (std::uint32_t t = 0; t < count; ++t)
        for (std::uint32_t k = 0; k < 4; ++k) {
            mesh.positions.insert(mesh.positions.end(), corners[k], corners[k] + 3);
            mesh.tets.push_back(4 * t + k);
        }
    return mesh;
}

inline TetMesh random_soup(std::size_t count, double extent, double decades, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    TetMesh mesh;
    for (std::size_t t = 0; t < count; ++t) {
        const double size = extent * 0.2 * std::pow(10.0, -decades * unit(rng));
        const double cx = extent * unit(rng), cy = extent * unit(rng), cz = extent * unit(rng);
        for (int k = 0; k < 4; ++k) {
            mesh.positions.push_back(cx + size * (unit(rng) - 0.5));
            mesh.positions.push_back(cy + size * (unit(rng) - 0.5));
            mesh.positions.push_back(cz + size * (unit(rng) - 0.5));
        }
        for (std::uint32_t k = 0; k < 4; ++k) mesh.tets.push_back(static_cast<std::uint32_t>(4 * t) + k);
    }
    return mesh;
}

/// @brief Rotates about the z axis through the mesh's box centre, then translates.
inline TetMesh moved(const TetMesh& mesh, double angle, double dx, double dy, double dz) {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v)
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], mesh.positions[3 * v + a]);
            hi[a] = std::max(hi[a], mesh.positions[3 * v + a]);
        }
    const double c[3] = {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2};
    TetMesh out = mesh;
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
        const double x = mesh.positions[3 * v] - c[0], y = mesh.positions[3 * v + 1] - c[1];
        out.positions[3 * v] = c[0] + std::cos(angle) * x - std::sin(angle) * y + dx;
        out.positions[3 * v + 1] = c[1] + std::sin(angle) * x + std::cos(angle) * y + dy;
        out.positions[3 * v + 2] = mesh.positions[3 * v + 2] + dz;
    }
    return out;
}

/// @brief Largest box extent of a mesh.
inline double extent_of(const TetMesh& mesh) {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v)
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], mesh.positions[3 * v + a]);
            hi[a] = std::max(hi[a], mesh.positions[3 * v + a]);
        }
    return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
}

} // namespace kdet::test
