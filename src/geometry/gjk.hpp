#pragma once
/// @file gjk.hpp
/// @brief GJK on the Minkowski difference of two tetrahedra, with the signed-volumes distance
/// sub-algorithm of Montanari, Petrinic and Barbieri (2017).
///
/// It runs in the pair's unit-size frame, so every tolerance is relative to the longest edge. GJK
/// only proposes a direction: a separation is reported when the projection gap of the two tets along
/// that direction (the same certificate as the SAT) exceeds k_gap_tolerance. So the test never misses
/// an intersecting pair, whatever the rounding inside the iterations. When GJK ends at a distance
/// above the tolerance that its direction cannot certify (rounding, on pairs much closer than their
/// size), the SAT's axes decide.

#include "geometry/sat.hpp"

namespace kdet::narrow {

/// @brief More than enough for two tets (16 Minkowski vertices); reached only on rounding stalls.
constexpr int k_gjk_max_iterations = 32;

/// @brief GJK stops when the next support point improves the distance bound by less than this
/// fraction of |v|^2: v is then the closest point up to a relative error far below the test margins.
constexpr float k_gjk_relative_progress = 1e-5f;

/// @brief Up to four points of the Minkowski difference.
struct Simplex {
    vec3 p[4];
    int size;
};

/// @brief True when a and b are both nonzero with the same sign (the comparison of the paper).
KDET_HD inline bool same_sign(float a, float b) { return (a > 0.0f && b > 0.0f) || (a < 0.0f && b < 0.0f); }

/// @brief Index of the largest component of |v|.
KDET_HD inline int dominant_axis(vec3 v) {
    const float x = fabsf(v.x), y = fabsf(v.y), z = fabsf(v.z);
    return x >= y && x >= z ? 0 : (y >= z ? 1 : 2);
}

/// @brief Closest point to the origin on segment s.p[0] s.p[1]; s keeps the points it needs.
/// Barycentric weights are signed lengths along the segment's dominant axis.
KDET_HD inline vec3 closest_on_segment(Simplex& s) {
    const vec3 s0 = s.p[0], s1 = s.p[1], t = s1 - s0;
    const float tt = dot(t, t);
    if (!(tt > 0.0f)) {
        s.size = 1;
        return s0;
    }
    const vec3 foot = s0 - t * (dot(s0, t) / tt); // projection of the origin onto the line
    const int k = dominant_axis(t);
    const float length = component(s1, k) - component(s0, k);
    const float w0 = component(s1, k) - component(foot, k); // weight of s0, times length
    const float w1 = component(foot, k) - component(s0, k); // weight of s1, times length
    if (same_sign(length, w0) && same_sign(length, w1)) return foot;
    s.size = 1;
    if (!same_sign(length, w1)) return s0; // the foot lies before s0
    s.p[0] = s1;
    return s1;
}

/// @brief Keeps in `best` the candidate simplex whose closest point is nearest to the origin.
KDET_HD inline void keep_nearer(const Simplex& candidate, vec3 point, Simplex& best, vec3& best_point,
                                float& best_distance2) {
    const float d2 = length_squared(point);
    if (d2 < best_distance2) {
        best = candidate;
        best_point = point;
        best_distance2 = d2;
    }
}

/// @brief Twice the signed area of triangle a b c projected onto the coordinate plane (i, j).
KDET_HD inline float planar_area2(vec3 a, vec3 b, vec3 c, int i, int j) {
    return (component(b, i) - component(a, i)) * (component(c, j) - component(a, j)) -
           (component(b, j) - component(a, j)) * (component(c, i) - component(a, i));
}

/// @brief Closest point to the origin on triangle s.p[0..2]. Barycentric weights are signed areas in
/// the coordinate plane where the triangle's projection is largest; when the origin's projection
/// falls outside, the edges opposite the vertices with wrong-signed weights are searched.
KDET_HD inline vec3 closest_on_triangle(Simplex& s) {
    const vec3 s0 = s.p[0], s1 = s.p[1], s2 = s.p[2];
    const vec3 n = cross(s1 - s0, s2 - s0);
    const float nn = dot(n, n);
    float weight[3] = {0.0f, 0.0f, 0.0f};
    float area = 0.0f;
    vec3 foot = s0;
    if (nn > 0.0f) {
        foot = n * (dot(s0, n) / nn); // projection of the origin onto the plane
        const int k = dominant_axis(n);
        const int i = (k + 1) % 3, j = (k + 2) % 3; // (i, j, k) cyclic: 2-D areas equal n's k component
        area = planar_area2(s0, s1, s2, i, j);
        weight[0] = planar_area2(foot, s1, s2, i, j);
        weight[1] = planar_area2(s0, foot, s2, i, j);
        weight[2] = planar_area2(s0, s1, foot, i, j);
        if (same_sign(area, weight[0]) && same_sign(area, weight[1]) && same_sign(area, weight[2])) return foot;
    }
    Simplex best = s;
    vec3 best_point = s0;
    float best_distance2 = k_huge;
    for (int m = 0; m < 3; ++m) {
        if (same_sign(area, weight[m])) continue;
        Simplex edge{{s.p[(m + 1) % 3], s.p[(m + 2) % 3]}, 2};
        const vec3 point = closest_on_segment(edge);
        keep_nearer(edge, point, best, best_point, best_distance2);
    }
    s = best;
    return best_point;
}

/// @brief Closest point to the origin on tetrahedron s.p[0..3]; keeps all four points only when the
/// origin is inside. Barycentric weights are the signed volumes with one vertex moved to the origin.
KDET_HD inline vec3 closest_on_tetrahedron(Simplex& s) {
    const vec3 s0 = s.p[0], s1 = s.p[1], s2 = s.p[2], s3 = s.p[3];
    const float weight[4] = {dot(s1, cross(s2, s3)), -dot(s0, cross(s2, s3)), dot(s0, cross(s1, s3)),
                             -dot(s0, cross(s1, s2))};
    const float volume = weight[0] + weight[1] + weight[2] + weight[3];
    if (same_sign(volume, weight[0]) && same_sign(volume, weight[1]) && same_sign(volume, weight[2]) &&
        same_sign(volume, weight[3]))
        return vec3{0.0f, 0.0f, 0.0f};
    Simplex best = s;
    vec3 best_point = s0;
    float best_distance2 = k_huge;
    for (int m = 0; m < 4; ++m) {
        if (same_sign(volume, weight[m])) continue;
        Simplex face{{s.p[(m + 1) & 3], s.p[(m + 2) & 3], s.p[(m + 3) & 3]}, 3};
        const vec3 point = closest_on_triangle(face);
        keep_nearer(face, point, best, best_point, best_distance2);
    }
    s = best;
    return best_point;
}

/// @brief Signed-volumes sub-algorithm: closest point of the simplex's hull to the origin; s is
/// reduced to the smallest sub-simplex that holds it.
KDET_HD inline vec3 closest_on_simplex(Simplex& s) {
    switch (s.size) {
    case 4:
        return closest_on_tetrahedron(s);
    case 3:
        return closest_on_triangle(s);
    case 2:
        return closest_on_segment(s);
    default:
        return s.p[0];
    }
}

/// @brief The point of the Minkowski difference A - B with the smallest projection onto v.
KDET_HD inline vec3 lowest_point(const LocalPair& p, vec3 v) {
    int ia, ib;
    lowest_difference(p.a, p.b, v, ia, ib);
    return p.a[ia] - p.b[ib];
}

/// @brief True when the projections onto v (any length) prove the tets separated.
KDET_HD inline bool direction_separates(const LocalPair& p, vec3 v) {
    const float vv = length_squared(v);
    return vv > 0.0f && projection_gap(p, v * (1.0f / sqrtf(vv))) > k_gap_tolerance;
}

/// @brief GJK boolean test on input coordinates; see tets_intersect_gjk.
KDET_HD inline bool gjk_intersect(const vec3 a[4], const vec3 b[4]) {
    LocalPair p;
    if (!make_local_pair(a, b, p)) return points_coincide(a[0], b[0]);
    // Start from a vertex of A - B, held in the simplex so that |v| can only decrease.
    vec3 v = p.a[0] - p.b[0];
    Simplex s{{v}, 1};
    float vv = length_squared(v);
    for (int iteration = 0; iteration < k_gjk_max_iterations; ++iteration) {
        // The origin lies within the tolerance of A - B: touching counts as intersecting.
        if (vv <= k_gap_tolerance * k_gap_tolerance) return true;
        const vec3 w = lowest_point(p, v);
        const float vw = dot(v, w);
        if (vw > 0.0f && direction_separates(p, v)) return false;
        if (vv - vw <= k_gjk_relative_progress * vv) break; // v is the closest point
        bool repeated = false;
        for (int i = 0; i < s.size; ++i) repeated = repeated || points_coincide(s.p[i], w);
        if (repeated) break; // cycling on rounding
        s.p[s.size++] = w;
        const vec3 next = closest_on_simplex(s);
        if (s.size == 4) return true; // the origin is inside a simplex of A - B
        const float next_vv = length_squared(next);
        if (!(next_vv < vv)) {
            // No progress, through rounding. When the distance is small against the tets, nearly
            // equal distances can come with very different directions, and the new simplex (often a
            // face of A - B, whose normal is an exact SAT axis) may hold the one that separates.
            if (direction_separates(p, next)) return false;
            break;
        }
        v = next;
        vv = next_vv;
    }
    if (direction_separates(p, v)) return false;
    // GJK sees a distance above the tolerance, but its direction does not prove it. When the distance
    // is small against the tets, the direction of a closest point computed from Minkowski points of
    // size 1 carries rounding of order eps / distance, which can tip it out of the closest feature's
    // normal cone; the SAT's axes come from the short edges and decide such rare pairs.
    MtvState unused{k_huge, vec3{0.0f, 0.0f, 0.0f}};
    return vv <= k_gap_tolerance * k_gap_tolerance || !sat_separates<false>(p, true, unused);
}

} // namespace kdet::narrow
