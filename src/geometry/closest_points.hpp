#pragma once
/// @file closest_points.hpp
/// @brief Closest points in double between a point and a segment or a triangle (with its barycentric
/// coordinates), degenerate ones included (a triangle whose points are collinear or coincide is taken
/// as the segment or point it is), and between two lines. Approximate: the distances and points that
/// the margin stage (tet_closest.hpp, tet_distance.hpp) and point location (point_tet.hpp) report; the
/// decisions themselves are exact there.

#include "geometry/dvec3.hpp"

namespace kdet::narrow {

KDET_HD inline double clamp01(double t) { return t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t); }

KDET_HD inline double squared_distance(dvec3 a, dvec3 b) {
    const dvec3 d = a - b;
    return dot(d, d);
}

/// @brief Where on segment [a, b] the point closest to p lies, from 0 (a) to 1 (b); a point segment gives a.
KDET_HD inline double segment_parameter(dvec3 p, dvec3 a, dvec3 b) {
    const dvec3 e = b - a;
    const double length2 = dot(e, e);
    return length2 > 0.0 ? clamp01(dot(p - a, e) / length2) : 0.0;
}

/// @brief The point of segment [a, b] closest to p.
KDET_HD inline dvec3 closest_on_segment(dvec3 p, dvec3 a, dvec3 b) { return a + segment_parameter(p, a, b) * (b - a); }

/// @brief A closest point and its barycentric coordinates in the triangle (or segment) it lies on.
struct ClosestOnTriangle {
    dvec3 point;
    double weight[3]; ///< of the triangle's vertices a, b, c (c's 0 for a segment)
};

/// @brief closest_on_segment with the point's weights of a and b.
KDET_HD inline ClosestOnTriangle closest_on_edge(dvec3 p, dvec3 a, dvec3 b) {
    const double t = segment_parameter(p, a, b);
    return ClosestOnTriangle{a + t * (b - a), {1.0 - t, t, 0.0}};
}

/// @brief Whether p projects into triangle (a, b, c) whose normal n = (b - a) x (c - a) has n2 = |n|^2 > 0;
/// then `projection` is set.
KDET_HD inline bool project_into_triangle(dvec3 p, dvec3 a, dvec3 b, dvec3 c, dvec3 n, double n2, dvec3& projection) {
    // Barycentric coordinates of the projection, each the signed area of a sub-triangle.
    const double u = dot(cross(c - b, p - b), n), v = dot(cross(a - c, p - c), n), w = dot(cross(b - a, p - a), n);
    if (!(u >= 0.0 && v >= 0.0 && w >= 0.0)) return false;
    projection = p - (dot(p - a, n) / n2) * n;
    return true;
}

/// @brief The point of triangle abc closest to p, with its barycentric coordinates, by the triangle's
/// Voronoi regions (vertices, edges, inside), as in Ericson's Real-Time Collision Detection, 5.1.5. A
/// triangle without area (collinear or repeated vertices), whose inside region the test cannot divide
/// by, takes the closest of its three edges, the first one on a tie.
KDET_HD inline ClosestOnTriangle closest_on_triangle(dvec3 p, dvec3 a, dvec3 b, dvec3 c) {
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
        ClosestOnTriangle best = closest_on_edge(p, a, b);
        const ClosestOnTriangle bc = closest_on_edge(p, b, c), ca = closest_on_edge(p, c, a);
        double best_d = squared_distance(p, best.point);
        const double bc_d = squared_distance(p, bc.point), ca_d = squared_distance(p, ca.point);
        if (bc_d < best_d) {
            best = ClosestOnTriangle{bc.point, {0.0, bc.weight[0], bc.weight[1]}};
            best_d = bc_d;
        }
        if (ca_d < best_d) best = ClosestOnTriangle{ca.point, {ca.weight[1], 0.0, ca.weight[0]}};
        return best;
    }
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        const double v = d1 / (d1 - d3);
        return ClosestOnTriangle{a + v * ab, {1.0 - v, v, 0.0}};
    }
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        const double w = d2 / (d2 - d6);
        return ClosestOnTriangle{a + w * ac, {1.0 - w, 0.0, w}};
    }
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return ClosestOnTriangle{b + w * (c - b), {0.0, 1.0 - w, w}};
    }
    const double v = vb / area, w = vc / area;
    return ClosestOnTriangle{a + (v * ab + w * ac), {1.0 - v - w, v, w}};
}

/// @brief Where the lines through [a, a + e1] and [c, c + e2] come closest, n = e1 x e2 with n2 = |n|^2 > 0:
/// the parameters s along the first and t along the second.
KDET_HD inline void closest_on_lines(dvec3 a, dvec3 e1, dvec3 c, dvec3 e2, dvec3 n, double n2, double& s, double& t) {
    const dvec3 w = c - a;
    s = dot(cross(w, e2), n) / n2;
    t = dot(cross(w, e1), n) / n2;
}

} // namespace kdet::narrow
