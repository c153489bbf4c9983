#pragma once
/// @file mesh.hpp
/// @brief A tetrahedral mesh as plain arrays.

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

} // namespace kdet
