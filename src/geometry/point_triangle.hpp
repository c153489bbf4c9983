#pragma once
/// @file point_triangle.hpp
/// @brief The closest point of a triangle (or a segment) to a point, in double, with its barycentric
/// coordinates: what point location reports for a point that no tet holds.

#include "geometry/exact_test.hpp"

namespace kdet::point_query {

using narrow::dvec3;

KDET_HD inline dvec3 add(dvec3 a, dvec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
KDET_HD inline dvec3 scale(dvec3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
KDET_HD inline double distance_squared(dvec3 a, dvec3 b) {
    const dvec3 d = narrow::operator-(a, b);
    return narrow::dot(d, d);
}

/// @brief A closest point and its barycentric coordinates in the triangle (or segment) it lies on.
struct ClosestOnTriangle {
    dvec3 point;
    double weight[3]; ///< of the triangle's vertices a, b, c (c's 0 for a segment)
};

/// @brief The closest point of segment [a, b] to p; a point segment gives a.
KDET_HD inline ClosestOnTriangle closest_on_segment(dvec3 p, dvec3 a, dvec3 b) {
    const dvec3 ab = narrow::operator-(b, a);
    const double length2 = narrow::dot(ab, ab);
    double t = length2 > 0.0 ? narrow::dot(narrow::operator-(p, a), ab) / length2 : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    return ClosestOnTriangle{add(a, scale(ab, t)), {1.0 - t, t, 0.0}};
}

/// @brief The closest point of triangle abc to p by its Voronoi regions (vertices, edges, inside), as
/// in Ericson's Real-Time Collision Detection, 5.1.5. A triangle without area (collinear or repeated
/// vertices), whose inside region the test cannot divide by, takes the closest of its three edges.
KDET_HD inline ClosestOnTriangle closest_on_triangle(dvec3 p, dvec3 a, dvec3 b, dvec3 c) {
    using narrow::dot;
    using narrow::operator-;
    const dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return ClosestOnTriangle{a, {1.0, 0.0, 0.0}};
    const dvec3 bp = p - b;
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return ClosestOnTriangle{b, {0.0, 1.0, 0.0}};
    const dvec3 cp = p - c;
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return ClosestOnTriangle{c, {0.0, 0.0, 1.0}};
    const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    const double area = va + vb + vc;
    if (!(area > 0.0)) {
        // No area: the closest of the edges, the first one on a tie.
        ClosestOnTriangle best = closest_on_segment(p, a, b);
        ClosestOnTriangle bc = closest_on_segment(p, b, c), ca = closest_on_segment(p, c, a);
        double best_d = distance_squared(p, best.point);
        const double bc_d = distance_squared(p, bc.point), ca_d = distance_squared(p, ca.point);
        if (bc_d < best_d) {
            best = ClosestOnTriangle{bc.point, {0.0, bc.weight[0], bc.weight[1]}};
            best_d = bc_d;
        }
        if (ca_d < best_d) best = ClosestOnTriangle{ca.point, {ca.weight[1], 0.0, ca.weight[0]}};
        return best;
    }
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        const double v = d1 / (d1 - d3);
        return ClosestOnTriangle{add(a, scale(ab, v)), {1.0 - v, v, 0.0}};
    }
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        const double w = d2 / (d2 - d6);
        return ClosestOnTriangle{add(a, scale(ac, w)), {1.0 - w, 0.0, w}};
    }
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return ClosestOnTriangle{add(b, scale(c - b, w)), {0.0, 1.0 - w, w}};
    }
    const double v = vb / area, w = vc / area;
    return ClosestOnTriangle{add(a, add(scale(ab, v), scale(ac, w))), {1.0 - v - w, v, w}};
}

} // namespace kdet::point_query
