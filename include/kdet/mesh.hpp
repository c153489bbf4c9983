#pragma once
/// @file mesh.hpp
/// @brief Tetrahedral and triangle meshes as plain arrays.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace kdet {

/// @brief A tetrahedral mesh: vertex coordinates and 0-based vertex indices, four per tetrahedron.
struct TetMesh {
    std::vector<double> positions;      ///< x0 y0 z0 x1 y1 z1 ...
    std::vector<std::uint32_t> tets;    ///< a0 b0 c0 d0 a1 b1 c1 d1 ... (0-based)

    std::size_t num_vertices() const { return positions.size() / 3; }
    std::size_t num_tets() const { return tets.size() / 4; }
};

/// @brief A triangle surface: vertex coordinates and 0-based vertex indices, three per triangle.
struct TriangleMesh {
    std::vector<double> positions;        ///< x0 y0 z0 x1 y1 z1 ...
    std::vector<std::uint32_t> triangles; ///< a0 b0 c0 a1 b1 c1 ... (0-based)

    std::size_t num_vertices() const { return positions.size() / 3; }
    std::size_t num_triangles() const { return triangles.size() / 3; }
};

} // namespace kdet
