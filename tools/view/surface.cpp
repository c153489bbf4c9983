#include "surface.hpp"

#include <algorithm>
#include <array>

namespace kdet::view {

namespace {

/// @brief Face k of tet `tet`: its sorted vertices (the key that finds its twin), the same vertices
/// in the order that faces away from the tet's fourth vertex, and where it came from.
struct Face {
    std::array<std::uint32_t, 3> key;
    std::array<std::uint32_t, 3> oriented;
    std::uint32_t tet;
    std::uint32_t k;
};

double orient(const TetMesh& mesh, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    const double* p = mesh.positions.data();
    double u[3], v[3], w[3];
    for (int i = 0; i < 3; ++i) {
        u[i] = p[3 * b + i] - p[3 * a + i];
        v[i] = p[3 * c + i] - p[3 * a + i];
        w[i] = p[3 * d + i] - p[3 * a + i];
    }
    return w[0] * (u[1] * v[2] - u[2] * v[1]) + w[1] * (u[2] * v[0] - u[0] * v[2]) + w[2] * (u[0] * v[1] - u[1] * v[0]);
}

} // namespace

MeshFaces analyse_faces(const TetMesh& mesh) {
    std::vector<Face> faces;
    faces.reserve(4 * mesh.num_tets());
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        const std::uint32_t* v = &mesh.tets[4 * t];
        for (std::uint32_t k = 0; k < 4; ++k) {
            const int* c = tet_face_vertices[k];
            // The vertex not on face k: the four corner indices sum to 6.
            const std::uint32_t opposite = v[6 - c[0] - c[1] - c[2]];
            Face f{{}, {v[c[0]], v[c[1]], v[c[2]]}, static_cast<std::uint32_t>(t), k};
            // Outward: the fourth vertex lies behind the face's plane.
            if (orient(mesh, f.oriented[0], f.oriented[1], f.oriented[2], opposite) > 0) std::swap(f.oriented[1], f.oriented[2]);
            f.key = f.oriented;
            std::sort(f.key.begin(), f.key.end());
            faces.push_back(f);
        }
    }
    std::sort(faces.begin(), faces.end(), [](const Face& x, const Face& y) { return x.key < y.key; });
    MeshFaces out;
    out.neighbour.assign(4 * mesh.num_tets(), no_tet);
    for (std::size_t i = 0; i < faces.size();) {
        std::size_t j = i + 1;
        while (j < faces.size() && faces[j].key == faces[i].key) ++j;
        if (j - i == 1) {
            out.boundary.insert(out.boundary.end(), faces[i].oriented.begin(), faces[i].oriented.end());
            out.boundary_tet.push_back(faces[i].tet);
        } else if (j - i == 2) {
            out.neighbour[4 * faces[i].tet + faces[i].k] = faces[i + 1].tet;
            out.neighbour[4 * faces[i + 1].tet + faces[i + 1].k] = faces[i].tet;
        }
        i = j;
    }
    return out;
}

void append_flagged_region(const TetMesh& mesh, const MeshFaces& faces, const std::vector<std::uint8_t>& flags,
                           std::vector<std::uint32_t>& out) {
    for (std::size_t t = 0; t < flags.size(); ++t) {
        if (!flags[t]) continue;
        const std::uint32_t* v = &mesh.tets[4 * t];
        for (int k = 0; k < 4; ++k) {
            const std::uint32_t other = faces.neighbour[4 * t + static_cast<std::size_t>(k)];
            if (other != no_tet && flags[other]) continue;
            const int* c = tet_face_vertices[k];
            out.insert(out.end(), {v[c[0]], v[c[1]], v[c[2]]});
        }
    }
}

} // namespace kdet::view
