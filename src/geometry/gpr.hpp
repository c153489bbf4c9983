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
/// conditioned at sharp edges (the combined normal is short when the faces are nearly opposite), so an
/// edge whose decision is unsure is decided by its 6 SAT edge-edge axes instead, and a pair with a
/// tet too flat to orient goes to the 44-axis SAT.

#include "geometry/sat.hpp"

namespace kdet::narrow {

/// @brief Signed distances of the other tet's vertices to a tet's outward face planes.
struct FacePlanes {
    float distance[4][4]; ///< [face][vertex of the other tet], in local units
};

/// @brief What building a tet's face planes found.
enum class FaceOutcome {
    go_on,     ///< all four planes built, none separates
    separated, ///< a face plane has the other tet beyond the tolerance
    flat,      ///< a face is degenerate or an opposite vertex is within the tolerance of its face
               ///< plane: the orientation is unsure, the pair goes to the SAT
};

/// @brief Builds the outward face planes of tet `own` and the distances of `other`'s vertices to
/// them, face by face, stopping at the first face that separates.
KDET_HD inline FaceOutcome build_face_planes(const vec3 own[4], const vec3 other[4], FacePlanes& f) {
    for (int k = 0; k < 4; ++k) {
        vec3 n;
        float length2;
        if (!face_axis(own, k, n, length2)) return FaceOutcome::flat;
        n = unit(n, length2);
        const float d0 = dot(own[(k + 1) & 3], n), d1 = dot(own[(k + 2) & 3], n), d2 = dot(own[(k + 3) & 3], n);
        const float face_lo = min_f(min_f(d0, d1), d2), face_hi = max_f(max_f(d0, d1), d2);
        const float apex = dot(own[k], n);
        float offset; // the tet's own highest projection onto the outward normal
        if (apex < face_lo - k_gap_tolerance) {
            offset = face_hi;
        } else if (apex > face_hi + k_gap_tolerance) {
            n = -n;
            offset = -face_lo;
        } else {
            return FaceOutcome::flat;
        }
        float nearest = k_huge;
        for (int j = 0; j < 4; ++j) {
            f.distance[k][j] = dot(n, other[j]) - offset;
            nearest = min_f(nearest, f.distance[k][j]);
        }
        if (nearest > k_gap_tolerance) return FaceOutcome::separated;
    }
    return FaceOutcome::go_on;
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
    const FaceOutcome outcome_a = build_face_planes(p.a, p.b, fa);
    if (outcome_a == FaceOutcome::separated) return false;
    if (outcome_a == FaceOutcome::flat) return !sat_separates<false>(p, true, unused);
    if (some_vertex_inside(fa)) return true;
    const FaceOutcome outcome_b = build_face_planes(p.b, p.a, fb);
    if (outcome_b == FaceOutcome::separated) return false;
    if (outcome_b == FaceOutcome::flat) return !sat_separates<false>(p, true, unused);
    if (some_vertex_inside(fb)) return true;
    // Faces i and k of A share the edge opposite them: with pairs enumerated like edges,
    // pair q = (edge_first(q), edge_second(q)) shares edge 5 - q.
    for (int q = 0; q < 6; ++q) {
        const float* di = fa.distance[edge_first(q)];
        const float* dk = fa.distance[edge_second(q)];
        if (wedge_separates(di, dk, k_gap_tolerance)) return false;
        // Unsure within the tolerance (a sharp edge amplifies it): decide with the edge's SAT axes.
        if (wedge_separates(di, dk, -k_gap_tolerance) && edge_axes_separate<false>(p, 5 - q, unused)) return false;
    }
    return true;
}

} // namespace kdet::narrow
