#pragma once
/// @file face_planes.hpp
/// @brief A pre-test for tet pairs from each tet's four face planes, computed once per tet and frame.
/// It proves a pair separated (one tet lies beyond a face plane of the other) or intersecting (a vertex
/// or an edge point of one tet lies inside the other), each only by a margin far above every rounding
/// involved, and leaves all other pairs to the narrow-phase test. So it never changes what a test reports.
///
/// Bounds, with u = 2^-24, L the pair's longest edge, l_P the plane owner's longest and l its shortest
/// edge, and for face k l_k the shorter and s_k the sine of the angle of the two edges its normal is
/// built from (s_k >= 1/64 for a used face, and l <= l_k <= l_P <= L), and pairs whose boxes overlap
/// (the pipeline runs the pre-test on no other), so every vertex lies within 2 sqrt(3) L of the
/// owner's vertex 0, the origin of its planes:
/// - Rounding of the pre-test. A signed distance dot(n, w - origin) - offset, with |n| = 1 within 2u,
///   is off by at most 4u |w - origin| + 4u L + u |d| < 23u L (1.4e-6 L) from the exact distance to
///   the stored plane (n, offset), and the stored offset is the owner's highest projection within 4u L.
/// - Its normals against the true face normals. An owner edge is one rounded difference of two of its
///   vertices taken from its vertex 0 (error below 3u l_P), so normal k is within (6u l_P / l_k + 3u) /
///   s_k of the face's (below 2.3e-5 l_P / l + 1.2e-5 at worst). Over the 4.5 L that the projections
///   of the pair span, that moves a distance by (27u l_P L / l_k + 14u L) / s_k at most (1.1e-4 l_P L / l
///   + 0.6e-4 L at worst).
/// - The float tests' own face axes. They build the same normal from the same two edges in the pair's
///   frame (origin at the first tet's vertex 0, unit longest edge), where an edge of the other tet
///   carries up to 14u L of rounding; their normal is within (34u L / l_k + 8u) / s_k of the pre-test's,
///   which moves a gap by (153u L^2 / l_k + 36u L) / s_k at most (5.8e-4 L^2 / l + 1.4e-4 L at worst).
/// - The float tests' tolerance: a separation needs a gap above 32 eps L (64u L, 3.8e-6 L).
/// Face k's separation margin is (2^-15 / s_k + 2^-16) L^2 / l_k (`TetPlanes::separation_scale`), more
/// than 2.7 times what the first, third and fourth add up to ((189u / s_k + 87u) L^2 / l_k at most, as
/// s_k <= 1 and l_k <= L), so a pair the pre-test separates shows a gap above (1.9e-5 / s_k + 1.0e-5)
/// L^2 / l_k (at least 2.9e-5 L) along a face axis that sat, sat_no_edges and sat_mtv compute and
/// report as separating, and with the first two bounds a true gap above 4e-5 L. Taken face by face,
/// the margin is below 2^-12 L^2 / l_k for a face whose angle has a sine above 1/4, an eighth of what
/// the smallest sine allowed (1/64) needs, so that most pairs a face axis separates are decided here.
/// An intersection needs no agreement with the float tests' axes, only a point truly inside the owner.
/// Its error comes from the first two bounds alone, and the second shrinks with the owner: a point of
/// the other tet found inside plane k of a `solid` tet by face k's inside margin, (2^-14 / s_k +
/// 2^-15) l_P L / l_k (twice the separation margin with l_P L for L^2), lies behind the true face by
/// more than (5.8e-5 / s_k + 2.6e-5) l_P L / l_k (at least 8.4e-5 L): the first two bounds add up to
/// (41u / s_k + 23u) l_P L / l_k at most, and the point is a vertex, or a point of an edge whose
/// distances are interpolated from those of its ends (under 40u L more rounding). A tet is solid when
/// its four faces are used and each lies above its opposite vertex by more than the face's separation
/// margin for the owner alone, (2^-15 / s_k + 2^-16) l_P^2 / l_k: that height is computed within
/// (18u / s_k + 5u) l_P^2 / l_k (the second bound over the owner's own span of 2 l_P, and the rounding),
/// a 28th of it, so every stored normal faces away from its opposite vertex as the true one does, and a
/// point behind all four true faces lies inside the tet. So the tets overlap by that much along every
/// axis. Both
/// decisions are therefore true for the exact float input (the `exact` test agrees) and lie far
/// inside the clear band (beyond 1e-5 L) where gjk and fast agree with CGAL
/// (tests/cgal/test_narrow_phase_cgal.cpp), and no test misses an intersecting pair.
///
/// The bounds need every intermediate value normal: a tet is used only when its coordinates relative
/// to its vertex 0 lie within [2^-60, 2^60] in magnitude and its shortest edge is at least 2^-20 of
/// its longest (a thinner tet's margin exceeds what any pair could show anyway), and a pair is decided
/// only when both tets' longest edges are at most 2^100 (a tet whose edges overflow float has none). Its normals are built
/// from the edges scaled by a power of two (exact), so no square underflows or overflows. Every face of
/// an unused tet, and every face too thin to give a normal, gets an infinite separation scale: every
/// margin involving it is infinite or NaN, and decides nothing.

#include "geometry/tet_pair.hpp"
#include "geometry/vec3.hpp"

#include <cstdint>

namespace kdet {

/// @brief Face k's separation margin is (k_plane_sine_margin / s_k + k_plane_edge_margin) L^2 / l_k
/// (see the file comment).
constexpr float k_plane_sine_margin = 0x1p-15f;
constexpr float k_plane_edge_margin = 0x1p-16f;

/// @brief How far inside plane k of the other tet a point must lie to prove an intersection, in units
/// of face k's separation margin taken with l_P L for L^2 (file comment).
constexpr float k_plane_inside_share = 2.0f;

/// @brief Faces whose two normal-building edges meet at an angle with a smaller sine are not used.
constexpr float k_plane_min_sine = 1.0f / 64.0f;

/// @brief A tet is used when its largest coordinate relative to its vertex 0 lies within
/// [2^-k_plane_exponent_range, 2^k_plane_exponent_range] ...
constexpr int k_plane_exponent_range = 60;

/// @brief ... and its shortest edge is at least this fraction of its longest.
constexpr float k_plane_min_edge_ratio = 0x1p-20f;

/// @brief A pair decides something only when both tets' longest edges are at most this.
constexpr float k_plane_longest_limit = 0x1p100f;

/// @brief The four face planes of one tet, relative to its vertex 0, coordinate by coordinate so that
/// the four faces are evaluated together (vector instructions on the CPU).
struct TetPlanes {
    float nx[4], ny[4], nz[4]; ///< unit normal of face k (opposite vertex k), pointing away from vertex k; 0 if unused
    float offset[4];           ///< the tet's highest projection onto normal k, relative to vertex 0
    /// The tet's vertices, beside its planes: the pre-test reads the other tet's from here, where
    /// loading them through its indices took two dependent cache misses.
    vec3 vertex[4];
    float longest;             ///< longest edge
    float separation_scale[4]; ///< face k's separation margin is separation_scale[k] * L^2; infinite for an
                               ///< unused face
    std::uint32_t solid;       ///< 1 when all four faces are used and each opposite vertex lies below its face
                               ///< by more than the face's separation margin for the tet alone: only then can
                               ///< the pre-test prove a point inside
};

/// @brief The face planes of tet v.
KDET_HD inline TetPlanes tet_planes(const vec3 v[4]) {
    TetPlanes p;
    for (int k = 0; k < 4; ++k) p.vertex[k] = v[k];
    const vec3 q[4] = {make_vec3(0.0f, 0.0f, 0.0f), v[1] - v[0], v[2] - v[0], v[3] - v[0]};
    float largest = 0.0f;
    for (int i = 1; i < 4; ++i) largest = max_f(largest, max_f(fabsf(q[i].x), max_f(fabsf(q[i].y), fabsf(q[i].z))));
    const int exponent = frexp_exponent(largest);
    // Scaled by a power of two, edges keep their exact directions and ratios, and their squares stay normal.
    const float scale = times_power_of_two(1.0f, -exponent);
    // Corner k relative to vertex 0 as rows, one lane a corner (q, and e scaled), from which the faces'
    // corners below are lane rotations: built from the tet's vec3s, they went through the stack.
    float qx[4], qy[4], qz[4], ex[4], ey[4], ez[4];
    KDET_VECTOR_LOOP
    for (int k = 0; k < 4; ++k) {
        qx[k] = q[k].x, qy[k] = q[k].y, qz[k] = q[k].z;
        ex[k] = q[k].x * scale, ey[k] = q[k].y * scale, ez[k] = q[k].z * scale;
    }
    float longest2 = 0.0f, shortest2 = 3.4e38f;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
            const float l2 = length_squared(make_vec3(ex[j] - ex[i], ey[j] - ey[i], ez[j] - ez[i]));
            longest2 = max_f(longest2, l2);
            shortest2 = min_f(shortest2, l2);
        }
    p.longest = times_power_of_two(sqrtf(longest2), exponent);
    const bool used = largest >= 0x1p-60f && largest <= 0x1p60f &&
                      shortest2 >= k_plane_min_edge_ratio * k_plane_min_edge_ratio * longest2;
    // Undoes the scaling exactly for the lengths of a used tet (its exponent and lengths keep every
    // product normal).
    const float unscale = times_power_of_two(1.0f, exponent);
    // Face k (opposite vertex k) has the corners a, b, c = e[k+1], e[k+2], e[k+3] (mod 4); as rows, so
    // that the four faces are computed side by side, each lane without a branch.
    const float ax[4] = {ex[1], ex[2], ex[3], ex[0]}, ay[4] = {ey[1], ey[2], ey[3], ey[0]}, az[4] = {ez[1], ez[2], ez[3], ez[0]};
    const float bx[4] = {ex[2], ex[3], ex[0], ex[1]}, by[4] = {ey[2], ey[3], ey[0], ey[1]}, bz[4] = {ez[2], ez[3], ez[0], ez[1]};
    const float cx[4] = {ex[3], ex[0], ex[1], ex[2]}, cy[4] = {ey[3], ey[0], ey[1], ey[2]}, cz[4] = {ez[3], ez[0], ez[1], ez[2]};
    std::uint32_t solid_faces[4];
    KDET_VECTOR_LOOP
    for (int k = 0; k < 4; ++k) {
        const vec3 a{ax[k], ay[k], az[k]}, b{bx[k], by[k], bz[k]}, c{cx[k], cy[k], cz[k]};
        // The normal comes from the two edges at the face's largest angle (opposite its longest edge).
        const vec3 ab = b - a, ac = c - a, bc = c - b;
        const float lab = length_squared(ab), lac = length_squared(ac), lbc = length_squared(bc);
        const bool ab_longest = (lab >= lbc) & (lab >= lac);
        const bool g_is_bc = ab_longest | (lac >= lbc);
        const vec3 f{ab_longest ? ac.x : ab.x, ab_longest ? ac.y : ab.y, ab_longest ? ac.z : ab.z};
        const vec3 g{g_is_bc ? bc.x : ac.x, g_is_bc ? bc.y : ac.y, g_is_bc ? bc.z : ac.z};
        const float lf = ab_longest ? lac : lab, lg = g_is_bc ? lbc : lac;
        vec3 n = cross(f, g);
        const float n2 = length_squared(n);
        const bool face_used = used & (n2 > k_plane_min_sine * k_plane_min_sine * lf * lg);
        // The sine from the rounded cross product is within 2e-5 of the edges' (relative: the product
        // cancels to no less than 1/64 of |f| |g|); taken a thousandth smaller, it cannot shrink the
        // margin. An unused face's values (maybe infinite or NaN) are replaced below.
        const float sine = sqrtf(n2 / (lf * lg)) * (1.0f - 0x1p-10f);
        const float separation_scale = (k_plane_sine_margin / sine + k_plane_edge_margin) / (sqrtf(min_f(lf, lg)) * unscale);
        n = n * (1.0f / sqrtf(n2));
        const vec3 d{ex[k], ey[k], ez[k]};
        const bool flip = dot(n, d - a) > 0.0f;
        n = vec3{flip ? -n.x : n.x, flip ? -n.y : n.y, flip ? -n.z : n.z};
        // q[0] projects to 0.
        const float offset = max_f(max_f(max_f(0.0f, dot(n, vec3{qx[1], qy[1], qz[1]})), dot(n, vec3{qx[2], qy[2], qz[2]})),
                                   dot(n, vec3{qx[3], qy[3], qz[3]}));
        p.nx[k] = face_used ? n.x : 0.0f;
        p.ny[k] = face_used ? n.y : 0.0f;
        p.nz[k] = face_used ? n.z : 0.0f;
        p.offset[k] = face_used ? offset : 0.0f;
        p.separation_scale[k] = face_used ? separation_scale : INFINITY;
        // The face's separation margin for the tet alone bounds the error of this height many times over
        // (file comment), so the normal's side is certain.
        const float owner_margin = separation_scale * p.longest * p.longest;
        solid_faces[k] = face_used & (offset - dot(n, vec3{qx[k], qy[k], qz[k]}) > owner_margin) ? 1u : 0u;
    }
    p.solid = solid_faces[0] & solid_faces[1] & solid_faces[2] & solid_faces[3];
    return p;
}

/// @brief Signed distance of point w beyond each face plane k of p.
KDET_HD inline void plane_distances(const TetPlanes& p, vec3 w, float distance[4]) {
    const vec3 r = w - p.vertex[0];
    KDET_VECTOR_LOOP
    for (int k = 0; k < 4; ++k) distance[k] = p.nx[k] * r.x + p.ny[k] * r.y + p.nz[k] * r.z - p.offset[k];
}

/// @brief What the four face planes of p show about the four vertices w of a tet paired with p's:
/// whether all of w lies beyond one face plane by more than its separation margin plus `reach`, for a
/// pair whose longest edge is `longest` (`separated`), and whether some vertex lies inside each of the four by
/// more than its inside margin (`inside`). The four faces are evaluated side by side (vector
/// instructions on the CPU).
struct PlaneSides {
    bool separated;
    bool inside;
};

/// @brief Face k's inside margin for a pair whose longest edge is `longest`, in `margin[k]`: it grows with
/// p's own longest edge times the pair's, not with the pair's squared (file comment).
KDET_HD inline void inside_margins(const TetPlanes& p, float longest, float margin[4]) {
    const float scale = p.longest * longest;
    KDET_VECTOR_LOOP
    for (int k = 0; k < 4; ++k) margin[k] = k_plane_inside_share * p.separation_scale[k] * scale;
}

KDET_HD inline PlaneSides plane_sides(const TetPlanes& p, const vec3 w[4], float longest, float reach) {
    const float longest2 = longest * longest;
    float nearest[4] = {3.4e38f, 3.4e38f, 3.4e38f, 3.4e38f};
    float inside_margin[4];
    inside_margins(p, longest, inside_margin);
    bool inside = false;
    for (int j = 0; j < 4; ++j) {
        float distance[4];
        plane_distances(p, w[j], distance);
        std::uint32_t behind[4];
        KDET_VECTOR_LOOP
        for (int k = 0; k < 4; ++k) {
            nearest[k] = min_f(nearest[k], distance[k]);
            behind[k] = distance[k] + inside_margin[k] < 0.0f ? ~0u : 0u;
        }
        inside |= lane_bits(behind) == 15u;
    }
    std::uint32_t beyond[4];
    KDET_VECTOR_LOOP
    for (int k = 0; k < 4; ++k) beyond[k] = nearest[k] > p.separation_scale[k] * longest2 + reach ? ~0u : 0u;
    return PlaneSides{lane_bits(beyond) != 0, inside && p.solid != 0};
}

/// @brief A distance beyond any that a used tet's planes give along the other tet's edges.
constexpr float k_plane_far = 3.0e38f;

/// @brief Whether a point of some edge of tet w lies inside each of the four face planes of a solid tet
/// p by more than its inside margin (for a pair whose longest edge is `longest`): where no
/// vertex lies inside the other tet, two intersecting tets still have an
/// edge of one passing through the other. The distances vary linearly along an edge, so the part of
/// it inside every plane is clipped from those at its ends (each face keeps the parameters between
/// where its distance reaches minus its margin and where it would reach -k_plane_far, with min and max
/// only: a branch per edge and face would be a coin flip). The middle of that part, clamped onto
/// the edge whatever the rounding, is then checked as a vertex is, from the interpolated distances.
KDET_HD inline bool edges_pass_inside(const TetPlanes& p, const vec3 w[4], float longest) {
    if (!p.solid) return false;
    float margin[4];
    inside_margins(p, longest, margin);
    // plane_sides computed these distances too; they are computed again so that plane_sides, which
    // every candidate runs, keeps nothing for the few pairs that get this far.
    float distance[4][4];
    for (int j = 0; j < 4; ++j) plane_distances(p, w[j], distance[j]);
    // Edge e and face k at [4 e + k], in flat arrays so that each step runs on all 24 at once (vector
    // instructions on the CPU; rolled loops on the GPU, where 24 of each would be live in registers).
    float from[24], slope[24], enter[24], leave[24], at_s[24], s[6];
    KDET_NO_UNROLL
    for (int e = 0; e < 6; ++e)
        for (int k = 0; k < 4; ++k) {
            from[4 * e + k] = distance[narrow::edge_first(e)][k];
            slope[4 * e + k] = distance[narrow::edge_second(e)][k] - distance[narrow::edge_first(e)][k];
        }
    KDET_NO_UNROLL
    for (int i = 0; i < 24; ++i) {
        const float inverse_slope = 1.0f / slope[i];
        const float at_margin = -(from[i] + margin[i & 3]) * inverse_slope;
        const float at_far = -(from[i] + k_plane_far) * inverse_slope;
        enter[i] = min_f(at_margin, at_far);
        leave[i] = max_f(at_margin, at_far);
    }
    KDET_NO_UNROLL
    for (int e = 0; e < 6; ++e) {
        const float* en = enter + 4 * e;
        const float* le = leave + 4 * e;
        const float first = max_f(max_f(max_f(en[0], en[1]), max_f(en[2], en[3])), 0.0f);
        const float last = min_f(min_f(min_f(le[0], le[1]), min_f(le[2], le[3])), 1.0f);
        s[e] = min_f(max_f(0.5f * (first + last), 0.0f), 1.0f);
    }
    KDET_NO_UNROLL
    for (int i = 0; i < 24; ++i) at_s[i] = from[i] + s[i / 4] * slope[i] + margin[i & 3];
    int found = 0;
    KDET_NO_UNROLL
    for (int e = 0; e < 6; ++e) {
        const float* d = at_s + 4 * e;
        found |= max_f(max_f(d[0], d[1]), max_f(d[2], d[3])) < 0.0f ? 1 : 0;
    }
    return found != 0;
}

/// @brief What a separation must add to a face's separation margin to prove two tets more than
/// `margin` apart: the margin and 2^-20 of it. The distance to a plane bounds the distance between the
/// tets from below along its (unit within 2u) normal, and with a margin the pair's boxes overlap only
/// once grown by it, so the other tet's vertices lie up to sqrt(3) margin farther from the plane's
/// origin than the file comment allows: the rounding of a distance grows by under 8u margin and that of
/// the threshold's sum by u of it, both below the 16u margin added; the separation margin still covers
/// the rest, as without a margin. 0 for no margin, which leaves every threshold as it was.
KDET_HD inline float face_plane_reach(float margin) { return margin + margin * 0x1p-20f; }

/// @brief What the face planes prove about two tets whose boxes overlap.
enum class PlaneVerdict { unsure, separated, intersecting };

/// @brief The face-plane pre-test of tets a and b (with their planes pa and pb): b's planes go first,
/// and b's vertices are read only when they do not separate the pair (the grid's pairs read them from
/// beside b's planes, TetPlanes::vertex). In the candidate search's pairs b is the larger tet, whose
/// faces separate more pairs than a's, and the smaller a's edges are the likelier to pass through it,
/// so they are tried first (the narrow phase, where the GPU runs the pre-test, takes a pair's tets in
/// id order). With `separation_only`, an intersection is not looked for (the caller only rejects).
/// With a `margin` (DetectorOptions::margin), `separated` proves the tets more than the margin apart
/// (face_plane_reach); at 0 the verdicts are those without one, bit for bit.
KDET_HD inline PlaneVerdict face_plane_pretest(const TetPlanes& pa, const vec3 a[4], const TetPlanes& pb,
                                               const vec3 b[4], bool separation_only, float margin) {
    // The margins bound the rounding only while the pair's longest edge, and so every distance, is a
    // normal float far from overflow; a tet whose edges overflow has a NaN longest edge, which max_f
    // could drop in favour of the other tet's.
    if (!(pa.longest <= k_plane_longest_limit && pb.longest <= k_plane_longest_limit)) return PlaneVerdict::unsure;
    const float longest = max_f(pa.longest, pb.longest);
    const float reach = face_plane_reach(margin);
    const PlaneSides a_by_b = plane_sides(pb, a, longest, reach);
    if (a_by_b.separated) return PlaneVerdict::separated;
    const PlaneSides b_by_a = plane_sides(pa, b, longest, reach);
    if (b_by_a.separated) return PlaneVerdict::separated;
    if (separation_only) return PlaneVerdict::unsure;
    if (b_by_a.inside || a_by_b.inside) return PlaneVerdict::intersecting;
    // The same verdict in either order; a's edges go first (see above).
    if (edges_pass_inside(pb, a, longest) || edges_pass_inside(pa, b, longest))
        return PlaneVerdict::intersecting;
    return PlaneVerdict::unsure;
}

} // namespace kdet
