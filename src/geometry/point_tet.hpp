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
/// the sign of each orientation with vertex k replaced by the point and its value in double (as
/// TetFaces computes it, within the bound of narrow::sign_det3).
struct PointTetSigns {
    int tet;
    int face[4];
    double det[4];
};

/// @brief A tet's faces prepared for testing many points of its box: the orientation with p in place
/// of vertex k is det(e1, e2, p - base[k]) for two edges e1, e2 of face k from its vertex base[k]
/// (after an odd permutation of its rows for faces 0 and 2, folded into the normal's sign), so their
/// double cross product is computed once per tet. Per point it is then narrow::sign_det3's own
/// computation, a dot product decided where it exceeds its bound, else the exact sign; the bound's
/// factor max|p - base[k]| is bounded once for every point of the box by the box's largest side (the
/// differences of coordinates within it, rounded, are no larger), so it too is computed once.
struct TetFaces {
    // Per face k, side by side so that the four are computed together.
    double base_x[4], base_y[4], base_z[4];
    double normal_x[4], normal_y[4], normal_z[4];
    double error[4]; ///< the double value's rounding bound for any point of the tet's box
    TetFaces() = default;
    KDET_HD explicit TetFaces(const vec3 v[4]) {
        // Face k's rows: v[first[k]] - v[from[k]], v[second[k]] - v[from[k]], p - v[from[k]].
        const int from[4] = {1, 0, 0, 0}, first[4] = {2, 2, 1, 1}, second[4] = {3, 3, 3, 2};
        const bool odd[4] = {true, false, true, false};
        const Aabb box = tet_box(v);
        const double side =
            narrow::max_d(double{box.hi.x} - double{box.lo.x}, narrow::max_d(double{box.hi.y} - double{box.lo.y}, double{box.hi.z} - double{box.lo.z}));
        for (int k = 0; k < 4; ++k) {
            const dvec3 base = narrow::widen(v[from[k]]);
            const dvec3 e1 = narrow::operator-(narrow::widen(v[first[k]]), base);
            const dvec3 e2 = narrow::operator-(narrow::widen(v[second[k]]), base);
            const dvec3 normal = narrow::cross(e1, e2);
            base_x[k] = base.x;
            base_y[k] = base.y;
            base_z[k] = base.z;
            normal_x[k] = odd[k] ? -normal.x : normal.x;
            normal_y[k] = odd[k] ? -normal.y : normal.y;
            normal_z[k] = odd[k] ? -normal.z : normal.z;
            error[k] = narrow::k_double_det_bound * narrow::norm1(e1) * narrow::norm1(e2) * side;
        }
    }
    /// Per face k, the orientation of v with vertex k replaced by p (a point of the tet's box), in
    /// double: plain loops over the faces, which a compiler runs two or four faces at a time.
    KDET_HD void face_values(vec3 p, double value[4]) const {
        double rx[4], ry[4], rz[4];
        for (int k = 0; k < 4; ++k) {
            rx[k] = double{p.x} - base_x[k];
            ry[k] = double{p.y} - base_y[k];
            rz[k] = double{p.z} - base_z[k];
        }
        for (int k = 0; k < 4; ++k) value[k] = normal_x[k] * rx[k] + normal_y[k] * ry[k] + normal_z[k] * rz[k];
    }
    /// The exact sign of that orientation: the double value where it exceeds its bound.
    KDET_HD int decided_sign(const vec3 v[4], int k, vec3 p, double value) const {
        if (value > error[k]) return 1;
        if (value < -error[k]) return -1;
        vec3 w[4];
        replace_vertex(v, k, p, w);
        return orient3d_sign(w[0], w[1], w[2], w[3]);
    }
};

/// @brief Whether the closed tet v, whose orientation (orient3d_sign of its vertices) and faces are
/// given, holds p, a point of its box, exactly. A tet with volume holds p iff no orientation with a
/// vertex replaced by p has the opposite sign of the tet's own (zero: p lies on that face's plane).
/// The four double values come first: one certainly opposite decides without any exact sign.
/// A tet without volume is decided by the exact tet-tet test against the point as a tet of four equal
/// vertices, which handles flat and collinear tets.
KDET_HD inline bool tet_holds_point(const TetFaces& faces, const vec3 v[4], vec3 p, int orientation, PointTetSigns& signs) {
    signs.tet = orientation;
    if (signs.tet == 0) {
        const vec3 point[4] = {p, p, p, p};
        bool exact_stage = false;
        return narrow::exact_intersect(v, point, exact_stage);
    }
    faces.face_values(p, signs.det);
    bool opposite = false;
    for (int k = 0; k < 4; ++k) opposite |= signs.tet * signs.det[k] < -faces.error[k];
    if (opposite) return false;
    for (int k = 0; k < 4; ++k) {
        signs.face[k] = faces.decided_sign(v, k, p, signs.det[k]);
        if (signs.face[k] == -signs.tet) return false;
    }
    return true;
}

/// @brief As above for any point, with the tet's orientation and faces computed here (a caller
/// testing many points against one tet computes them once instead).
KDET_HD inline bool tet_holds_point(const vec3 v[4], vec3 p, PointTetSigns& signs) {
    const int orientation = orient3d_sign(v[0], v[1], v[2], v[3]);
    // The box holds the closed tet: a point outside it is outside the tet.
    if (!box_holds(tet_box(v), p)) {
        signs.tet = orientation;
        return false;
    }
    return tet_holds_point(TetFaces(v), v, p, orientation, signs);
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
/// place of each vertex (the double values in `signs`) over their sum (those the exact signs put on a
/// face exactly 0, any the double values put on the wrong side 0 too), the point itself and distance 0. Otherwise the closest point
/// of the boundary (for a tet without volume that holds p, distance 0 and the point itself).
KDET_HD inline PointInTet locate_in_tet(const vec3 v[4], vec3 p, bool holds, const PointTetSigns& signs) {
    if (holds && signs.tet != 0) {
        PointInTet r;
        double sum = 0.0;
        for (int k = 0; k < 4; ++k) {
            double part = 0.0;
            if (signs.face[k] != 0) {
                part = signs.tet > 0 ? signs.det[k] : -signs.det[k];
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
