#pragma once
/// @file gpr.hpp
/// @brief Face-plane tetrahedron test after the idea of Ganovelli, Ponchio and Rocchini (2002).
///
/// The signed distances of B's four vertices to A's four face planes (16 numbers) decide A's face
/// axes and, two faces at a time, A's six edges: a plane through an edge of A whose normal lies
/// between the normals of the edge's two faces is lambda * plane_i + mu * plane_k (lambda, mu >= 0),
/// so it separates B exactly when the 2-D points (d_i, d_k) of B's vertices lie in an open half-plane
/// with a normal in the positive quadrant, which 2x2 determinants decide. These planes include every
/// edge-edge axis of the SAT (the normal cones of A's edges cover the Minkowski difference's edge-edge
/// faces), so with B's face planes the test is complete, without any cross product of edges.
///
/// Robustness: each face normal is oriented against its opposite vertex (vertex order does not matter)
/// and each plane is placed at the tet's own support value, so A lies inside it whatever the rounding.
/// Every decision has three outcomes with the tolerance k_gap_tolerance. The edge decisions are poorly
/// conditioned at sharp edges (the combined normal is short when the faces are nearly opposite), so a
/// pair whose edge decision is uncertain, or a tet too flat to orient, goes to the 44-axis SAT.

#include "geometry/sat.hpp"

namespace kdet::narrow {

/// @brief Outward unit normals of a tet's faces and the other tet's distances to them.
struct FacePlanes {
    vec3 normal[4];
    float offset[4];      ///< the tet's own highest projection onto normal[k]
    float distance[4][4]; ///< [face][vertex of the other tet], in local units
};

/// @brief Builds the outward face planes of tet v. Returns false when a face is degenerate or an
/// opposite vertex is within the tolerance of its face plane (the orientation is then unsure).
KDET_HD inline bool outward_planes(const vec3 v[4], FacePlanes& f) {
    for (int k = 0; k < 4; ++k) {
        vec3 n;
        if (!unit_face_normal(v, k, n)) return false;
        const float d0 = dot(v[(k + 1) & 3], n), d1 = dot(v[(k + 2) & 3], n), d2 = dot(v[(k + 3) & 3], n);
        const float face_lo = min_f(min_f(d0, d1), d2), face_hi = max_f(max_f(d0, d1), d2);
        const float apex = dot(v[k], n);
        if (apex < face_lo - k_gap_tolerance) {
            f.normal[k] = n;
            f.offset[k] = face_hi;
        } else if (apex > face_hi + k_gap_tolerance) {
            f.normal[k] = -n;
            f.offset[k] = -face_lo;
        } else {
            return false;
        }
    }
    return true;
}

/// @brief Fills f.distance with the signed distances of the vertices w to the planes of f.
KDET_HD inline void plane_distances(const vec3 w[4], FacePlanes& f) {
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 4; ++j) f.distance[k][j] = dot(f.normal[k], w[j]) - f.offset[k];
}

/// @brief True when some face plane has every vertex farther than the tolerance.
KDET_HD inline bool some_face_separates(const FacePlanes& f) {
    for (int k = 0; k < 4; ++k) {
        const float nearest = min_f(min_f(f.distance[k][0], f.distance[k][1]), min_f(f.distance[k][2], f.distance[k][3]));
        if (nearest > k_gap_tolerance) return true;
    }
    return false;
}

/// @brief True when some vertex is inside all four planes by more than the tolerance: the tets meet.
KDET_HD inline bool some_vertex_inside(const FacePlanes& f) {
    for (int j = 0; j < 4; ++j) {
        const float farthest = max_f(max_f(f.distance[0][j], f.distance[1][j]), max_f(f.distance[2][j], f.distance[3][j]));
        if (farthest < -k_gap_tolerance) return true;
    }
    return false;
}

/// @brief Whether a plane lambda * plane_i + mu * plane_k (lambda, mu >= 0) has all four vertices
/// on its positive side, after moving both planes outward by `shift` (negative: inward).
/// di and dk are the vertices' distances to the two planes.
KDET_HD inline bool wedge_separates(const float di[4], const float dk[4], float shift) {
    float x[4], y[4];
    for (int j = 0; j < 4; ++j) {
        x[j] = di[j] - shift;
        y[j] = dk[j] - shift;
        if (x[j] <= 0.0f && y[j] <= 0.0f) return false; // behind both planes: behind every combination
    }
    // A vertex ahead of plane i only (x > 0 >= y) needs lambda / mu > -y / x; one ahead of plane k
    // only (y > 0 >= x) needs lambda / mu < y / -x. Both hold iff x_j y_m > y_j x_m for all such j, m.
    // The products are compared with a relative margin that covers their rounding.
    for (int j = 0; j < 4; ++j) {
        if (!(x[j] > 0.0f && y[j] <= 0.0f)) continue;
        for (int m = 0; m < 4; ++m) {
            if (!(y[m] > 0.0f && x[m] <= 0.0f)) continue;
            if (!(x[j] * y[m] > (y[j] * x[m]) * (1.0f + 4.0f * k_float_eps))) return false;
        }
    }
    return true;
}

/// @brief Face-plane test on input coordinates; see tets_intersect_fast.
KDET_HD inline bool gpr_intersect(const vec3 a[4], const vec3 b[4]) {
    LocalPair p;
    if (!make_local_pair(a, b, p)) return points_coincide(a[0], b[0]);
    MtvState unused{k_huge, vec3{0.0f, 0.0f, 0.0f}};
    FacePlanes fa, fb;
    if (!outward_planes(p.a, fa) || !outward_planes(p.b, fb)) return !sat_separates<false>(p, true, unused);
    plane_distances(p.b, fa);
    if (some_face_separates(fa)) return false;
    if (some_vertex_inside(fa)) return true;
    plane_distances(p.a, fb);
    if (some_face_separates(fb)) return false;
    if (some_vertex_inside(fb)) return true;
    bool unsure = false;
    for (int i = 0; i < 3; ++i)
        for (int k = i + 1; k < 4; ++k) { // faces i and k of A share one edge
            if (wedge_separates(fa.distance[i], fa.distance[k], k_gap_tolerance)) return false;
            unsure = unsure || wedge_separates(fa.distance[i], fa.distance[k], -k_gap_tolerance);
        }
    return !unsure || !sat_separates<false>(p, true, unused);
}

} // namespace kdet::narrow
