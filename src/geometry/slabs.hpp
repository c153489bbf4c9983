#pragma once
/// @file slabs.hpp
/// @brief A tet's extent along eight directions besides the coordinate axes (its box's), computed once
/// per tet and frame, so that a pair whose boxes overlap but which lies apart along one of them is
/// rejected from 64 bytes per tet, before the face-plane pre-test loads its planes.
///
/// The directions are the four space diagonals (1,1,1), (1,1,-1), (1,-1,1), (-1,1,1) and four of
/// the six face diagonals, (1,1,0), (1,-1,0), (1,0,1), (1,0,-1): eight lanes, one vector row per bound.
/// Of the box-overlapping pairs of the peer comparison's cases (bench/cpu_vs_cgal.cpp) they separate
/// most, the space diagonals alone fewer, and the other two face diagonals would add little
/// (docs/performance.md): most of them pairs that a face plane would also have separated, at a
/// fraction of its cost, and some that only an edge axis separates, which no longer reach the narrow
/// phase.
///
/// A rejection is certain, with a margin far beyond every test's tolerance: a projection, a sum of
/// two or three coordinates with signs, is off by at most 2.0000003 u M (u = 2^-24, M the tet's
/// largest |x| + |y| + |z|), and each bound is widened by 2^-21 M + 2^-10 l (l the tet's longest edge),
/// which also covers the rounding of the widening itself (u M more). So two tets whose widened extents
/// are disjoint along a direction d lie apart along it by more than 2^-10 (l_a + l_b), and are at
/// least that over |d| <= sqrt(3), 5.6e-4 L (L the pair's longest edge), apart: far beyond the 1e-5 L
/// within which sat, sat_mtv, gjk and fast may call a separated pair intersecting, and the 3e-5 L of
/// fast on needles (tests/cgal/test_narrow_phase_cgal.cpp), and exact agrees on every pair. Only
/// sat_no_edges, which reports pairs that only an edge axis separates however far apart, must not use
/// it. Non-finite sums give infinite or NaN bounds, which separate nothing.
///
/// With a margin m (DetectorOptions::margin) each bound is widened by m more: two tets at most m apart
/// project at most |d| m <= sqrt(3) m apart along d, less than the 2 m the two widenings add, and the
/// rest, over 0.26 m, covers the rounding that m adds (u m per bound). So disjoint extents prove the
/// tets more than m apart, and at m = 0 the bounds are those without a margin.

#include "geometry/vec3.hpp"

#include <cstdint>

namespace kdet {

constexpr int slab_directions = 8;

/// @brief Lower and upper bounds of a tet's projections onto the slab directions, widened (see the
/// file comment); a row per bound, a lane per direction, each row on a 32-byte boundary for aligned
/// vector loads (on 64 bytes, a line a tet, it measured the same).
struct alignas(32) TetSlabs {
    float lo[slab_directions];
    float hi[slab_directions];
};

/// @brief The widened slabs of tet v, whose longest edge is `longest`, for pairs within `margin`.
KDET_HD inline TetSlabs tet_slabs(const vec3 v[4], float longest, float margin) {
    float largest_sum = 0.0f;
    for (int k = 0; k < 4; ++k) largest_sum = max_f(largest_sum, fabsf(v[k].x) + fabsf(v[k].y) + fabsf(v[k].z));
    const float widen = 0x1p-21f * largest_sum + 0x1p-10f * longest + margin;
    TetSlabs s;
    for (int d = 0; d < slab_directions; ++d) {
        s.lo[d] = INFINITY;
        s.hi[d] = -INFINITY;
    }
    for (int k = 0; k < 4; ++k) {
        const vec3 p = v[k];
        const float along[slab_directions] = {p.x + p.y + p.z, p.x + p.y - p.z, p.x - p.y + p.z, -p.x + p.y + p.z,
                                              p.x + p.y,       p.x - p.y,       p.x + p.z,       p.x - p.z};
        for (int d = 0; d < slab_directions; ++d) {
            s.lo[d] = min_f(s.lo[d], along[d]);
            s.hi[d] = max_f(s.hi[d], along[d]);
        }
    }
    for (int d = 0; d < slab_directions; ++d) {
        s.lo[d] -= widen;
        s.hi[d] += widen;
    }
    return s;
}

/// @brief Whether the slabs prove two tets apart: disjoint along some direction. All eight lanes are
/// compared, without a branch (vector instructions on the host); a NaN bound compares false and so
/// separates nothing.
KDET_HD KDET_ALWAYS_INLINE bool slabs_separate(const TetSlabs& a, const TetSlabs& b) {
    std::uint32_t apart[slab_directions];
    KDET_VECTOR_LOOP
    for (int d = 0; d < slab_directions; ++d) apart[d] = (a.hi[d] < b.lo[d]) | (b.hi[d] < a.lo[d]) ? ~0u : 0u;
    return lane_bits(apart) != 0;
}

} // namespace kdet
