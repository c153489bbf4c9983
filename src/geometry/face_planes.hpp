#pragma once
/// @file face_planes.hpp
/// @brief A pre-test for tet pairs from each tet's four face planes, computed once per tet and frame.
/// It proves a pair separated (one tet lies beyond a face plane of the other) or intersecting (a vertex
/// of one tet lies inside the other), each only by a margin far above every rounding involved, and
/// leaves all other pairs to the narrow-phase test. So it never changes what a test reports:
///
/// - Rounding of the pre-test itself. Coordinates are taken relative to the plane owner's vertex 0,
///   so a signed distance d = dot(n, w - origin) - offset (n of unit length within a few u, u = 2^-24)
///   is off by at most about 4u |w - origin| + 4u L_owner + u |d|. The pre-test runs on pairs whose
///   boxes overlap, where |w - origin| <= 2 sqrt(3) L (L: the pair's longest edge), so the error is
///   below 20 u L, about 1.2e-6 L.
/// - The tests' own axes. The narrow-phase tests compute the same face normals, from the same two
///   edges, in their frame (origin at the first tet's vertex 0, unit longest edge). There an edge
///   carries an error of up to about 2u |w - origin| <= 7u L, so for edges of length >= l_min meeting
///   at an angle with sine >= s the two normals differ in direction by at most about
///   (u / s)(14 L / l_min + 3) (times sqrt(3) for componentwise rounding), and a gap along them by that
///   times the pair's extent (<= 2 sqrt(3) L): with s = 1/64, below 3.3e-4 L^2 / l_min + 0.7e-4 L.
///   Faces whose two edges meet at a smaller sine are not used.
/// - The tests' tolerance: a separation needs a gap above 32 eps L (3.8e-6 L).
///
/// A face's margin is k_plane_margin L^2 / l_min(owner), k_plane_margin = 2^-10 (about 1e-3), more
/// than twice the sum of the above. A pair the pre-test separates therefore shows a gap above
/// 5e-4 L^2 / l_min along a face axis that every test computes (sat, sat_no_edges, sat_mtv, fast)
/// or falls back on (gjk decides with the SAT axes when its own direction does not prove the gap),
/// and is truly separated, so an exact test agrees too. A vertex found inside the other tet by that
/// margin makes the pair truly intersecting, and no test misses an intersecting pair.

#include "geometry/vec3.hpp"

#include <cstdint>

namespace kdet {

/// @brief Margin of the pre-test in units of L^2 / l_min (see the file comment).
constexpr float k_plane_margin = 1.0f / 1024.0f;

/// @brief Faces whose two normal-building edges meet at an angle with a smaller sine are not used.
constexpr float k_plane_min_sine = 1.0f / 64.0f;

/// @brief The four face planes of one tet, relative to its vertex 0, coordinate by coordinate so that
/// the four faces are evaluated together (vector instructions on the CPU).
struct TetPlanes {
    float nx[4], ny[4], nz[4]; ///< unit normal of face k (opposite vertex k), pointing away from vertex k; 0 if unused
    float offset[4];           ///< the tet's highest projection onto normal k, relative to origin
    vec3 origin;               ///< the tet's vertex 0
    float longest;             ///< longest edge
    float margin_scale;        ///< k_plane_margin / shortest edge: a face's margin is margin_scale * L^2
    std::uint32_t solid;       ///< 1 when all four faces are used and each opposite vertex lies clearly below
                               ///< its face: only then can the pre-test prove a vertex inside
};

/// @brief The face planes of tet v.
KDET_HD inline TetPlanes tet_planes(const vec3 v[4]) {
    TetPlanes p;
    p.origin = v[0];
    const vec3 q[4] = {make_vec3(0.0f, 0.0f, 0.0f), v[1] - v[0], v[2] - v[0], v[3] - v[0]};
    float longest2 = 0.0f, shortest2 = 3.4e38f;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
            const float l2 = length_squared(q[j] - q[i]);
            longest2 = max_f(longest2, l2);
            shortest2 = min_f(shortest2, l2);
        }
    p.longest = sqrtf(longest2);
    // A zero edge makes the scale infinite and every margin infinite (or NaN): nothing is decided.
    p.margin_scale = k_plane_margin / sqrtf(shortest2);
    p.solid = 1u;
    for (int k = 0; k < 4; ++k) {
        const vec3 a = q[(k + 1) & 3], b = q[(k + 2) & 3], c = q[(k + 3) & 3];
        // The normal comes from the two edges at the face's largest angle (opposite its longest edge).
        const vec3 ab = b - a, ac = c - a, bc = c - b;
        const float lab = length_squared(ab), lac = length_squared(ac), lbc = length_squared(bc);
        vec3 e = ab, f = ac;
        float le = lab, lf = lac;
        if (lab >= lbc && lab >= lac) {
            e = ac;
            f = bc;
            le = lac;
            lf = lbc;
        } else if (lac >= lbc) {
            f = bc;
            lf = lbc;
        }
        vec3 n = cross(e, f);
        const float n2 = length_squared(n);
        if (!(n2 > k_plane_min_sine * k_plane_min_sine * le * lf)) {
            p.nx[k] = p.ny[k] = p.nz[k] = p.offset[k] = 0.0f;
            p.solid = 0u;
            continue;
        }
        n = n * (1.0f / sqrtf(n2));
        if (dot(n, q[k] - a) > 0.0f) n = -n;
        float offset = 0.0f; // q[0] projects to 0
        for (int i = 1; i < 4; ++i) offset = max_f(offset, dot(n, q[i]));
        p.nx[k] = n.x;
        p.ny[k] = n.y;
        p.nz[k] = n.z;
        p.offset[k] = offset;
        if (!(offset - dot(n, q[k]) > p.margin_scale * longest2)) p.solid = 0u;
    }
    return p;
}

/// @brief What the four face planes of p show about the four vertices w, with a margin: whether all
/// of w lies beyond one face plane (`separated`), and whether some vertex lies inside all four
/// (`inside`). The four faces are evaluated side by side (vector instructions on the CPU).
struct PlaneSides {
    bool separated;
    bool inside;
};

KDET_HD inline PlaneSides plane_sides(const TetPlanes& p, const vec3 w[4], float margin) {
    float nearest[4] = {3.4e38f, 3.4e38f, 3.4e38f, 3.4e38f};
    int inside = 0;
    for (int j = 0; j < 4; ++j) {
        const vec3 r = w[j] - p.origin;
        float distance[4];
        for (int k = 0; k < 4; ++k) distance[k] = p.nx[k] * r.x + p.ny[k] * r.y + p.nz[k] * r.z - p.offset[k];
        for (int k = 0; k < 4; ++k) nearest[k] = min_f(nearest[k], distance[k]);
        const float farthest = max_f(max_f(distance[0], distance[1]), max_f(distance[2], distance[3]));
        inside |= farthest < -margin ? 1 : 0;
    }
    int separated = 0;
    for (int k = 0; k < 4; ++k) separated |= nearest[k] > margin ? 1 : 0;
    return PlaneSides{separated != 0, inside != 0 && p.solid != 0};
}

/// @brief What the face planes prove about two tets whose boxes overlap.
enum class PlaneVerdict { unsure, separated, intersecting };

/// @brief The face-plane pre-test of tets a and b (with their planes pa and pb). With
/// `separation_only`, an intersection is not looked for (the caller only rejects).
KDET_HD inline PlaneVerdict face_plane_pretest(const TetPlanes& pa, const vec3 a[4], const TetPlanes& pb,
                                               const vec3 b[4], bool separation_only) {
    const float longest = max_f(pa.longest, pb.longest);
    const PlaneSides b_by_a = plane_sides(pa, b, pa.margin_scale * longest * longest);
    if (b_by_a.separated) return PlaneVerdict::separated;
    const PlaneSides a_by_b = plane_sides(pb, a, pb.margin_scale * longest * longest);
    if (a_by_b.separated) return PlaneVerdict::separated;
    if (!separation_only && (b_by_a.inside || a_by_b.inside)) return PlaneVerdict::intersecting;
    return PlaneVerdict::unsure;
}

} // namespace kdet
