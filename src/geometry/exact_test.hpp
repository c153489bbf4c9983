#pragma once
/// @file exact_test.hpp
/// @brief The `exact` narrow-phase test: whether two closed tetrahedra given by float points share a
/// point, decided exactly (the answer of CGAL's do_intersect with exact predicates), at about the cost
/// of the float separating-axis test.
///
/// **Why the 44 axes decide it.** For two tets T1, T2 the Minkowski difference D = T1 - T2 is a convex
/// polytope, and the tets meet iff 0 lies in D. When D is 3-dimensional, each facet normal of D is a
/// face normal of T1 or T2 or the cross product of an edge of T1 and an edge of T2, so 0 is outside D
/// iff one of those 44 axes shows a positive gap between the projections. With p, q the two edges that
/// define an axis n = p x q, the gap between vertex x of T2 and vertex y of T1 along n is
/// det(p, q, x - y): each axis is decided by the signs of 3x3 determinants whose rows are differences
/// of input points. An axis whose edges are exactly parallel has n = 0 and never separates.
///
/// **Filtered evaluation** (like Shewchuk's and CGAL's predicates), three levels:
/// 1. float (inline, every pair): the 44 axes in float in a frame translated to a[0], each with a
///    proven bound on the rounding error of its gaps. A gap beyond the bound decides the axis; a pair
///    is decided here when an axis certifies a separation, or when every axis certifies an overlap and
///    a tet certifies a non-zero volume.
/// 2. double (out of line, only the axes level 1 left open): the same gaps in double, with the double
///    bound; a per-vertex-pair bound on the differences picks the few determinants still open.
/// 3. exact (ExactSum): the sign of each open determinant.
/// Tets of zero volume (with --allow-degenerate) are decided in the plane or on the line that holds
/// the pair (decide_exactly). docs/narrow-phase.md has the bounds' derivation and the measurements.

#include "geometry/dvec3.hpp"
#include "geometry/exact_sum.hpp"
#include "geometry/tet_pair.hpp"

namespace kdet::narrow {

// ---- Error bounds. u is the unit roundoff (2^-24 for float, 2^-53 for double); ||.||_1 and
// ||.||_inf are the 1- and max-norms of the computed (rounded) vectors. For rows p, q, x that are each
// one rounded difference of input points, the computed (p x q) . x differs from det(P, Q, X) of the
// exact differences by at most 8u(1 + 11u) ||p||_1 ||q||_1 ||x||_inf (6 terms, each through 3 roundings
// of its inputs and at most 5 of the arithmetic: gamma_8 / (1 - u)^3), plus, in float only,
// eta (2.001 ||x||_1 + 3.001) for products that underflow (eta = 2^-150). A gap (difference of two
// projections, rounded once) therefore has the exact gap's sign beyond 2(1 + u) times that; the
// constants below also cover the roundings of computing the bound itself, (1 - u)^7, with room to
// spare.

/// @brief Gap bound factor in float: 16u(1 + 64u), u = 2^-24; times ||p||_1 ||q||_1 max|x|.
constexpr float k_float_gap_bound = 0x1p-20f * (1.0f + 0x1p-18f);
/// @brief Smallest positive float, 2 eta: the underflow term is 2^-149 (8 ||x||_1 + 16).
constexpr float k_float_smallest = 0x1p-149f;
/// @brief The float level runs only while ||edge||_1^2 max|x| is below this: then no projection
/// can overflow (edges are at most 6 max|x| long, so they stay below 2^35 and projections below 2^101).
constexpr float k_float_range = 0x1p100f;
/// @brief Gap bound factor in double, 16u(1 + 64u) with u = 2^-53. No product of float
/// differences can underflow or overflow in double (all lie between 2^-551 and 2^391).
constexpr double k_double_gap_bound = 0x1p-49 * (1.0 + 0x1p-47);
/// @brief Bound factor for a single determinant in double (no gap): 8u(1 + 64u). Also the gap bound
/// of the 2-D projections e_i x_j - e_j x_i (4 roundings each, 4u(1 + 10u) ||e||_1 ||x||_inf per
/// projection).
constexpr double k_double_det_bound = 0x1p-50 * (1.0 + 0x1p-47);

/// @brief Edge indices (LocalPair order) of the two edges at one vertex of face k, the face opposite
/// vertex k: (1,2) (1,3) for face 0, then (0,2) (0,3), (0,1) (0,3), (0,1) (0,2).
KDET_HD inline int face_edge(int k, int which) {
    switch (k) {
    case 0: return which ? 4 : 3;
    case 1: return which ? 2 : 1;
    case 2: return which ? 2 : 0;
    default: return which ? 1 : 0;
    }
}

// ---- Level 1: float.

/// @brief The pair for the float level: vertices translated to a[0] and edges taken from the inputs,
/// each one rounded difference, so the bound above applies to every projection.
struct FilterPair {
    vec3 a[4], b[4];
    vec3 edge_a[6];
    EdgeRows edge_b;
    float norm_a[6], norm_b[EdgeRows::padded]; ///< ||edge||_1 (norm_b: 0 for the zero edges)
    float relative;             ///< k_float_gap_bound * max |coordinate of a translated vertex|
    float absolute;             ///< the underflow term
};

KDET_HD inline float norm1(vec3 v) { return fabsf(v.x) + fabsf(v.y) + fabsf(v.z); }
KDET_HD inline vec3 abs_v(vec3 v) { return {fabsf(v.x), fabsf(v.y), fabsf(v.z)}; }

/// @brief Below this largest coordinate of the translated pair, make_filter_pair scales the pair up.
constexpr float k_float_tiny = 0x1p-30f;

/// @brief Fills f; false when the coordinates are too large for the float level (k_float_range).
/// A tiny pair, whose products would underflow and leave every axis to the double level, is scaled
/// up by the power of two that brings its largest translated coordinate into [1/2, 1) first: each
/// row is then still one rounded difference of the input points (times that power, exactly, since
/// scaling up loses no bit), and no determinant changes its sign, so the bounds above hold as they do
/// at ordinary sizes.
KDET_HD inline bool make_filter_pair(const vec3 a[4], const vec3 b[4], FilterPair& f) {
    const vec3 origin = a[0];
    float largest = 0.0f;
    for (int i = 0; i < 4; ++i) {
        f.a[i] = a[i] - origin;
        f.b[i] = b[i] - origin;
        largest = max_f(largest, max_f(max_abs(f.a[i]), max_abs(f.b[i])));
    }
    for (int k = 0; k < 6; ++k) {
        f.edge_a[k] = a[edge_second(k)] - a[edge_first(k)];
        f.edge_b.set(k, b[edge_second(k)] - b[edge_first(k)]);
    }
    if (largest < k_float_tiny && largest > 0.0f) {
        const int exponent = frexp_exponent(largest);
        for (int i = 0; i < 4; ++i) {
            f.a[i] = times_power_of_two(f.a[i], -exponent);
            f.b[i] = times_power_of_two(f.b[i], -exponent);
        }
        for (int k = 0; k < 6; ++k) {
            f.edge_a[k] = times_power_of_two(f.edge_a[k], -exponent);
            f.edge_b.set(k, times_power_of_two(f.edge_b[k], -exponent));
        }
    }
    vec3 extent{0.0f, 0.0f, 0.0f};
    for (int i = 0; i < 4; ++i) extent = max_v(extent, max_v(abs_v(f.a[i]), abs_v(f.b[i])));
    float longest = 0.0f;
    for (int k = 0; k < 6; ++k) {
        f.norm_a[k] = norm1(f.edge_a[k]);
        f.norm_b[k] = norm1(f.edge_b[k]);
        longest = max_f(longest, max_f(f.norm_a[k], f.norm_b[k]));
    }
    f.edge_b.pad(f.norm_b);
    const float span = max_f(extent.x, max_f(extent.y, extent.z));
    f.relative = k_float_gap_bound * span;
    f.absolute = k_float_smallest * (8.0f * (extent.x + extent.y + extent.z) + 16.0f);
    return longest * longest * span < k_float_range; // false for non-finite values too
}

/// @brief What the float level knows about one axis.
enum class AxisVerdict { overlaps, separates, uncertain };

/// @brief Projections of the 8 translated vertices onto n.
struct FilterProjections {
    float a[4], b[4];
};

KDET_HD inline void filter_project(const FilterPair& f, vec3 n, FilterProjections& s) {
    for (int i = 0; i < 4; ++i) {
        s.a[i] = dot(f.a[i], n);
        s.b[i] = dot(f.b[i], n);
    }
}

/// @brief Both gaps (`up`: b above a, `down`: a above b) against the bound: separates when one is
/// certainly positive, overlaps when both are certainly negative.
KDET_HD inline AxisVerdict gaps_verdict(float up, float down, float bound) {
    if (up > bound || down > bound) return AxisVerdict::separates;
    if (up < -bound && down < -bound) return AxisVerdict::overlaps;
    return AxisVerdict::uncertain;
}

KDET_HD inline AxisVerdict filter_verdict(const FilterProjections& s, float bound) {
    const float lo_a = min_f(min_f(s.a[0], s.a[1]), min_f(s.a[2], s.a[3]));
    const float hi_a = max_f(max_f(s.a[0], s.a[1]), max_f(s.a[2], s.a[3]));
    const float lo_b = min_f(min_f(s.b[0], s.b[1]), min_f(s.b[2], s.b[3]));
    const float hi_b = max_f(max_f(s.b[0], s.b[1]), max_f(s.b[2], s.b[3]));
    return gaps_verdict(lo_b - hi_a, lo_a - hi_b, bound);
}

// ---- Levels 2 and 3: double, then exact. Out of line: only pairs with an open axis get here.

/// @brief One of the 12 edges of the pair as its two input points: 0..5 of a, 6..11 of b.
struct Segment {
    vec3 from, to;
};
KDET_HD inline Segment pair_edge(const vec3 a[4], const vec3 b[4], int e) {
    const vec3* t = e < 6 ? a : b;
    const int k = e < 6 ? e : e - 6;
    return Segment{t[edge_first(k)], t[edge_second(k)]};
}
KDET_HD inline bool is_point(Segment s) { return points_coincide(s.from, s.to); }

/// @brief Sign of det(p, q, r) for three differences of float points: the double filter, then exact.
KDET_HD inline int sign_det3(Segment p, Segment q, Segment r) {
    const dvec3 dp = widen(p.to) - widen(p.from), dq = widen(q.to) - widen(q.from), dr = widen(r.to) - widen(r.from);
    const double det = dot(cross(dp, dq), dr);
    const double bound = k_double_det_bound * norm1(dp) * norm1(dq) * norm_inf(dr);
    if (det > bound) return 1;
    if (det < -bound) return -1;
    return exact::sign_det3_exact(p.from, p.to, q.from, q.to, r.from, r.to);
}

/// @brief Exact sign of the 2-D determinant of two differences in the coordinates (u, v).
KDET_HD inline int sign_det2(Segment p, Segment q, int u, int v) {
    return exact::sign_det2_exact(p.from, p.to, q.from, q.to, u, v);
}

/// @brief Whether a + b == c + d exactly for floats: each sum as its double and the exact rounding
/// error of that double (Knuth's TwoSum), a pair that only the same real number gives.
KDET_HD inline bool sums_equal(float a, float b, float c, float d) {
    const double s = double{a} + b, t = double{c} + d;
    const double sb = s - a, tb = t - c;
    return s == t && (a - (s - sb)) + (b - sb) == (c - (t - tb)) + (d - tb);
}

/// @brief Whether two differences of float points are exactly parallel (or zero): equal or opposite
/// differences (a shared edge, an exactly translated copy) by a few exact sums, otherwise all three
/// components of their cross product exactly 0.
KDET_HD inline bool parallel_exactly(Segment p, Segment q) {
    bool equal = true, opposite = true;
    KDET_NO_UNROLL
    for (int k = 0; k < 3; ++k) {
        const float p0 = component(p.from, k), p1 = component(p.to, k), q0 = component(q.from, k), q1 = component(q.to, k);
        equal = equal && sums_equal(p1, q0, q1, p0);    // p1 - p0 == q1 - q0
        opposite = opposite && sums_equal(p1, q1, q0, p0); // p1 - p0 == q0 - q1
    }
    if (equal || opposite) return true;
    KDET_NO_UNROLL
    for (int k = 0; k < 3; ++k)
        if (sign_det2(p, q, (k + 1) % 3, (k + 2) % 3) != 0) return false;
    return true;
}

/// @brief Projections of an axis in double, with the bound on the error of a difference between a
/// projection of a and one of b.
struct ExactProjections {
    double a[4], b[4];
    double bound;
};

/// @brief Whether the axis separates the tets, exactly. `exact_sign(i, j)` is the exact sign of
/// projection(b[j]) - projection(a[i]). Differences beyond the bound are certain; the others are
/// evaluated exactly, and only until the side is decided.
template <class ExactSign>
KDET_HD inline bool separates_exactly(const ExactProjections& s, const ExactSign& exact_sign) {
    KDET_NO_UNROLL
    for (int side = 0; side < 2; ++side) { // side 0: b above a; side 1: a above b
        bool separates = true;
        KDET_NO_UNROLL
        for (int i = 0; i < 4 && separates; ++i)
            KDET_NO_UNROLL
            for (int j = 0; j < 4 && separates; ++j) {
                const double gap = side == 0 ? s.b[j] - s.a[i] : s.a[i] - s.b[j];
                if (gap > s.bound) continue;
                separates = gap >= -s.bound && (side == 0 ? exact_sign(i, j) : -exact_sign(i, j)) > 0;
            }
        if (separates) return true;
    }
    return false;
}

/// @brief exact_sign for a 3-D axis p x q: det(p, q, b[j] - a[i]).
struct AxisDet3 {
    Segment p, q;
    const vec3* a;
    const vec3* b;
    KDET_HD int operator()(int i, int j) const {
        return exact::sign_det3_exact(p.from, p.to, q.from, q.to, a[i], b[j]);
    }
};

/// @brief exact_sign for a 2-D axis perpendicular to e in the coordinates (u, v).
struct AxisDet2 {
    Segment e;
    const vec3* a;
    const vec3* b;
    int u, v;
    KDET_HD int operator()(int i, int j) const { return exact::sign_det2_exact(e.from, e.to, a[i], b[j], u, v); }
};

/// @brief The largest coordinate of the pair translated to a[0], in double.
KDET_HD inline double translated_extent(const vec3 a[4], const vec3 b[4]) {
    const dvec3 origin = widen(a[0]);
    double extent = 0.0;
    KDET_NO_UNROLL
    for (int i = 0; i < 4; ++i) extent = max_d(extent, max_d(norm_inf(widen(a[i]) - origin), norm_inf(widen(b[i]) - origin)));
    return extent;
}

/// @brief Axis 0..43 (0-3 faces of a, 4-7 faces of b, 8 + 6i + j edge i of a x edge j of b), exactly.
KDET_HD inline bool axis_separates_exactly(const vec3 a[4], const vec3 b[4], int axis, double extent) {
    Segment p, q;
    if (axis < 8) {
        const int k = axis & 3, offset = axis < 4 ? 0 : 6;
        p = pair_edge(a, b, offset + face_edge(k, 0));
        q = pair_edge(a, b, offset + face_edge(k, 1));
    } else {
        p = pair_edge(a, b, (axis - 8) / 6);
        q = pair_edge(a, b, 6 + (axis - 8) % 6);
    }
    const dvec3 dp = widen(p.to) - widen(p.from), dq = widen(q.to) - widen(q.from);
    const dvec3 n = cross(dp, dq), origin = widen(a[0]);
    // Edges that are exactly parallel (translated copies, a shared edge) give an axis that never
    // separates. Three exact 2x2 determinants prove it, where the gaps would need two 3x3 ones.
    if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0 && parallel_exactly(p, q)) return false;
    ExactProjections s;
    KDET_NO_UNROLL
    for (int i = 0; i < 4; ++i) {
        s.a[i] = dot(widen(a[i]) - origin, n);
        s.b[i] = dot(widen(b[i]) - origin, n);
    }
    s.bound = k_double_gap_bound * norm1(dp) * norm1(dq) * extent;
    return separates_exactly(s, AxisDet3{p, q, a, b});
}

/// @brief All 8 points lie in one plane, parallel to the coordinate `dropped`: the 2-D separating axis
/// test in the other two coordinates (a bijection of the plane), over the perpendiculars of the 12 edges.
KDET_HD inline bool coplanar_tets_intersect(const vec3 a[4], const vec3 b[4], int dropped, double extent) {
    const int u = dropped == 0 ? 1 : 0, v = dropped == 2 ? 1 : 2;
    const dvec3 origin = widen(a[0]);
    KDET_NO_UNROLL
    for (int e = 0; e < 12; ++e) {
        const Segment edge = pair_edge(a, b, e);
        if (is_point(edge)) continue; // a zero axis never separates
        const dvec3 d = widen(edge.to) - widen(edge.from);
        const double du = component(d, u), dv = component(d, v);
        ExactProjections s;
        KDET_NO_UNROLL
        for (int i = 0; i < 4; ++i) {
            const dvec3 x = widen(a[i]) - origin, y = widen(b[i]) - origin;
            s.a[i] = du * component(x, v) - dv * component(x, u);
            s.b[i] = du * component(y, v) - dv * component(y, u);
        }
        s.bound = k_double_det_bound * (fabs(du) + fabs(dv)) * extent;
        if (separates_exactly(s, AxisDet2{edge, a, b, u, v})) return false;
    }
    return true;
}

/// @brief All 8 points lie on lines parallel to `direction` (a non-zero edge): they meet iff the lines
/// are one and the intervals along it overlap, compared in a coordinate where the direction changes.
KDET_HD inline bool collinear_tets_intersect(const vec3 a[4], const vec3 b[4], Segment direction) {
    const Segment between{a[0], b[0]};
    KDET_NO_UNROLL
    for (int k = 0; k < 3; ++k)
        if (sign_det2(direction, between, (k + 1) % 3, (k + 2) % 3) != 0) return false;
    const int c = direction.from.x != direction.to.x ? 0 : (direction.from.y != direction.to.y ? 1 : 2);
    float lo_a = component(a[0], c), hi_a = lo_a, lo_b = component(b[0], c), hi_b = lo_b;
    KDET_NO_UNROLL
    for (int i = 1; i < 4; ++i) {
        lo_a = min_f(lo_a, component(a[i], c));
        hi_a = max_f(hi_a, component(a[i], c));
        lo_b = min_f(lo_b, component(b[i], c));
        hi_b = max_f(hi_b, component(b[i], c));
    }
    return lo_a <= hi_b && lo_b <= hi_a;
}

/// @brief Levels 2 and 3 for a pair the float level left open: the `open` axes (bit k: axis k) are
/// decided exactly; if none separates, the pair intersects when the float level certified a tet of
/// non-zero volume (`solid`). Otherwise the rank of the edge directions of both tets decides: 3, the
/// axes were complete; 2, the pair is in parallel planes (apart) or in one plane (2-D test); 1, on
/// parallel lines or one line; 0, two points.
KDET_NOINLINE KDET_HD inline bool decide_exactly(const vec3 a[4], const vec3 b[4], std::uint64_t open, bool solid) {
    const double extent = translated_extent(a, b);
    KDET_NO_UNROLL
    for (int axis = 0; axis < 44; ++axis)
        if (((open >> axis) & 1u) && axis_separates_exactly(a, b, axis, extent)) return false;
    if (solid) return true;

    int first = -1;
    KDET_NO_UNROLL
    for (int e = 0; e < 12 && first < 0; ++e)
        if (!is_point(pair_edge(a, b, e))) first = e;
    if (first < 0) return points_coincide(a[0], b[0]);
    const Segment u = pair_edge(a, b, first);
    int second = -1, dropped = -1;
    KDET_NO_UNROLL
    for (int e = first + 1; e < 12 && second < 0; ++e)
        KDET_NO_UNROLL
        for (int k = 0; k < 3 && second < 0; ++k)
            if (sign_det2(u, pair_edge(a, b, e), (k + 1) % 3, (k + 2) % 3) != 0) {
                second = e;
                dropped = k; // component k of u x v is non-zero
            }
    if (second < 0) return collinear_tets_intersect(a, b, u);
    const Segment v = pair_edge(a, b, second);
    KDET_NO_UNROLL
    for (int e = 0; e < 12; ++e)
        if (sign_det3(u, v, pair_edge(a, b, e)) != 0) return true; // 3-D: the 44 axes were complete
    if (sign_det3(u, v, Segment{a[0], b[0]}) != 0) return false;   // parallel planes
    return coplanar_tets_intersect(a, b, dropped, extent);
}

/// @brief The exact test; `exact_stage` is set when the float level could not decide the pair.
/// `edges_first` runs the float level's 36 edge axes before its 8 face axes (for pairs the face-plane
/// pre-test left undecided, which a face axis seldom separates): a separation ends the test in either
/// order, and otherwise every axis runs, so the answer is the same.
KDET_HD inline bool exact_intersect(const vec3 a[4], const vec3 b[4], bool& exact_stage, bool edges_first = false) {
    FilterPair f;
    std::uint64_t open = 0;
    bool solid = false;
    if (make_filter_pair(a, b, f)) {
        FilterProjections s;
        // Each returns true when one of its axes separates the pair, marking the undecided ones open.
        const auto face_axes_separate = [&]() {
            for (int t = 0; t < 2; ++t)
                for (int k = 0; k < 4; ++k) {
                    const float* norms = t ? f.norm_b : f.norm_a;
                    const int e0 = face_edge(k, 0), e1 = face_edge(k, 1);
                    const vec3 first = t ? f.edge_b[e0] : f.edge_a[e0], second = t ? f.edge_b[e1] : f.edge_a[e1];
                    filter_project(f, cross(first, second), s);
                    const float bound = norms[e0] * norms[e1] * f.relative + f.absolute;
                    const AxisVerdict verdict = filter_verdict(s, bound);
                    if (verdict == AxisVerdict::separates) return true;
                    if (verdict == AxisVerdict::uncertain) open |= std::uint64_t{1} << (4 * t + k);
                    // Face 0 against vertex 0 of its own tet: six times the tet's volume.
                    const float* own = t ? s.b : s.a;
                    if (k == 0 && fabsf(own[0] - own[1]) > bound) solid = true;
                }
            return false;
        };
        const auto edge_axes_separate = [&]() {
            EdgeAxisLanes lanes;
            for (int i = 0; i < 6; ++i)
                for (int first = 0; first < 6; first += k_edge_lanes) {
                    edge_axis_lanes(f, i, first, lanes);
                    for (int j = first; j < 6 && j < first + k_edge_lanes; ++j) {
                        const float bound = f.norm_a[i] * f.norm_b[j] * f.relative + f.absolute;
                        // The gaps are minus what remains of the overlap (negation is exact).
                        const int l = j - first;
                        const AxisVerdict verdict = gaps_verdict(-lanes.over_up[l], -lanes.over_down[l], bound);
                        if (verdict == AxisVerdict::separates) return true;
                        if (verdict == AxisVerdict::uncertain) open |= std::uint64_t{1} << (8 + 6 * i + j);
                    }
                }
            return false;
        };
        if (edges_first ? edge_axes_separate() || face_axes_separate() : face_axes_separate() || edge_axes_separate())
            return false;
        if (open == 0 && solid) return true;
    } else {
        open = (std::uint64_t{1} << 44) - 1;
    }
    exact_stage = true;
    return decide_exactly(a, b, open, solid);
}

} // namespace kdet::narrow
