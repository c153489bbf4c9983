#include "surface.hpp"

#include <algorithm>
#include <array>

namespace kdet::view {

namespace {

/// @brief One face of one tet: its sorted vertices (the key that finds its twin) and, in
/// `oriented`, the same vertices in the order that faces away from the tet's fourth vertex.
struct Face {
    std::array<std::uint32_t, 3> key;
    std::array<std::uint32_t, 3> oriented;
};

double orient(const TetMesh& mesh, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    const double* p = mesh.positions.data();
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; ++k) {
        u[k] = p[3 * b + k] - p[3 * a + k];
        v[k] = p[3 * c + k] - p[3 * a + k];
        w[k] = p[3 * d + k] - p[3 * a + k];
    }
    return w[0] * (u[1] * v[2] - u[2] * v[1]) + w[1] * (u[2] * v[0] - u[0] * v[2]) + w[2] * (u[0] * v[1] - u[1] * v[0]);
}

} // namespace

std::vector<std::uint32_t> boundary_triangles(const TetMesh& mesh) {
    // The faces opposite vertex 3, 2, 1 and 0; (a, b, c) is counter-clockwise seen from outside
    // when the fourth vertex lies on the negative side of its plane.
    static constexpr int corners[4][4] = {{0, 1, 2, 3}, {0, 3, 1, 2}, {1, 3, 2, 0}, {0, 2, 3, 1}};
    std::vector<Face> faces;
    faces.reserve(4 * mesh.num_tets());
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        const std::uint32_t* v = &mesh.tets[4 * t];
        for (const auto& c : corners) {
            Face f;
            f.oriented = {v[c[0]], v[c[1]], v[c[2]]};
            if (orient(mesh, v[c[0]], v[c[1]], v[c[2]], v[c[3]]) > 0) std::swap(f.oriented[1], f.oriented[2]);
            f.key = f.oriented;
            std::sort(f.key.begin(), f.key.end());
            faces.push_back(f);
        }
    }
    std::sort(faces.begin(), faces.end(), [](const Face& x, const Face& y) { return x.key < y.key; });
    std::vector<std::uint32_t> triangles;
    for (std::size_t i = 0; i < faces.size();) {
        std::size_t j = i + 1;
        while (j < faces.size() && faces[j].key == faces[i].key) ++j;
        if (j - i == 1) triangles.insert(triangles.end(), faces[i].oriented.begin(), faces[i].oriented.end());
        i = j;
    }
    return triangles;
}

} // namespace kdet::view
