#pragma once
/// @file tet_pair.hpp
/// @brief Pieces shared by the tetrahedron-tetrahedron tests: the pair moved to a local frame of unit
/// size, the relative tolerances, face normals, edge cross products and projections onto an axis.
///
/// Every test first translates both tets by the first tet's vertex 0 and divides by the longest edge
/// of the pair. Then all lengths are about 1 wherever the tets can touch, and one set of tolerances
/// fits tets of any size and position.

#include <cmath>

#include "geometry/vec3.hpp"

namespace kdet::narrow {

/// @brief Machine epsilon of float (FLT_EPSILON).
constexpr float k_float_eps = 1.1920929e-7f;

/// @brief Two edges (or the two edges of a face) whose angle has a sine below sqrt(eps) give no
/// usable axis: their cross product is mostly rounding. Skipping them is safe, since exactly parallel
/// edges add no face to the Minkowski difference.
constexpr float k_parallel_sine = 3.4526698e-4f;

/// @brief A gap along an axis proves separation only above this, in units of the longest edge.
/// While the tets intersect, every point lies within 2 of the origin, so rounding of the frame change
/// and of the projections moves a gap by at most about 10 eps; 32 eps keeps a margin of 3.
constexpr float k_gap_tolerance = 32.0f * k_float_eps;

/// @brief A value larger than any overlap in the unit frame.
constexpr float k_huge = 3.0e38f;

/// @brief Edge axes computed at once by edge_axis_lanes: on the host one per edge of the second tet,
/// side by side in vector instructions (six, padded to eight); on the GPU one, so that a thread stops
/// at the first axis that separates and keeps no lanes in registers.
#if defined(__CUDA_ARCH__)
constexpr int k_edge_lanes = 1;
#else
constexpr int k_edge_lanes = 8;
#endif

/// @brief A tet's six edges coordinate by coordinate (a row per coordinate), then two zero edges
/// (which give no usable axis), so that edge_axis_lanes loads each coordinate of eight at once.
struct EdgeRows {
    static constexpr int padded = 8;
    float x[padded], y[padded], z[padded];
    KDET_HD vec3 operator[](int k) const { return vec3{x[k], y[k], z[k]}; }
    KDET_HD void set(int k, vec3 e) {
        x[k] = e.x;
        y[k] = e.y;
        z[k] = e.z;
    }
    /// @brief Sets the edges after the six to zero, and the same entries of a per-edge array.
    KDET_HD void pad(float* per_edge) {
        for (int k = 6; k < padded; ++k) {
            set(k, vec3{0.0f, 0.0f, 0.0f});
            per_edge[k] = 0.0f;
        }
    }
};
static_assert(k_edge_lanes <= EdgeRows::padded, "edge_axis_lanes reads k_edge_lanes edges from the first");

/// @brief Both tets in the local frame: origin at a[0], longest edge of the pair 1.
struct LocalPair {
    vec3 a[4];
    vec3 b[4];
    vec3 edge_a[6];            ///< edges in the order (0,1) (0,2) (0,3) (1,2) (1,3) (2,3)
    EdgeRows edge_b;           ///< the same order, then zero edges
    float length2_a[6];        ///< squared edge lengths in the local frame
    float length2_b[EdgeRows::padded];
    float scale; ///< longest edge in input units: multiply local lengths by it to get input lengths
};

/// @brief First and second vertex of edge k (0..5) of a tet, in the order of LocalPair.
KDET_HD inline int edge_first(int k) { return k < 3 ? 0 : (k < 5 ? 1 : 2); }
KDET_HD inline int edge_second(int k) { return k < 3 ? k + 1 : (k < 5 ? k - 1 : 3); }

/// @brief GJK's support point of the Minkowski difference A - B along -v: the vertex ia of A lowest
/// along v and the vertex ib of B highest (the first on a tie), for float or double vectors.
template <class V>
KDET_HD inline void lowest_difference(const V a[4], const V b[4], V v, int& ia, int& ib) {
    ia = 0;
    ib = 0;
    auto lo = dot(a[0], v), hi = dot(b[0], v);
    for (int i = 1; i < 4; ++i) {
        const auto da = dot(a[i], v), db = dot(b[i], v);
        if (da < lo) {
            lo = da;
            ia = i;
        }
        if (db > hi) {
            hi = db;
            ib = i;
        }
    }
}

/// @brief Fills p with the pair in the local frame. Returns false when every edge of both tets has
/// zero length (two points), where no frame of unit size exists. Tets of any size whose edges are
/// finite floats get the same frame as the same tets scaled by a power of two.
KDET_HD inline bool make_local_pair(const vec3 a[4], const vec3 b[4], LocalPair& p) {
    const vec3 origin = a[0];
    for (int i = 0; i < 4; ++i) {
        p.a[i] = a[i] - origin;
        p.b[i] = b[i] - origin;
    }
    float longest2 = 0.0f;
    for (int k = 0; k < 6; ++k) {
        p.edge_a[k] = p.a[edge_second(k)] - p.a[edge_first(k)];
        p.edge_b.set(k, p.b[edge_second(k)] - p.b[edge_first(k)]);
        longest2 = max_f(longest2, max_f(length_squared(p.edge_a[k]), length_squared(p.edge_b[k])));
    }
    // Where a square may have under- or overflowed, the pair is first scaled by the power of two that
    // brings its largest edge coordinate into [1/2, 1) (exact, as is every later step's rounding, which
    // scales with it): then the answer does not depend on the pair's size.
    int exponent = 0;
    if (!(longest2 >= 0x1p-100f && longest2 <= 0x1p100f)) {
        float largest = 0.0f;
        for (int k = 0; k < 6; ++k) largest = max_f(largest, max_f(max_abs(p.edge_a[k]), max_abs(p.edge_b[k])));
        if (!(largest > 0.0f)) return false;
        if (largest <= 3.4028235e38f) {
            exponent = frexp_exponent(largest);
            for (int i = 0; i < 4; ++i) {
                p.a[i] = times_power_of_two(p.a[i], -exponent);
                p.b[i] = times_power_of_two(p.b[i], -exponent);
            }
            longest2 = 0.0f;
            for (int k = 0; k < 6; ++k) {
                p.edge_a[k] = times_power_of_two(p.edge_a[k], -exponent);
                p.edge_b.set(k, times_power_of_two(p.edge_b[k], -exponent));
                longest2 = max_f(longest2, max_f(length_squared(p.edge_a[k]), length_squared(p.edge_b[k])));
            }
        }
    }
    const float local_scale = sqrtf(longest2);
    p.scale = times_power_of_two(local_scale, exponent);
    const float inverse = 1.0f / local_scale;
    for (int i = 0; i < 4; ++i) {
        p.a[i] = p.a[i] * inverse;
        p.b[i] = p.b[i] * inverse;
    }
    for (int k = 0; k < 6; ++k) {
        p.edge_a[k] = p.edge_a[k] * inverse;
        p.edge_b.set(k, p.edge_b[k] * inverse);
        p.length2_a[k] = length_squared(p.edge_a[k]);
        p.length2_b[k] = length_squared(p.edge_b[k]);
    }
    p.edge_b.pad(p.length2_b);
    return true;
}

/// @brief The answer for two tets that are single points: closed sets meet only if the points do.
KDET_HD inline bool points_coincide(vec3 a, vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/// @brief cross(e, f) and its squared length, or false when the sine of their angle is below
/// k_parallel_sine (this includes zero-length edges). e_length2 and f_length2 are |e|^2 and |f|^2.
KDET_HD inline bool edge_axis(vec3 e, float e_length2, vec3 f, float f_length2, vec3& axis, float& length2) {
    axis = cross(e, f);
    length2 = length_squared(axis);
    return length2 > k_parallel_sine * k_parallel_sine * e_length2 * f_length2;
}

/// @brief Normal of face k (the face opposite vertex k) of tet v, either orientation, not normalised,
/// and its squared length; false for a degenerate face. The cross product uses the two edges at the
/// vertex opposite the longest edge: their angle is the largest of the triangle, which keeps the
/// rounding smallest.
KDET_HD inline bool face_axis(const vec3 v[4], int k, vec3& axis, float& length2) {
    const vec3 p0 = v[(k + 1) & 3], p1 = v[(k + 2) & 3], p2 = v[(k + 3) & 3];
    const vec3 e01 = p1 - p0, e02 = p2 - p0, e12 = p2 - p1;
    const float l01 = length_squared(e01), l02 = length_squared(e02), l12 = length_squared(e12);
    if (l12 >= l01 && l12 >= l02) return edge_axis(e01, l01, e02, l02, axis, length2);
    if (l02 >= l01) return edge_axis(e01, l01, e12, l12, axis, length2);
    return edge_axis(e02, l02, e12, l12, axis, length2);
}

/// @brief axis scaled to unit length; length2 is its squared length (nonzero).
KDET_HD inline vec3 unit(vec3 axis, float length2) { return axis * (1.0f / sqrtf(length2)); }

/// @brief Closed interval of the projections of a tet's vertices onto an axis.
struct Interval {
    float lo, hi;
};

KDET_HD inline Interval project(const vec3 v[4], vec3 axis) {
    const float d0 = dot(v[0], axis), d1 = dot(v[1], axis), d2 = dot(v[2], axis), d3 = dot(v[3], axis);
    return Interval{min_f(min_f(d0, d1), min_f(d2, d3)), max_f(max_f(d0, d1), max_f(d2, d3))};
}

/// @brief The axes cross(edge i of A, edge j of B) for j = first .. first + k_edge_lanes - 1 (those
/// past 5 are zero axes), with both tets' projections onto them. `over_up` and `over_down` are what
/// remains of the overlap when B moves along +axis and -axis (times |axis|): a negative one is a gap.
struct EdgeAxisLanes {
    float x[k_edge_lanes], y[k_edge_lanes], z[k_edge_lanes];
    float over_up[k_edge_lanes], over_down[k_edge_lanes];
};

/// @brief Fills `lanes` for edge i of A and the edges of B from `first` on; Pair has vertices a, b
/// and edges edge_a, edge_b (EdgeRows).
template <class Pair>
KDET_HD inline void edge_axis_lanes(const Pair& p, int i, int first, EdgeAxisLanes& lanes) {
    const vec3 e = p.edge_a[i];
    KDET_VECTOR_LOOP
    for (int l = 0; l < k_edge_lanes; ++l) {
        const int j = first + l;
        const vec3 f{p.edge_b.x[j], p.edge_b.y[j], p.edge_b.z[j]};
        const vec3 axis = cross(e, f);
        // The four projections of each tet written out: a loop here would keep GCC from packing the lanes.
        const float a0 = dot(p.a[0], axis), a1 = dot(p.a[1], axis), a2 = dot(p.a[2], axis), a3 = dot(p.a[3], axis);
        const float b0 = dot(p.b[0], axis), b1 = dot(p.b[1], axis), b2 = dot(p.b[2], axis), b3 = dot(p.b[3], axis);
        const float lo_a = min_f(min_f(a0, a1), min_f(a2, a3)), hi_a = max_f(max_f(a0, a1), max_f(a2, a3));
        const float lo_b = min_f(min_f(b0, b1), min_f(b2, b3)), hi_b = max_f(max_f(b0, b1), max_f(b2, b3));
        lanes.x[l] = axis.x;
        lanes.y[l] = axis.y;
        lanes.z[l] = axis.z;
        lanes.over_up[l] = hi_a - lo_b;
        lanes.over_down[l] = hi_b - lo_a;
    }
}

/// @brief Largest gap between the projections of the two tets onto a unit axis, in the local frame:
/// positive when the axis separates them, minus the overlap otherwise.
KDET_HD inline float projection_gap(const LocalPair& p, vec3 axis) {
    const Interval ia = project(p.a, axis), ib = project(p.b, axis);
    return max_f(ib.lo - ia.hi, ia.lo - ib.hi);
}

} // namespace kdet::narrow
