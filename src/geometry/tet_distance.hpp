#pragma once
/// @file tet_distance.hpp
/// @brief Pairs within a margin (DetectorOptions::margin): whether two disjoint closed tetrahedra lie
/// at most a distance m apart, decided exactly for the float coordinates and the float m, and the
/// distance with a closest point on each tet (approximate, in double) for DetectorOptions::distances.
///
/// **The decision.** The distance of two disjoint convex polytopes is reached by a closest pair of
/// points in the relative interiors of a vertex, edge or face of each, and where both are edges or
/// faces a pair of a lower dimension reaches it as well; so it is the least over vertex-vertex,
/// vertex-edge, vertex-face and edge-edge pairs of the features' distance, each counted only where its
/// closest points lie inside both features (where they do not, a smaller feature pair reaches it).
/// Each such condition is a sign of a polynomial in differences of the input floats:
/// - vertex p, vertex q: |p - q|^2 - m^2 <= 0 (degree 2);
/// - vertex p, edge [a, b] (a != b): (p - a).e >= 0, (b - p).e >= 0 and |(p - a) x e|^2 - m^2 |e|^2 <= 0
///   (degree 4), e = b - a;
/// - vertex p, face (a, b, c) with n = (b - a) x (c - a) != 0: the three signed areas
///   ((v' - v) x (p - v)).n >= 0 (degree 4) and (n.(p - a))^2 - m^2 |n|^2 <= 0 (degree 6);
/// - edges [a, b], [c, d] with n = (b - a) x (d - c) != 0: the lines' closest points inside both,
///   ((c - a) x (d - c)).n, ((b - c) x (d - c)).n, ((c - a) x (b - a)).n, ((b - a) x (d - a)).n >= 0, and
///   ((c - a).n)^2 - m^2 |n|^2 <= 0 (degree 6).
/// Each true condition proves a distance <= m, and the least feature pair satisfies its own, so the
/// disjunction is the answer. Zero-volume tets are covered too: their hull is the union of their faces.
///
/// **Filtered evaluation.** Each sign is first computed in double on differences scaled by a power of
/// two 2^-k that brings the pair's extent (vertices and m, about a[0]) into [1/2, 1), alongside the same
/// polynomial over the absolute values (FilterNumber::magnitude). Every operation rounds once (the
/// differences too), at most a dozen along any path, so the computed value is off by at most
/// gamma_12 magnitude < 2^-48 magnitude (also covering the rounding of the magnitude itself), plus
/// what underflow may add: after scaling every value is below 2^20, so an underflow's 2^-1075 grows to
/// less than 2^-1000 however it propagates. A sign beyond that bound is certain; the rest are
/// evaluated exactly (exact::Number, exact_number.hpp).
///
/// **Shortcuts.** Before the scan, the filter alone tries each tet's face planes (all four vertices of
/// the other tet certainly more than m beyond one proves the pair too far apart), then the pair's
/// closest features found in double (tet_closest.hpp): the direction between their points, certified
/// by the filter over all sixteen vertex pairs, proves a pair farther apart than m, and the feature
/// pair's own conditions above prove it within. Only a proof ends the decision, so the answer does
/// not depend on those double computations; the scan decides what they leave (a distance within
/// rounding of m, shapes where GJK stalls).

#include "geometry/exact_number.hpp"
#include "geometry/tet_closest.hpp"

namespace kdet::narrow {

/// @brief A value computed in double with the same polynomial over absolute values beside it.
struct FilterNumber {
    double value, magnitude;
};
KDET_HD inline FilterNumber operator+(FilterNumber a, FilterNumber b) { return {a.value + b.value, a.magnitude + b.magnitude}; }
KDET_HD inline FilterNumber operator-(FilterNumber a, FilterNumber b) { return {a.value - b.value, a.magnitude + b.magnitude}; }
KDET_HD inline FilterNumber operator*(FilterNumber a, FilterNumber b) { return {a.value * b.value, a.magnitude * b.magnitude}; }

/// @brief The filter's bound on the rounding error: relative to the magnitude, and for underflow.
constexpr double k_margin_relative_bound = 0x1p-48;
constexpr double k_margin_absolute_bound = 0x1p-1000;

/// @brief Differences of input floats and m^2 for the filter, in the pair's scaled frame.
struct FilterMaker {
    double scale, margin;
    KDET_HD FilterNumber diff(float x, float y) const {
        const double v = (static_cast<double>(x) - static_cast<double>(y)) * scale;
        return {v, fabs(v)};
    }
    KDET_HD FilterNumber margin_squared() const { return {margin * margin, margin * margin}; }
};

/// @brief The same, exactly.
struct ExactMaker {
    float margin;
    KDET_HD exact::Number diff(float x, float y) const { return exact::Number::of(x) - exact::Number::of(y); }
    KDET_HD exact::Number margin_squared() const { return exact::Number::of(margin) * exact::Number::of(margin); }
};

template <class N>
struct Vec3N {
    N x, y, z;
};
template <class Maker>
KDET_HD inline auto difference(const Maker& mk, vec3 p, vec3 q) {
    using N = decltype(mk.diff(0.0f, 0.0f));
    return Vec3N<N>{mk.diff(p.x, q.x), mk.diff(p.y, q.y), mk.diff(p.z, q.z)};
}
template <class N>
KDET_HD inline N dot_n(const Vec3N<N>& a, const Vec3N<N>& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class N>
KDET_HD inline Vec3N<N> cross_n(const Vec3N<N>& a, const Vec3N<N>& b) {
    return Vec3N<N>{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// ---- The polynomials, each written once for both makers.

/// |p - q|^2 - m^2.
template <class Maker>
KDET_HD inline auto vertex_vertex_excess(const Maker& mk, vec3 p, vec3 q) {
    const auto d = difference(mk, p, q);
    return dot_n(d, d) - mk.margin_squared();
}
/// (p - a).(b - a): where p projects along [a, b] (swap a and b for the other end).
template <class Maker>
KDET_HD inline auto along_edge(const Maker& mk, vec3 p, vec3 a, vec3 b) {
    return dot_n(difference(mk, p, a), difference(mk, b, a));
}
/// |(p - a) x e|^2 - m^2 |e|^2, e = b - a.
template <class Maker>
KDET_HD inline auto vertex_line_excess(const Maker& mk, vec3 p, vec3 a, vec3 b) {
    const auto e = difference(mk, b, a);
    const auto c = cross_n(difference(mk, p, a), e);
    return dot_n(c, c) - mk.margin_squared() * dot_n(e, e);
}
/// ((b - a) x (c - a)) . ((b - a) x (c - a)).
template <class Maker>
KDET_HD inline auto face_normal_squared(const Maker& mk, vec3 a, vec3 b, vec3 c) {
    const auto n = cross_n(difference(mk, b, a), difference(mk, c, a));
    return dot_n(n, n);
}
/// ((w - v) x (p - v)) . n with n = (b - a) x (c - a): p on the inner side of the face's edge (v, w).
template <class Maker>
KDET_HD inline auto face_side(const Maker& mk, vec3 p, vec3 v, vec3 w, vec3 a, vec3 b, vec3 c) {
    const auto n = cross_n(difference(mk, b, a), difference(mk, c, a));
    return dot_n(cross_n(difference(mk, w, v), difference(mk, p, v)), n);
}
/// (n.(p - a))^2 - m^2 |n|^2 with n = (b - a) x (c - a).
template <class Maker>
KDET_HD inline auto vertex_plane_excess(const Maker& mk, vec3 p, vec3 a, vec3 b, vec3 c) {
    const auto n = cross_n(difference(mk, b, a), difference(mk, c, a));
    const auto h = dot_n(n, difference(mk, p, a));
    return h * h - mk.margin_squared() * dot_n(n, n);
}
/// n . (p - a) with n = (b - a) x (c - a).
template <class Maker>
KDET_HD inline auto plane_side(const Maker& mk, vec3 p, vec3 a, vec3 b, vec3 c) {
    return dot_n(cross_n(difference(mk, b, a), difference(mk, c, a)), difference(mk, p, a));
}
/// ((p - q) x (r - s)) . n with n = (b - a) x (d - c): one of the edge-edge parameters.
template <class Maker>
KDET_HD inline auto edge_parameter(const Maker& mk, vec3 p, vec3 q, vec3 r, vec3 s, vec3 a, vec3 b, vec3 c, vec3 d) {
    const auto n = cross_n(difference(mk, b, a), difference(mk, d, c));
    return dot_n(cross_n(difference(mk, p, q), difference(mk, r, s)), n);
}
/// ((c - a).n)^2 - m^2 |n|^2 with n = (b - a) x (d - c).
template <class Maker>
KDET_HD inline auto edge_edge_excess(const Maker& mk, vec3 a, vec3 b, vec3 c, vec3 d) {
    const auto n = cross_n(difference(mk, b, a), difference(mk, d, c));
    const auto h = dot_n(difference(mk, c, a), n);
    return h * h - mk.margin_squared() * dot_n(n, n);
}

// ---- Signs.

/// @brief The filter's sign of `expr`: -1 or +1 where certain, 0 where it cannot tell.
template <class Expr>
KDET_HD inline int filter_sign(const FilterMaker& f, const Expr& expr) {
    const FilterNumber x = expr(f);
    const double bound = k_margin_relative_bound * x.magnitude + k_margin_absolute_bound;
    return x.value > bound ? 1 : (x.value < -bound ? -1 : 0);
}

template <class Expr>
KDET_NOINLINE KDET_HD int exact_sign(const ExactMaker& e, const Expr& expr) {
    return expr(e).sign();
}

/// @brief The exact sign of `expr`: the filter's, else exact arithmetic's.
template <class Expr>
KDET_HD inline int margin_sign(const FilterMaker& f, const ExactMaker& e, const Expr& expr) {
    const int s = filter_sign(f, expr);
    return s != 0 ? s : exact_sign(e, expr);
}

/// @brief The filter's frame of a pair and margin: 2^-k with the extent about a[0] in [1/2, 1).
KDET_HD inline FilterMaker margin_filter(const vec3 a[4], const vec3 b[4], float margin) {
    double extent = static_cast<double>(margin);
    for (int i = 0; i < 8; ++i) {
        const vec3 p = i < 4 ? a[i] : b[i - 4];
        extent = max_d(extent, norm_inf(widen(p) - widen(a[0])));
    }
    int exponent = 0;
    frexp(extent, &exponent);
    const double scale = ldexp(1.0, -exponent);
    return FilterMaker{scale, static_cast<double>(margin) * scale};
}

/// @brief Whether the filter proves every vertex of `other` more than m beyond a face plane of t.
KDET_HD inline bool face_planes_far(const FilterMaker& f, const vec3 t[4], const vec3 other[4]) {
    for (int face = 0; face < 4; ++face) {
        const vec3 a = t[face_vertex(face, 0)], b = t[face_vertex(face, 1)], c = t[face_vertex(face, 2)];
        // The face's own tet lies on the negative side of an outward normal.
        const int inner = filter_sign(f, [&](const auto& mk) { return plane_side(mk, t[face], a, b, c); });
        if (inner == 0) continue;
        bool far = true;
        for (int i = 0; i < 4 && far; ++i) {
            const vec3 q = other[i];
            far = filter_sign(f, [&](const auto& mk) { return plane_side(mk, q, a, b, c); }) == -inner &&
                  filter_sign(f, [&](const auto& mk) { return vertex_plane_excess(mk, q, a, b, c); }) > 0;
        }
        if (far) return true;
    }
    return false;
}

/// @brief Whether the filter proves every vertex pair (a[i], b[j]) more than m apart along the direction
/// n (any double vector): then the tets are, since a tet projects onto the span of its vertices'
/// projections. The direction's exact double value is what is certified, so where it comes from does not
/// matter (closest points found by rounding computations); a direction that proves nothing is harmless.
KDET_HD inline bool separated_along(const FilterMaker& f, const vec3 a[4], const vec3 b[4], dvec3 n) {
    const double largest = norm_inf(n);
    if (!(largest > 0.0 && largest < INFINITY)) return false;
    n = (1.0 / largest) * n; // 1 <= |n|^2 <= 3: its square root neither underflows nor overflows
    // Above |n|: the sum of squares rounds twice, the root once, this product once more.
    const double length_up = sqrt(dot(n, n)) * (1.0 + 0x1p-40);
    const double reach = f.margin * length_up; // above m |n| in the pair's frame, for the same reason
    const FilterNumber nx{n.x, fabs(n.x)}, ny{n.y, fabs(n.y)}, nz{n.z, fabs(n.z)}, r{reach, reach};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            const auto d = difference(f, b[j], a[i]);
            const FilterNumber h = nx * d.x + ny * d.y + nz * d.z - r;
            if (!(h.value > k_margin_relative_bound * h.magnitude + k_margin_absolute_bound)) return false;
        }
    return true;
}

/// @brief Whether vertex p projects into edge [a, b] (a != b) within m of it.
KDET_HD inline bool vertex_edge_within(const FilterMaker& f, const ExactMaker& e, vec3 p, vec3 a, vec3 b) {
    return margin_sign(f, e, [&](const auto& mk) { return along_edge(mk, p, a, b); }) >= 0 &&
           margin_sign(f, e, [&](const auto& mk) { return along_edge(mk, p, b, a); }) >= 0 &&
           margin_sign(f, e, [&](const auto& mk) { return vertex_line_excess(mk, p, a, b); }) <= 0;
}

/// @brief Whether vertex p projects into face (a, b, c) within m of it; false for a face without area.
KDET_HD inline bool vertex_face_within(const FilterMaker& f, const ExactMaker& e, vec3 p, vec3 a, vec3 b, vec3 c) {
    return margin_sign(f, e, [&](const auto& mk) { return face_normal_squared(mk, a, b, c); }) != 0 &&
           margin_sign(f, e, [&](const auto& mk) { return face_side(mk, p, a, b, a, b, c); }) >= 0 &&
           margin_sign(f, e, [&](const auto& mk) { return face_side(mk, p, b, c, a, b, c); }) >= 0 &&
           margin_sign(f, e, [&](const auto& mk) { return face_side(mk, p, c, a, a, b, c); }) >= 0 &&
           margin_sign(f, e, [&](const auto& mk) { return vertex_plane_excess(mk, p, a, b, c); }) <= 0;
}

/// @brief Whether vertex p lies within m of tet t's edges or faces by the conditions above (its
/// features' interiors; the vertex-vertex pairs are the caller's).
KDET_HD inline bool vertex_within(const FilterMaker& f, const ExactMaker& e, vec3 p, const vec3 t[4]) {
    for (int k = 0; k < 6; ++k) {
        const vec3 a = t[edge_first(k)], b = t[edge_second(k)];
        if (!points_coincide(a, b) && vertex_edge_within(f, e, p, a, b)) return true;
    }
    for (int face = 0; face < 4; ++face)
        if (vertex_face_within(f, e, p, t[face_vertex(face, 0)], t[face_vertex(face, 1)], t[face_vertex(face, 2)]))
            return true;
    return false;
}

/// @brief Whether edges [a, b] and [c, d] have their lines' closest points inside both, within m.
KDET_HD inline bool edges_within(const FilterMaker& f, const ExactMaker& e, vec3 a, vec3 b, vec3 c, vec3 d) {
    const auto param = [&](vec3 p, vec3 q, vec3 r, vec3 s) {
        return margin_sign(f, e, [&](const auto& mk) { return edge_parameter(mk, p, q, r, s, a, b, c, d); }) >= 0;
    };
    // n != 0: |n|^2 = ((b - a) x (d - c)).n, the parameter form with (p, q, r, s) = (b, a, d, c).
    return margin_sign(f, e, [&](const auto& mk) { return edge_parameter(mk, b, a, d, c, a, b, c, d); }) > 0 &&
           param(c, a, d, c) && param(b, c, d, c) && param(c, a, b, a) && param(b, a, d, a) &&
           margin_sign(f, e, [&](const auto& mk) { return edge_edge_excess(mk, a, b, c, d); }) <= 0;
}

/// @brief Distance and closest points of a disjoint pair, in double.
KDET_HD inline double disjoint_tets_distance(const dvec3 a[4], const dvec3 b[4], dvec3& on_a, dvec3& on_b) {
    ClosestFeatures features;
    return sqrt(closest_points_and_features(a, b, on_a, on_b, features));
}

/// @brief Whether vertex p lies within m of edge [a, b] or of one of its ends.
KDET_HD inline bool vertex_segment_within(const FilterMaker& f, const ExactMaker& e, vec3 p, vec3 a, vec3 b) {
    return margin_sign(f, e, [&](const auto& mk) { return vertex_vertex_excess(mk, p, a); }) <= 0 ||
           margin_sign(f, e, [&](const auto& mk) { return vertex_vertex_excess(mk, p, b); }) <= 0 ||
           (!points_coincide(a, b) && vertex_edge_within(f, e, p, a, b));
}

/// @brief Whether the conditions of one feature pair prove the tets within m.
KDET_HD inline bool features_within(const FilterMaker& f, const ExactMaker& e, const vec3 a[4], const vec3 b[4],
                                    ClosestFeatures features) {
    const int i = features.first, j = features.second;
    switch (features.kind) {
    case ClosestFeatures::vertex_face:
        return vertex_face_within(f, e, a[i], b[face_vertex(j, 0)], b[face_vertex(j, 1)], b[face_vertex(j, 2)]);
    case ClosestFeatures::face_vertex:
        return vertex_face_within(f, e, b[j], a[face_vertex(i, 0)], a[face_vertex(i, 1)], a[face_vertex(i, 2)]);
    case ClosestFeatures::vertex_edge:
        return vertex_segment_within(f, e, a[i], b[edge_first(j)], b[edge_second(j)]);
    case ClosestFeatures::edge_vertex:
        return vertex_segment_within(f, e, b[j], a[edge_first(i)], a[edge_second(i)]);
    case ClosestFeatures::edge_edge:
        return edges_within(f, e, a[edge_first(i)], a[edge_second(i)], b[edge_first(j)], b[edge_second(j)]);
    }
    return false;
}

/// @brief Whether two tets that do not intersect lie at most `margin` apart (margin >= 0), exactly.
/// For a pair that intersects the answer is meaningless: the caller's intersection test goes first.
/// The face planes go first unless the caller tried them already (`face_planes_first` false); then the
/// pair's closest features found in double (by GJK, else by trying every feature pair): the direction
/// between their points proves most pairs farther apart, their own conditions most pairs within. The
/// scan of every feature pair decides the rest (distances within rounding of m, degenerate tets).
KDET_NOINLINE KDET_HD inline bool disjoint_tets_within(const vec3 a[4], const vec3 b[4], float margin,
                                                      bool face_planes_first = true) {
    const FilterMaker f = margin_filter(a, b, margin);
    const ExactMaker e{margin};
    if (face_planes_first && (face_planes_far(f, a, b) || face_planes_far(f, b, a))) return false;
    {
        dvec3 da[4], db[4];
        for (int i = 0; i < 4; ++i) {
            da[i] = widen(a[i]);
            db[i] = widen(b[i]);
        }
        dvec3 on_a, on_b;
        ClosestFeatures features;
        closest_points_and_features(da, db, on_a, on_b, features);
        if (separated_along(f, a, b, on_b - on_a)) return false;
        if (features_within(f, e, a, b, features)) return true;
    }
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            if (margin_sign(f, e, [&](const auto& mk) { return vertex_vertex_excess(mk, a[i], b[j]); }) <= 0) return true;
    for (int i = 0; i < 4; ++i)
        if (vertex_within(f, e, a[i], b) || vertex_within(f, e, b[i], a)) return true;
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j)
            if (edges_within(f, e, a[edge_first(i)], a[edge_second(i)], b[edge_first(j)], b[edge_second(j)])) return true;
    return false;
}

// ---- Distances and closest points (approximate).

/// @brief Distance from x to tet t in double: 0 inside (all four faces' orientations agree with the
/// tet's), else the nearest face's. A tet without volume has no inside: every face's orientation
/// of the opposite vertex is 0 there, which would agree with any point's; its faces cover its hull.
/// Flat up to rounding (|6V| at most 2^-48 of its extent cubed, above the double computation's error)
/// counts as without volume: an inside that thin lies within 2^-24 of the extent from its faces.
KDET_HD inline double point_tet_distance(dvec3 x, const dvec3 t[4]) {
    double extent = 0.0;
    for (int k = 1; k < 4; ++k) {
        const dvec3 e = t[k] - t[0];
        extent = fmax(extent, fmax(fabs(e.x), fmax(fabs(e.y), fabs(e.z))));
    }
    const double volume = fabs(dot(cross(t[1] - t[0], t[2] - t[0]), t[3] - t[0]));
    double side[4];
    bool inside = volume > 0x1p-48 * extent * extent * extent;
    for (int face = 0; face < 4; ++face) {
        const dvec3 a = t[face_vertex(face, 0)], b = t[face_vertex(face, 1)], c = t[face_vertex(face, 2)];
        const dvec3 n = cross(b - a, c - a);
        side[face] = dot(n, x - a) * dot(n, t[face] - a);
        inside = inside && side[face] >= 0.0;
    }
    if (inside) return 0.0;
    double best = INFINITY;
    for (int face = 0; face < 4; ++face) {
        const dvec3 a = t[face_vertex(face, 0)], b = t[face_vertex(face, 1)], c = t[face_vertex(face, 2)];
        const double d2 = squared_distance(x, closest_on_triangle(x, a, b, c).point);
        best = d2 < best ? d2 : best;
    }
    return sqrt(best);
}

/// @brief A common point of two intersecting tets, in double: of the vertices and of each edge's
/// crossing of the other tet's face planes (brought onto the face), the one farthest from neither tet
/// (the first on a tie). A candidate's second distance is computed only where its first leaves it a
/// chance, and a candidate on both tets (score 0) ends the search: no later one could replace it.
KDET_HD inline dvec3 common_point(const dvec3 a[4], const dvec3 b[4]) {
    dvec3 best = a[0];
    double best_score = INFINITY;
    // True once the best candidate lies on both tets.
    const auto consider = [&](dvec3 x, const dvec3* first, const dvec3* second) {
        const double d1 = point_tet_distance(x, first);
        if (!(d1 < best_score)) return false;
        const double d2 = point_tet_distance(x, second);
        const double score = d1 > d2 ? d1 : d2;
        if (score < best_score) {
            best_score = score;
            best = x;
        }
        return best_score == 0.0;
    };
    // A vertex lies on its own tet: the other tet's distance decides first.
    for (int i = 0; i < 4; ++i)
        if (consider(a[i], b, a) || consider(b[i], a, b)) return best;
    for (int side = 0; side < 2; ++side) {
        const dvec3* s = side ? b : a;
        const dvec3* t = side ? a : b;
        for (int k = 0; k < 6; ++k) {
            const dvec3 p = s[edge_first(k)], q = s[edge_second(k)];
            for (int face = 0; face < 4; ++face) {
                const dvec3 fa = t[face_vertex(face, 0)], fb = t[face_vertex(face, 1)], fc = t[face_vertex(face, 2)];
                const dvec3 n = cross(fb - fa, fc - fa);
                const double hp = dot(n, p - fa), hq = dot(n, q - fa);
                if (!(hp * hq <= 0.0) || hp == hq) continue;
                const dvec3 x = p + (hp / (hp - hq)) * (q - p);
                if (consider(closest_on_triangle(x, fa, fb, fc).point, s, t)) return best;
            }
        }
    }
    return best;
}

/// @brief DetectorOptions::distances of a reported pair: the distance (0 when `intersecting`) and a
/// closest point on each tet (a common point, twice, when intersecting), rounded to float.
KDET_NOINLINE KDET_HD inline float tets_distance(const vec3 a[4], const vec3 b[4], bool intersecting, vec3& on_a, vec3& on_b) {
    dvec3 da[4], db[4];
    for (int i = 0; i < 4; ++i) {
        da[i] = widen(a[i]);
        db[i] = widen(b[i]);
    }
    dvec3 x, y;
    double distance = 0.0;
    if (intersecting) {
        x = y = common_point(da, db);
    } else {
        distance = disjoint_tets_distance(da, db, x, y);
    }
    on_a = vec3{static_cast<float>(x.x), static_cast<float>(x.y), static_cast<float>(x.z)};
    on_b = vec3{static_cast<float>(y.x), static_cast<float>(y.y), static_cast<float>(y.z)};
    return static_cast<float>(distance);
}

} // namespace kdet::narrow
