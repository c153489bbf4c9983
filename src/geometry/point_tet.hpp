#pragma once
/// @file point_tet.hpp
/// @brief Whether a closed tet holds a point, decided exactly for float coordinates; the point's
/// barycentric coordinates in it, or the tet's closest point to it, in double.

#include "geometry/exact_test.hpp"
#include "geometry/closest_points.hpp"

namespace kdet::point_query {

using narrow::dvec3;

/// @brief Exact sign of orient3d(a, b, c, d) = det(b - a, c - a, d - a) for float points: the double
/// determinant where its proven bound decides, the exact sum otherwise (narrow::sign_det3).
KDET_HD inline int orient3d_sign(vec3 a, vec3 b, vec3 c, vec3 d) {
    return narrow::sign_det3(narrow::Segment{a, b}, narrow::Segment{a, c}, narrow::Segment{a, d});
}

/// @brief The tet with vertex k replaced by p.
KDET_HD inline void replace_vertex(const vec3 v[4], int k, vec3 p, vec3 out[4]) {
    for (int i = 0; i < 4; ++i) out[i] = i == k ? p : v[i];
}

/// @brief How a tet and a point lie: the tet's orientation (0: no volume) and, for a tet with volume,
/// the sign of each orientation with vertex k replaced by the point.
struct PointTetSigns {
    int tet;
    int face[4];
};

/// @brief Whether the closed tet v, whose orientation (orient3d_sign of its vertices) is given, holds
/// p, exactly. A tet with volume holds p iff no orientation with a
/// vertex replaced by p has the opposite sign of the tet's own (zero: p lies on that face's plane).
/// A tet without volume is decided by the exact tet-tet test against the point as a tet of four equal
/// vertices, which handles flat and collinear tets.
KDET_HD inline bool tet_holds_point(const vec3 v[4], vec3 p, int orientation, PointTetSigns& signs) {
    signs.tet = orientation;
    if (signs.tet == 0) {
        const vec3 point[4] = {p, p, p, p};
        bool exact_stage = false;
        return narrow::exact_intersect(v, point, exact_stage);
    }
    bool holds = true;
    for (int k = 0; k < 4; ++k) {
        vec3 w[4];
        replace_vertex(v, k, p, w);
        signs.face[k] = orient3d_sign(w[0], w[1], w[2], w[3]);
        if (signs.face[k] == -signs.tet) {
            holds = false;
            break;
        }
    }
    return holds;
}

/// @brief As above, with the tet's orientation computed here (a caller testing many points against
/// one tet computes it once instead).
KDET_HD inline bool tet_holds_point(const vec3 v[4], vec3 p, PointTetSigns& signs) {
    return tet_holds_point(v, p, orient3d_sign(v[0], v[1], v[2], v[3]), signs);
}

/// @brief A point's place relative to a tet, in double: barycentric coordinates (of the point when the
/// tet holds it, else of the tet's closest point), that closest point and the distance to it.
struct PointInTet {
    double barycentric[4];
    dvec3 closest;
    double distance;
};

/// @brief The closest point of the tet's boundary to p: the closest of its four faces' (face k is
/// opposite vertex k), the first on a tie.
KDET_HD inline PointInTet closest_on_tet_boundary(const vec3 v[4], vec3 p) {
    const dvec3 q = narrow::widen(p);
    PointInTet best{};
    double best_d = 0.0;
    for (int k = 0; k < 4; ++k) {
        const int i0 = k == 0 ? 1 : 0, i1 = k <= 1 ? 2 : 1, i2 = k <= 2 ? 3 : 2;
        const narrow::ClosestOnTriangle c =
            narrow::closest_on_triangle(q, narrow::widen(v[i0]), narrow::widen(v[i1]), narrow::widen(v[i2]));
        const double d = narrow::squared_distance(q, c.point);
        if (k == 0 || d < best_d) {
            best_d = d;
            best.closest = c.point;
            for (int i = 0; i < 4; ++i) best.barycentric[i] = 0.0;
            best.barycentric[i0] = c.weight[0];
            best.barycentric[i1] = c.weight[1];
            best.barycentric[i2] = c.weight[2];
        }
    }
    best.distance = sqrt(best_d);
    return best;
}

/// @brief Where p lies in tet v, given whether the tet holds it (tet_holds_point, with its signs).
/// For a tet with volume that holds p: the barycentric coordinates are the orientations with p in
/// place of each vertex over their sum (those the exact signs put on a face exactly 0, any the double
/// values put on the wrong side 0 too), the point itself and distance 0. Otherwise the closest point
/// of the boundary (for a tet without volume that holds p, distance 0 and the point itself).
KDET_HD inline PointInTet locate_in_tet(const vec3 v[4], vec3 p, bool holds, const PointTetSigns& signs) {
    if (holds && signs.tet != 0) {
        PointInTet r;
        double sum = 0.0;
        for (int k = 0; k < 4; ++k) {
            double part = 0.0;
            if (signs.face[k] != 0) {
                vec3 w[4];
                replace_vertex(v, k, p, w);
                const dvec3 a = narrow::widen(w[0]);
                const double det = narrow::dot(narrow::cross(narrow::operator-(narrow::widen(w[1]), a),
                                                             narrow::operator-(narrow::widen(w[2]), a)),
                                               narrow::operator-(narrow::widen(w[3]), a));
                part = signs.tet > 0 ? det : -det;
                if (part < 0.0) part = 0.0;
            }
            r.barycentric[k] = part;
            sum += part;
        }
        // The exact orientations sum to the tet's, which is not 0: some part is positive.
        for (int k = 0; k < 4; ++k) r.barycentric[k] = sum > 0.0 ? r.barycentric[k] / sum : (k == 0 ? 1.0 : 0.0);
        r.closest = narrow::widen(p);
        r.distance = 0.0;
        return r;
    }
    PointInTet r = closest_on_tet_boundary(v, p);
    if (holds) {
        r.closest = narrow::widen(p);
        r.distance = 0.0;
    }
    return r;
}

} // namespace kdet::point_query
