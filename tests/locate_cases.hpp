#pragma once
/// Point location's test cases, shared by tests/test_locate.cpp and the CGAL oracle
/// (tests/cgal/test_locate_cgal.cpp): meshes and the query points that stress containment (vertices
/// shared by many tets, face and edge midpoints rounded to float, points just outside the boundary).

#include <kdet/mesh.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

namespace kdet::test {

/// @brief A mesh's vertex as the float32 point the detector stores, widened back to double.
inline std::array<double, 3> float_vertex(const TetMesh& mesh, std::uint32_t v) {
    std::array<double, 3> p{};
    for (int a = 0; a < 3; ++a) p[a] = static_cast<float>(mesh.positions[3 * std::size_t{v} + a]);
    return p;
}

/// @brief Query points for a mesh (x y z each, exact as floats): every vertex, the midpoints of the
/// first `features` tets' edges and faces rounded to float, their centroids, boundary faces' centroids
/// pushed out by one and by a few float steps and by a tenth of the edge, and `random` points
/// uniform in the mesh's box grown by a fifth.
inline std::vector<double> locate_query_points(const TetMesh& mesh, std::size_t features, std::size_t random, unsigned seed) {
    std::vector<double> out;
    const auto push = [&](double x, double y, double z) {
        out.push_back(static_cast<float>(x));
        out.push_back(static_cast<float>(y));
        out.push_back(static_cast<float>(z));
    };
    for (std::uint32_t v = 0; v < mesh.num_vertices(); ++v) {
        const auto p = float_vertex(mesh, v);
        push(p[0], p[1], p[2]);
    }
    const std::size_t tets = std::min(features, mesh.num_tets());
    for (std::size_t t = 0; t < tets; ++t) {
        std::array<std::array<double, 3>, 4> v;
        for (int k = 0; k < 4; ++k) v[k] = float_vertex(mesh, mesh.tets[4 * t + k]);
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j) push((v[i][0] + v[j][0]) / 2, (v[i][1] + v[j][1]) / 2, (v[i][2] + v[j][2]) / 2);
        for (int skip = 0; skip < 4; ++skip) {
            double c[3] = {0, 0, 0};
            for (int k = 0; k < 4; ++k)
                if (k != skip)
                    for (int a = 0; a < 3; ++a) c[a] += v[k][a] / 3;
            push(c[0], c[1], c[2]);
        }
        push((v[0][0] + v[1][0] + v[2][0] + v[3][0]) / 4, (v[0][1] + v[1][1] + v[2][1] + v[3][1]) / 4,
             (v[0][2] + v[1][2] + v[2][2] + v[3][2]) / 4);
    }
    // Boundary faces: the faces only one tet uses, keyed by their sorted vertices.
    std::map<std::array<std::uint32_t, 3>, std::pair<int, std::size_t>> faces;
    for (std::size_t t = 0; t < mesh.num_tets(); ++t)
        for (int skip = 0; skip < 4; ++skip) {
            std::array<std::uint32_t, 3> f{};
            int n = 0;
            for (int k = 0; k < 4; ++k)
                if (k != skip) f[n++] = mesh.tets[4 * t + k];
            std::sort(f.begin(), f.end());
            auto& entry = faces[f];
            ++entry.first;
            entry.second = 4 * t + skip;
        }
    std::size_t boundary = 0;
    for (const auto& [f, use] : faces) {
        if (use.first != 1 || boundary++ >= features) continue;
        const auto a = float_vertex(mesh, f[0]), b = float_vertex(mesh, f[1]), c = float_vertex(mesh, f[2]);
        const auto opposite = float_vertex(mesh, mesh.tets[use.second]);
        double centre[3], n[3];
        const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        for (int k = 0; k < 3; ++k) centre[k] = (a[k] + b[k] + c[k]) / 3;
        // Outward: away from the tet's fourth vertex.
        const double side = n[0] * (opposite[0] - centre[0]) + n[1] * (opposite[1] - centre[1]) + n[2] * (opposite[2] - centre[2]);
        const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(length > 0)) continue;
        const double edge = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
        for (double step : {0.1 * edge, 1e-6 * edge, 0.0}) {
            double q[3];
            for (int k = 0; k < 3; ++k) q[k] = centre[k] + (side > 0 ? -1 : 1) * step * n[k] / length;
            push(q[0], q[1], q[2]);
        }
        // One and four float steps outward from the rounded centroid, along each axis the normal leaves by.
        for (int k = 0; k < 3; ++k) {
            const double outward = (side > 0 ? -1 : 1) * n[k];
            if (outward == 0) continue;
            float q[3] = {static_cast<float>(centre[0]), static_cast<float>(centre[1]), static_cast<float>(centre[2])};
            for (int s = 0; s < 4; ++s) {
                q[k] = std::nextafter(q[k], outward > 0 ? INFINITY : -INFINITY);
                if (s == 0 || s == 3) push(q[0], q[1], q[2]);
            }
        }
    }
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (std::uint32_t v = 0; v < mesh.num_vertices(); ++v)
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], mesh.positions[3 * std::size_t{v} + a]);
            hi[a] = std::max(hi[a], mesh.positions[3 * std::size_t{v} + a]);
        }
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-0.1, 1.1);
    for (std::size_t i = 0; i < random; ++i)
        push(lo[0] + unit(rng) * (hi[0] - lo[0]), lo[1] + unit(rng) * (hi[1] - lo[1]), lo[2] + unit(rng) * (hi[2] - lo[2]));
    return out;
}

} // namespace kdet::test
