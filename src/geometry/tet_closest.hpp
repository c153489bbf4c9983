#pragma once
/// @file tet_closest.hpp
/// @brief The closest points of two disjoint tetrahedra in double, with the feature pair (vertex, edge
/// or face of each) that reaches them: by GJK, fast, and by trying every feature pair, slower but
/// without iterations. Approximate: the margin's exact decision (tet_distance.hpp) certifies what it
/// takes from them, and DetectorOptions::distances reports them.

#include "geometry/closest_points.hpp"
#include "geometry/tet_pair.hpp"

namespace kdet::narrow {

/// @brief Vertex k of face `face` (the face opposite vertex `face`), k = 0..2.
KDET_HD inline int face_vertex(int face, int k) { return k + (k >= face ? 1 : 0); }

/// @brief The edge between vertices u < v (edge_first and edge_second's numbering).
KDET_HD inline int edge_between(int u, int v) { return u == 0 ? v - 1 : u + v; }

/// @brief Which feature pair reaches a disjoint pair's distance as found in double: a vertex of one tet
/// and a face or an edge (its ends included) of the other, or two edges' interiors. `first` indexes a's
/// feature, `second` b's (vertices 0-3, edges 0-5, faces 0-3: the face opposite that vertex).
struct ClosestFeatures {
    enum Kind { vertex_face, face_vertex, vertex_edge, edge_vertex, edge_edge } kind;
    int first, second;
};

/// @brief Squared distance and closest points of a disjoint pair, in double, with the feature pair that
/// reaches it: the least over its vertex-face pairs where the vertex projects into the face, its
/// vertex-edge pairs (which hold the vertex-vertex pairs) and its edge pairs whose lines come closest
/// inside both.
KDET_HD inline double closest_features(const dvec3 a[4], const dvec3 b[4], dvec3& on_a, dvec3& on_b,
                                       ClosestFeatures& features) {
    double best = INFINITY;
    on_a = a[0];
    on_b = b[0];
    features = ClosestFeatures{ClosestFeatures::vertex_edge, 0, 0};
    const auto consider = [&](dvec3 x, dvec3 y, ClosestFeatures::Kind kind, int first, int second) {
        const double d2 = squared_distance(x, y);
        if (d2 < best) {
            best = d2;
            on_a = x;
            on_b = y;
            features = ClosestFeatures{kind, first, second};
        }
    };
    dvec3 edge_a[6], edge_b[6];
    for (int k = 0; k < 6; ++k) {
        edge_a[k] = a[edge_second(k)] - a[edge_first(k)];
        edge_b[k] = b[edge_second(k)] - b[edge_first(k)];
    }
    for (int face = 0; face < 4; ++face) {
        const int i = face_vertex(face, 0), j = face_vertex(face, 1), k = face_vertex(face, 2);
        const dvec3 na = cross(a[j] - a[i], a[k] - a[i]), nb = cross(b[j] - b[i], b[k] - b[i]);
        const double na2 = dot(na, na), nb2 = dot(nb, nb);
        for (int v = 0; v < 4; ++v) {
            dvec3 q;
            if (nb2 > 0.0 && project_into_triangle(a[v], b[i], b[j], b[k], nb, nb2, q))
                consider(a[v], q, ClosestFeatures::vertex_face, v, face);
            if (na2 > 0.0 && project_into_triangle(b[v], a[i], a[j], a[k], na, na2, q))
                consider(q, b[v], ClosestFeatures::face_vertex, face, v);
        }
    }
    for (int v = 0; v < 4; ++v)
        for (int k = 0; k < 6; ++k) {
            consider(a[v], closest_on_segment(a[v], b[edge_first(k)], b[edge_second(k)]), ClosestFeatures::vertex_edge, v, k);
            consider(closest_on_segment(b[v], a[edge_first(k)], a[edge_second(k)]), b[v], ClosestFeatures::edge_vertex, k, v);
        }
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) {
            const dvec3 n = cross(edge_a[i], edge_b[j]);
            const double n2 = dot(n, n);
            if (!(n2 > 0.0)) continue;
            double s, t;
            closest_on_lines(a[edge_first(i)], edge_a[i], b[edge_first(j)], edge_b[j], n, n2, s, t);
            if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0)
                consider(a[edge_first(i)] + s * edge_a[i], b[edge_first(j)] + t * edge_b[j], ClosestFeatures::edge_edge, i, j);
        }
    return best;
}

/// @brief Up to four points of the Minkowski difference A - B, each with the vertices of A and of B that
/// it is the difference of, and the weights of the simplex's point closest to the origin.
struct MinkowskiSimplex {
    dvec3 w[4];
    int from_a[4], from_b[4];
    double weight[4];
    int size;
};

/// @brief Keeps the points of s with a positive weight (the sub-simplex that holds its closest point).
KDET_HD inline void keep_weighted(MinkowskiSimplex& s, const double* weight) {
    int kept = 0;
    for (int k = 0; k < s.size; ++k) {
        if (!(weight[k] > 0.0)) continue;
        s.w[kept] = s.w[k];
        s.from_a[kept] = s.from_a[k];
        s.from_b[kept] = s.from_b[k];
        s.weight[kept] = weight[k];
        ++kept;
    }
    s.size = kept;
}

/// @brief Reduces s to the sub-simplex that holds its point closest to the origin, with its weights;
/// false when the origin lies inside a tetrahedron s (the tets intersect) or no point keeps a weight.
KDET_HD inline bool closest_on_simplex(MinkowskiSimplex& s) {
    const dvec3 origin{0.0, 0.0, 0.0};
    double weight[4] = {1.0, 0.0, 0.0, 0.0};
    if (s.size == 2) {
        const ClosestOnTriangle c = closest_on_edge(origin, s.w[0], s.w[1]);
        weight[0] = c.weight[0];
        weight[1] = c.weight[1];
    } else if (s.size == 3) {
        const ClosestOnTriangle c = closest_on_triangle(origin, s.w[0], s.w[1], s.w[2]);
        for (int k = 0; k < 3; ++k) weight[k] = c.weight[k];
    } else if (s.size == 4) {
        // Outside the tetrahedron its closest point is its boundary's: the nearest face's. Every face is
        // tried, since a side test of a nearly flat simplex (a new point nearly in the old triangle's
        // plane) is rounding noise that could drop the face holding the old closest point.
        double best = INFINITY;
        bool inside = true;
        for (int m = 0; m < 4; ++m) {
            const int i = face_vertex(m, 0), j = face_vertex(m, 1), k = face_vertex(m, 2);
            const dvec3 n = cross(s.w[j] - s.w[i], s.w[k] - s.w[i]);
            inside = inside && dot(origin - s.w[i], n) * dot(s.w[m] - s.w[i], n) > 0.0;
            const ClosestOnTriangle c = closest_on_triangle(origin, s.w[i], s.w[j], s.w[k]);
            const double d2 = dot(c.point, c.point);
            if (d2 < best) {
                best = d2;
                weight[m] = 0.0;
                weight[i] = c.weight[0];
                weight[j] = c.weight[1];
                weight[k] = c.weight[2];
            }
        }
        if (inside) return false;
    }
    keep_weighted(s, weight);
    return s.size > 0;
}

/// @brief GJK's iterations at most: more than two tets' 16 Minkowski points need, reached on rounding.
constexpr int k_closest_gjk_iterations = 32;

/// @brief GJK stops when the next support point lowers |v|^2 by less than this fraction of it.
constexpr double k_closest_gjk_progress = 0x1p-40;

/// @brief The closest points of disjoint tets a and b by GJK, with the final simplex `s` that spans
/// them; false where GJK cannot tell (the tets touch or intersect up to rounding).
KDET_HD inline bool gjk_closest_points(const dvec3 a[4], const dvec3 b[4], dvec3& on_a, dvec3& on_b, MinkowskiSimplex& s) {
    s = MinkowskiSimplex{{a[0] - b[0]}, {0}, {0}, {1.0}, 1};
    dvec3 v = s.w[0];
    double vv = dot(v, v);
    for (int iteration = 0; iteration < k_closest_gjk_iterations; ++iteration) {
        if (!(vv > 0.0)) return false;
        int ia, ib;
        lowest_difference(a, b, v, ia, ib);
        if (vv - dot(v, a[ia] - b[ib]) <= k_closest_gjk_progress * vv) break;
        bool repeated = false;
        for (int k = 0; k < s.size; ++k) repeated = repeated || (s.from_a[k] == ia && s.from_b[k] == ib);
        if (repeated) break;
        s.w[s.size] = a[ia] - b[ib];
        s.from_a[s.size] = ia;
        s.from_b[s.size] = ib;
        ++s.size;
        if (!closest_on_simplex(s)) return false;
        dvec3 next{0.0, 0.0, 0.0};
        for (int k = 0; k < s.size; ++k) next = next + s.weight[k] * s.w[k];
        const double next_vv = dot(next, next);
        if (!(next_vv < vv)) break;
        v = next;
        vv = next_vv;
    }
    on_a = dvec3{0.0, 0.0, 0.0};
    on_b = dvec3{0.0, 0.0, 0.0};
    for (int k = 0; k < s.size; ++k) {
        on_a = on_a + s.weight[k] * a[s.from_a[k]];
        on_b = on_b + s.weight[k] * b[s.from_b[k]];
    }
    return true;
}

/// @brief The feature pair that GJK's final simplex spans: the vertices of each tet among its points
/// name a vertex, an edge or a face; false for none of ClosestFeatures' kinds.
KDET_HD inline bool simplex_features(const MinkowskiSimplex& s, ClosestFeatures& features) {
    int vertices_a = 0, vertices_b = 0, count_a = 0, count_b = 0;
    for (int k = 0; k < s.size; ++k) {
        count_a += (vertices_a >> s.from_a[k] & 1) ? 0 : 1;
        count_b += (vertices_b >> s.from_b[k] & 1) ? 0 : 1;
        vertices_a |= 1 << s.from_a[k];
        vertices_b |= 1 << s.from_b[k];
    }
    // A feature by its vertices: the lowest one, the edge from it to the next, the face without the missing one.
    const auto lowest = [](int set) { return set & 1 ? 0 : (set & 2 ? 1 : (set & 4 ? 2 : 3)); };
    const auto edge = [&](int set) { return edge_between(lowest(set), lowest(set & (set - 1))); };
    const auto face = [&](int set) { return lowest(~set & 15); };
    if (count_a == 1 && count_b == 3) {
        features = ClosestFeatures{ClosestFeatures::vertex_face, lowest(vertices_a), face(vertices_b)};
    } else if (count_a == 3 && count_b == 1) {
        features = ClosestFeatures{ClosestFeatures::face_vertex, face(vertices_a), lowest(vertices_b)};
    } else if (count_a == 1 && count_b <= 2) {
        // A vertex of B alone is the end of any edge from it: the lowest one's.
        const int end = count_b == 2 ? vertices_b : vertices_b | (vertices_b == 1 ? 2 : 1);
        features = ClosestFeatures{ClosestFeatures::vertex_edge, lowest(vertices_a), edge(end)};
    } else if (count_a == 2 && count_b == 1) {
        features = ClosestFeatures{ClosestFeatures::edge_vertex, edge(vertices_a), lowest(vertices_b)};
    } else if (count_a == 2 && count_b == 2) {
        features = ClosestFeatures{ClosestFeatures::edge_edge, edge(vertices_a), edge(vertices_b)};
    } else {
        return false;
    }
    return true;
}

/// @brief Squared distance and closest points of a disjoint pair, in double, with the feature pair
/// that reaches them: GJK's where it can tell, else those of trying every feature pair.
KDET_HD inline double closest_points_and_features(const dvec3 a[4], const dvec3 b[4], dvec3& on_a, dvec3& on_b,
                                                  ClosestFeatures& features) {
    MinkowskiSimplex s;
    if (gjk_closest_points(a, b, on_a, on_b, s) && simplex_features(s, features)) return squared_distance(on_a, on_b);
    return closest_features(a, b, on_a, on_b, features);
}

} // namespace kdet::narrow
