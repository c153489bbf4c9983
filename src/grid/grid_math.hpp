#pragma once
/// @file grid_math.hpp
/// @brief Layer choice, cell ranges and cell keys of the hierarchical grid.
///
/// Layer l has cell size c_l = c0 * 2^l. A tetrahedron of size d (diameter of its minimum enclosing
/// sphere) lives on the layer with c_(l-1) < d <= c_l, so its box spans at most two cells per axis.
/// Correctness never depends on these sizes: a pair whose boxes overlap always shares a cell on the
/// higher of its two layers, because both boxes contain the lower corner of their intersection and
/// every cell index comes from the same monotone function of a coordinate.

#include "geometry/vec3.hpp"
#include "grid/hash.hpp"

#include <cstdint>
#include <cstring>

namespace kdet {

/// @brief Most layers the grid uses; sizes beyond c0 * 2^(max_grid_layers-1) share the top layer.
constexpr int max_grid_layers = 32;

/// @brief Bits kept per cell coordinate in a key; farther cells alias, which costs only extra candidates.
constexpr int cell_coordinate_bits = 19;

/// @brief The frame's grid geometry, chosen from the scene (see choose_grid_params).
struct GridParams {
    vec3 origin;        ///< lower corner of the region that is gridded
    float cell_size0;   ///< c0: the smallest tet size among the gridded tets, or a few of their spacings (GridParamsKernel)
    float inv_cell_size0;
    int layer_count;    ///< layers 0 .. layer_count-1
};

/// @brief Layer of a tetrahedron of size `diameter`: the smallest l with diameter <= c0 * 2^l.
KDET_HD inline int layer_of(const GridParams& grid, float diameter) {
    int layer = 0;
    float cell = grid.cell_size0;
    while (diameter > cell && layer < grid.layer_count - 1) {
        cell *= 2.0f;
        ++layer;
    }
    return layer;
}

/// @brief Bins of a histogram of positive floats by their binary exponent (float_octave).
constexpr int float_octaves = 256;

/// @brief The bin of x >= 0 in such a histogram: its biased binary exponent, so that bin e holds
/// [2^(e-127), 2^(e-126)) (0 for zero and subnormals, 255 for infinity).
KDET_HD inline std::uint32_t float_octave(float x) {
    std::uint32_t bits;
    memcpy(&bits, &x, sizeof bits);
    return (bits >> 23) & 0xffu;
}

/// @brief The upper end of bin e < 254 of float_octave: 2^(e-126).
KDET_HD inline float float_octave_end(std::uint32_t e) { return power_of_two(static_cast<int>(e) - 126); }

/// @brief 2^-layer as a float (exact for 0 <= layer < 127).
KDET_HD inline float layer_scale(int layer) { return power_of_two(-layer); }

/// @brief Cell index along one axis on `layer`; monotone in x, clamped, and safe for NaN.
KDET_HD inline std::uint32_t cell_index(const GridParams& grid, float x, float origin, int layer) {
    // Scaling by a power of two keeps the map monotone, which the completeness argument needs. Halved
    // first (exact but for subnormals, and monotone), the difference cannot overflow: across a region
    // wider than the largest float it became infinite, and a box spanned 2^30 cells per axis.
    float scaled = (x * 0.5f - origin * 0.5f) * (grid.inv_cell_size0 * 2.0f) * layer_scale(layer);
    const float limit = 1073741824.0f; // 2^30: stays exact and inside uint32
    if (!(scaled >= 0.0f)) scaled = 0.0f;
    if (scaled > limit) scaled = limit;
    return static_cast<std::uint32_t>(scaled);
}

/// @brief Inclusive range of cells a box overlaps on one layer.
struct CellRange {
    std::uint32_t lo[3];
    std::uint32_t hi[3];
};

/// @brief Calls go_on(x, y, z) for each cell of r, x fastest, until it returns false (then returns
/// false itself; true once every cell was visited): one loop whose
/// steps wrap x and y through masks, so that only its end mispredicts (three nested loops of one or
/// two steps each mispredicted at each of their ends; selects became branches again). r must not be
/// empty along any axis, as cell_range's ranges never are (cell_index is monotone).
template <class GoOn>
KDET_HD KDET_ALWAYS_INLINE bool for_each_cell(const CellRange& r, GoOn&& go_on) {
    std::uint32_t x = r.lo[0], y = r.lo[1], z = r.lo[2];
    do {
        if (!go_on(x, y, z)) return false;
        // All ones where x (and then y) is at its range's end and wraps.
        const std::uint32_t next_row = 0u - static_cast<std::uint32_t>(x == r.hi[0]);
        const std::uint32_t next_slice = next_row & (0u - static_cast<std::uint32_t>(y == r.hi[1]));
        x = ((x + 1u) & ~next_row) | (r.lo[0] & next_row);
        y = ((y - next_row) & ~next_slice) | (r.lo[1] & next_slice);
        z -= next_slice;
    } while (z <= r.hi[2]);
    return true;
}

/// @brief The axes along which cell (x, y, z) of range r is the range's first (bit a for axis a):
/// a box's start bits in the grid, and what the one-cell rule asks of the other box elsewhere.
KDET_HD inline std::uint32_t first_cell_axes(const CellRange& r, std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    return (x == r.lo[0] ? 1u : 0u) | (y == r.lo[1] ? 2u : 0u) | (z == r.lo[2] ? 4u : 0u);
}

KDET_HD inline CellRange cell_range(const GridParams& grid, const Aabb& box, int layer) {
    CellRange r;
    r.lo[0] = cell_index(grid, box.lo.x, grid.origin.x, layer);
    r.lo[1] = cell_index(grid, box.lo.y, grid.origin.y, layer);
    r.lo[2] = cell_index(grid, box.lo.z, grid.origin.z, layer);
    r.hi[0] = cell_index(grid, box.hi.x, grid.origin.x, layer);
    r.hi[1] = cell_index(grid, box.hi.y, grid.origin.y, layer);
    r.hi[2] = cell_index(grid, box.hi.z, grid.origin.z, layer);
    return r;
}

/// @brief The cell coordinates as hashed and stored: wrapped to cell_coordinate_bits.
KDET_HD inline CellCoord make_cell(std::uint32_t x, std::uint32_t y, std::uint32_t z, int layer) {
    const std::uint32_t mask = (1u << cell_coordinate_bits) - 1u;
    return CellCoord{x & mask, y & mask, z & mask, static_cast<std::uint32_t>(layer)};
}

/// @brief 64-bit key that identifies a (wrapped) cell in the table; never 0 so 0 can mean "none".
KDET_HD inline std::uint64_t cell_key(CellCoord c) {
    return (static_cast<std::uint64_t>(c.layer + 1) << (3 * cell_coordinate_bits)) |
           (static_cast<std::uint64_t>(c.x) << (2 * cell_coordinate_bits)) |
           (static_cast<std::uint64_t>(c.y) << cell_coordinate_bits) | static_cast<std::uint64_t>(c.z);
}

} // namespace kdet
