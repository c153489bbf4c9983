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

/// @brief Tests one unit axis: true when it separates the tets. With track, also keeps the axis of
/// least overlap; `bias` is how much smaller an overlap must be to replace the current best.
template <bool track>
KDET_HD inline bool axis_separates(const LocalPair& p, vec3 axis, float bias, MtvState& best) {
    const Interval ia = project(p.a, axis), ib = project(p.b, axis);
    const float up = ia.hi - ib.lo;   // overlap left if the second tet moves along +axis
    const float down = ib.hi - ia.lo; // overlap left if it moves along -axis
    if (up < -k_gap_tolerance || down < -k_gap_tolerance) return true;
    if (track) {
        const float overlap = min_f(up, down);
        if (overlap < best.overlap - bias) best = MtvState{overlap, up <= down ? axis : -axis};
    }
    return false;
}

/// @brief Runs the face axes (and, with edges, the 36 edge axes); true as soon as one separates.
/// Face axes go first: they are cheaper and separate most pairs. Edge axes must beat a face axis by
/// more than the tolerance to become the MTV axis, so near-ties keep the more stable face normal.
template <bool track>
KDET_HD inline bool sat_separates(const LocalPair& p, bool edges, MtvState& best) {
    vec3 axis;
    for (int k = 0; k < 4; ++k)
        if (unit_face_normal(p.a, k, axis) && axis_separates<track>(p, axis, 0.0f, best)) return true;
    for (int k = 0; k < 4; ++k)
        if (unit_face_normal(p.b, k, axis) && axis_separates<track>(p, axis, 0.0f, best)) return true;
    if (!edges) return false;
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j)
            if (unit_cross(p.edge_a[i], p.length2_a[i], p.edge_b[j], p.length2_b[j], axis) &&
                axis_separates<track>(p, axis, k_gap_tolerance, best))
                return true;
    return false;
}

/// @brief 44-axis SAT (edges true) or face normals only (edges false) on input coordinates.
KDET_HD inline bool sat_intersect(const vec3 a[4], const vec3 b[4], bool edges) {
    LocalPair p;
    if (!make_local_pair(a, b, p)) return points_coincide(a[0], b[0]);
    MtvState unused{k_huge, vec3{0.0f, 0.0f, 0.0f}};
    return !sat_separates<false>(p, edges, unused);
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
