#pragma once
/// @file sat.hpp
/// @brief Separating axis tests for two tetrahedra: 44 axes (4 + 4 face normals, 36 edge cross
/// products), face normals only, and the variant that also returns the minimum translation vector.
///
/// Closed sets: touching tets intersect. A separation is reported only when some axis shows a gap
/// above k_gap_tolerance (relative to the longest edge), so an intersecting pair is never reported
/// as separated; pairs closer than that tolerance count as intersecting.

#include "geometry/tet_pair.hpp"

namespace kdet::narrow {

/// @brief Best axis so far for the minimum translation vector.
struct MtvState {
    float overlap;  ///< smallest overlap so far, in local units (negative: a gap within tolerance)
    vec3 direction; ///< unit direction that moves the second tet out by `overlap`
};

/// @brief Decides one axis (any length; length2 is its squared length > 0) from the overlaps left
/// when the second tet moves along +axis (`up`) and -axis (`down`), times |axis|: true when it
/// separates the tets, i.e. gap > tolerance * |axis|, tested squared so that no square root is needed.
/// With track, also keeps the axis of least overlap (normalised only when it becomes the best); `bias`
/// is how much smaller an overlap must be to replace the current best.
template <bool track>
KDET_HD inline bool overlaps_separate(float up, float down, vec3 axis, float length2, float bias, MtvState& best) {
    const float overlap = min_f(up, down);
    if (overlap < 0.0f && overlap * overlap > k_gap_tolerance * k_gap_tolerance * length2) return true;
    if constexpr (track) {
        // Is overlap / |axis| < target? Compared squared, by sign.
        const float target = best.overlap - bias;
        const float target2 = target * target * length2, overlap2 = overlap * overlap;
        const bool better = target > 0.0f ? (overlap < 0.0f || overlap2 < target2) : (overlap < 0.0f && overlap2 > target2);
        if (better) {
            const float inverse = 1.0f / sqrtf(length2);
            best = MtvState{overlap * inverse, (up <= down ? axis : -axis) * inverse};
        }
    }
    return false;
}

/// @brief Tests one axis: overlaps_separate on the tets' projections onto it.
template <bool track>
KDET_HD inline bool axis_separates(const LocalPair& p, vec3 axis, float length2, float bias, MtvState& best) {
    const Interval ia = project(p.a, axis), ib = project(p.b, axis);
    return overlaps_separate<track>(ia.hi - ib.lo, ib.hi - ia.lo, axis, length2, bias, best);
}

/// @brief Tests the 6 axes cross(edge i of A, edge j of B), k_edge_lanes at a time (edge_axis_lanes);
/// true when one separates. With track they are decided in order of j, as one at a time would be.
template <bool track>
KDET_HD inline bool edge_axes_separate(const LocalPair& p, int i, MtvState& best) {
    const float usable_scale = k_parallel_sine * k_parallel_sine * p.length2_a[i];
    EdgeAxisLanes lanes;
    for (int first = 0; first < 6; first += k_edge_lanes) {
        edge_axis_lanes(p, i, first, lanes);
        if constexpr (!track) {
            int separates = 0;
            KDET_VECTOR_LOOP
            for (int l = 0; l < k_edge_lanes; ++l) {
                const float length2 = lanes.x[l] * lanes.x[l] + lanes.y[l] * lanes.y[l] + lanes.z[l] * lanes.z[l];
                const float overlap = min_f(lanes.over_up[l], lanes.over_down[l]);
                // The conditions of edge_axis and overlaps_separate, combined without branches (& rather
                // than &&) so that the lanes stay in vector instructions.
                const int usable = length2 > usable_scale * p.length2_b[first + l];
                const int gap = overlap < 0.0f;
                const int wide = overlap * overlap > k_gap_tolerance * k_gap_tolerance * length2;
                separates |= usable & gap & wide;
            }
            if (separates) return true;
        } else {
            for (int j = first; j < 6 && j < first + k_edge_lanes; ++j) {
                const int l = j - first;
                const vec3 axis{lanes.x[l], lanes.y[l], lanes.z[l]};
                const float length2 = length_squared(axis);
                if (length2 > usable_scale * p.length2_b[j] &&
                    overlaps_separate<track>(lanes.over_up[l], lanes.over_down[l], axis, length2, k_gap_tolerance, best))
                    return true;
            }
        }
    }
    return false;
}

/// @brief Runs the face axes (and, with edges, the 36 edge axes); true as soon as one separates.
/// Face axes go first: they are cheaper and separate most pairs. Edge axes must beat a face axis by
/// more than the tolerance to become the MTV axis, so near-ties keep the more stable face normal.
/// `edges_first` (without track, for pairs the face-plane pre-test left undecided, which a face axis
/// seldom separates) runs the edge axes first; the order changes only when a separation is found,
/// never the answer.
template <bool track>
KDET_HD inline bool sat_separates(const LocalPair& p, bool edges, MtvState& best, bool edges_first = false) {
    const auto face_axes_separate = [&]() {
        vec3 axis;
        float length2;
        for (int k = 0; k < 4; ++k)
            if (face_axis(p.a, k, axis, length2) && axis_separates<track>(p, axis, length2, 0.0f, best)) return true;
        for (int k = 0; k < 4; ++k)
            if (face_axis(p.b, k, axis, length2) && axis_separates<track>(p, axis, length2, 0.0f, best)) return true;
        return false;
    };
    const auto all_edge_axes_separate = [&]() {
        for (int i = 0; i < 6; ++i)
            if (edge_axes_separate<track>(p, i, best)) return true;
        return false;
    };
    if (!edges) return face_axes_separate();
    if (edges_first && !track) return all_edge_axes_separate() || face_axes_separate();
    return face_axes_separate() || all_edge_axes_separate();
}

/// @brief 44-axis SAT (edges true) or face normals only (edges false) on input coordinates;
/// `edges_first` as for sat_separates.
KDET_HD inline bool sat_intersect(const vec3 a[4], const vec3 b[4], bool edges, bool edges_first = false) {
    LocalPair p;
    if (!make_local_pair(a, b, p)) return points_coincide(a[0], b[0]);
    MtvState unused{k_huge, vec3{0.0f, 0.0f, 0.0f}};
    return !sat_separates<false>(p, edges, unused, edges_first);
}

/// @brief 44-axis SAT with the minimum translation vector; see tets_intersect_sat_mtv.
KDET_HD inline bool sat_mtv_intersect(const vec3 a[4], const vec3 b[4], float& depth, vec3& direction) {
    LocalPair p;
    if (!make_local_pair(a, b, p)) {
        if (!points_coincide(a[0], b[0])) return false;
        depth = 0.0f;
        direction = vec3{0.0f, 0.0f, 0.0f};
        return true;
    }
    MtvState best{k_huge, vec3{0.0f, 0.0f, 0.0f}};
    if (sat_separates<true>(p, true, best)) return false;
    if (best.overlap == k_huge) { // no usable axis: both tets are parallel segments or points
        depth = 0.0f;
        direction = vec3{0.0f, 0.0f, 0.0f};
        return true;
    }
    depth = max_f(best.overlap, 0.0f) * p.scale;
    direction = best.direction;
    return true;
}

} // namespace kdet::narrow
