#pragma once
/// @file closest_points.hpp
/// @brief Closest points in double between a point and a segment or a triangle, and between two
/// segments, degenerate ones included (a triangle whose points are collinear or coincide is taken as
/// the segment or point it is). Approximate: the distances and points that the margin stage reports
/// (tet_distance.hpp); the decisions themselves are exact there.

#include "geometry/dvec3.hpp"

namespace kdet::narrow {

KDET_HD inline double clamp01(double t) { return t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t); }

KDET_HD inline double squared_distance(dvec3 a, dvec3 b) {
    const dvec3 d = a - b;
    return dot(d, d);
}

/// @brief The point of segment [a, b] closest to p.
KDET_HD inline dvec3 closest_on_segment(dvec3 p, dvec3 a, dvec3 b) {
    const dvec3 e = b - a;
    const double length2 = dot(e, e);
    if (!(length2 > 0.0)) return a;
    return a + clamp01(dot(p - a, e) / length2) * e;
}

/// @brief Whether p projects into triangle (a, b, c) (not a degenerate one); then `projection` is set.
KDET_HD inline bool project_into_triangle(dvec3 p, dvec3 a, dvec3 b, dvec3 c, dvec3& projection) {
    const dvec3 n = cross(b - a, c - a);
    const double n2 = dot(n, n);
    if (!(n2 > 0.0)) return false;
    // Barycentric coordinates of the projection, each the signed area of a sub-triangle.
    const double u = dot(cross(c - b, p - b), n), v = dot(cross(a - c, p - c), n), w = dot(cross(b - a, p - a), n);
    if (!(u >= 0.0 && v >= 0.0 && w >= 0.0)) return false;
    projection = p - (dot(p - a, n) / n2) * n;
    return true;
}

/// @brief The point of triangle (a, b, c) closest to p: the projection where it falls inside, else the
/// closest point of the nearest edge.
KDET_HD inline dvec3 closest_on_triangle(dvec3 p, dvec3 a, dvec3 b, dvec3 c) {
    dvec3 projection;
    if (project_into_triangle(p, a, b, c, projection)) return projection;
    dvec3 best = closest_on_segment(p, a, b);
    const dvec3 on_bc = closest_on_segment(p, b, c), on_ca = closest_on_segment(p, c, a);
    if (squared_distance(p, on_bc) < squared_distance(p, best)) best = on_bc;
    if (squared_distance(p, on_ca) < squared_distance(p, best)) best = on_ca;
    return best;
}

/// @brief Closest points x on [a, b] and y on [c, d]: the lines' closest points where both fall inside
/// the segments (lines not parallel), else the best of the four endpoint-to-segment pairs.
KDET_HD inline void closest_between_segments(dvec3 a, dvec3 b, dvec3 c, dvec3 d, dvec3& x, dvec3& y) {
    const dvec3 e1 = b - a, e2 = d - c, n = cross(e1, e2);
    const double n2 = dot(n, n);
    if (n2 > 0.0) {
        const dvec3 w = c - a;
        const double s = dot(cross(w, e2), n) / n2, t = dot(cross(w, e1), n) / n2;
        if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0) {
            x = a + s * e1;
            y = c + t * e2;
            return;
        }
    }
    x = a;
    y = closest_on_segment(a, c, d);
    double best = squared_distance(x, y);
    const dvec3 ends[4] = {b, c, d, a};
    for (int k = 0; k < 3; ++k) {
        const bool on_first = k >= 1; // b lies on [a, b]; c and d on [c, d]
        const dvec3 p = ends[k];
        const dvec3 q = on_first ? closest_on_segment(p, a, b) : closest_on_segment(p, c, d);
        const double d2 = squared_distance(p, q);
        if (d2 < best) {
            best = d2;
            x = on_first ? q : p;
            y = on_first ? p : q;
        }
    }
}

} // namespace kdet::narrow
