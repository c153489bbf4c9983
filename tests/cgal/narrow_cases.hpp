#pragma once
/// @file narrow_cases.hpp
/// @brief Tetrahedron pairs for validating the narrow phase against CGAL: deterministic generators of
/// hard cases, the exact oracle, and double-precision SAT quantities (margin, least overlap).
///
/// Shared by the CGAL tests and the narrow-phase report. Everything here is test code: CGAL is never a
/// dependency of the kdet library.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Gmpzf.h>
#include <CGAL/Homogeneous.h>
#include <CGAL/Polytope_distance_d.h>
#include <CGAL/Polytope_distance_d_traits_3.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include "geometry/vec3.hpp"

namespace kdet::cgal_check {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Tetrahedron = Kernel::Tetrahedron_3;

/// @brief The kinds of generated pairs.
enum class CaseKind {
    random,          ///< two random tets near each other
    shared_vertex,   ///< the second tet reuses one vertex of the first
    shared_edge,     ///< ... two vertices
    shared_face,     ///< ... three vertices, fourth on either side
    vertex_on_face,  ///< a vertex of the second tet on (or near) a face of the first, body outside
    edge_on_edge,    ///< an edge of the second tet crossing (or near) an edge of the first, body outside
    translated_copy, ///< the second tet is the first moved: all edges parallel, often near touching
    sliver,          ///< one or both tets nearly flat
    face_on_face,    ///< a face of the second tet in (or near) the plane of a face of the first, body outside
    needle,          ///< the first tet long and thin (width 1e-2 to 1e-4 of its length)
    // Exactly representable coordinates (integers times a power of two) with exact contacts, then
    // possibly moved by one lattice unit: the cases that only exact arithmetic decides.
    lattice_vertex_on_face, ///< a vertex exactly inside a face of the first tet, body outside
    lattice_edge_on_edge,   ///< an edge exactly crossing an edge of the first tet, bodies on either side
    lattice_face_on_face,   ///< a face exactly in the plane of a face of the first tet, body outside
    lattice_translated_copy, ///< the first tet moved by one of its edge vectors: touching at a vertex
    lattice_random,          ///< two random lattice tets near each other
};
constexpr CaseKind k_case_kinds[] = {CaseKind::random,
                                     CaseKind::shared_vertex,
                                     CaseKind::shared_edge,
                                     CaseKind::shared_face,
                                     CaseKind::vertex_on_face,
                                     CaseKind::edge_on_edge,
                                     CaseKind::translated_copy,
                                     CaseKind::sliver,
                                     CaseKind::face_on_face,
                                     CaseKind::needle,
                                     CaseKind::lattice_vertex_on_face,
                                     CaseKind::lattice_edge_on_edge,
                                     CaseKind::lattice_face_on_face,
                                     CaseKind::lattice_translated_copy,
                                     CaseKind::lattice_random};
constexpr int k_case_kind_count = 15;

inline const char* case_kind_name(CaseKind kind) {
    switch (kind) {
    case CaseKind::random: return "random";
    case CaseKind::shared_vertex: return "shared_vertex";
    case CaseKind::shared_edge: return "shared_edge";
    case CaseKind::shared_face: return "shared_face";
    case CaseKind::vertex_on_face: return "vertex_on_face";
    case CaseKind::edge_on_edge: return "edge_on_edge";
    case CaseKind::translated_copy: return "translated_copy";
    case CaseKind::sliver: return "sliver";
    case CaseKind::face_on_face: return "face_on_face";
    case CaseKind::needle: return "needle";
    case CaseKind::lattice_vertex_on_face: return "lattice_vertex_on_face";
    case CaseKind::lattice_edge_on_edge: return "lattice_edge_on_edge";
    case CaseKind::lattice_face_on_face: return "lattice_face_on_face";
    case CaseKind::lattice_translated_copy: return "lattice_translated_copy";
    case CaseKind::lattice_random: return "lattice_random";
    }
    return "?";
}

inline bool is_lattice(CaseKind kind) { return kind >= CaseKind::lattice_vertex_on_face; }

/// @brief Tet sizes and offsets from the origin (relative to the size, capped at 1e6 absolute).
constexpr double k_sizes[] = {1e-6, 1e-3, 1.0, 1e3, 1e6};
constexpr int k_size_count = 5;
constexpr double k_relative_offsets[] = {0.0, 1e2, 1e4, 1e6};
constexpr double k_max_offset = 1e6;

/// @brief Margin buckets: |margin| above k_clear_margin must be decided exactly by every exact test.
constexpr double k_clear_margin = 1e-5;
constexpr double k_touching_margin = 1e-7;
enum class Bucket { clear, near, touching };
constexpr int k_bucket_count = 3;
inline const char* bucket_name(Bucket b) {
    return b == Bucket::clear ? "clear (|m|>1e-5)" : (b == Bucket::near ? "near (1e-7<|m|<=1e-5)" : "touching (|m|<=1e-7)");
}
inline Bucket bucket_of(double margin) {
    const double m = std::fabs(margin);
    return m > k_clear_margin ? Bucket::clear : (m > k_touching_margin ? Bucket::near : Bucket::touching);
}

/// @brief One generated pair with its ground truth.
struct Case {
    vec3 a[4];
    vec3 b[4];
    CaseKind kind;
    double size;
    bool truth;    ///< CGAL: do the closed tets intersect?
    double margin; ///< max SAT gap over the 44 axes / longest edge, in double (negative: -least overlap)
};

// ---------------------------------------------------------------------------------------------
// Double-precision geometry.

struct d3 {
    double x, y, z;
};
inline d3 operator+(d3 a, d3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline d3 operator-(d3 a, d3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline d3 operator*(d3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline double dot(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline d3 cross(d3 a, d3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline d3 to_d3(vec3 v) { return {v.x, v.y, v.z}; }
inline vec3 to_vec3(d3 v) { return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)}; }
inline d3 normalized(d3 v) { return v * (1.0 / std::sqrt(dot(v, v))); }

inline Point to_point(d3 v) { return Point(v.x, v.y, v.z); }

inline Tetrahedron to_tetrahedron(const d3 v[4]) {
    return Tetrahedron(to_point(v[0]), to_point(v[1]), to_point(v[2]), to_point(v[3]));
}

// The oracle calls are never inlined: CGAL's filters switch the rounding mode, and GCC (even with
// -frounding-math) may move the caller's own floating-point arithmetic across the switch. Seen at
// -O3 when inlined: exactly degenerate tets passed `degenerate` and CGAL then answered wrongly.

/// @brief Exact: are the four points coplanar? (CGAL's tet test requires non-degenerate tets.)
[[gnu::noinline]] inline bool degenerate(const d3 v[4]) {
    return CGAL::orientation(to_point(v[0]), to_point(v[1]), to_point(v[2]), to_point(v[3])) == CGAL::COPLANAR;
}

/// @brief Exact oracle on double coordinates (closed sets).
[[gnu::noinline]] inline bool cgal_intersect(const d3 a[4], const d3 b[4]) {
    return CGAL::do_intersect(to_tetrahedron(a), to_tetrahedron(b));
}

/// @brief The exact squared distance of two hulls, numerator / denominator.
struct HullSquaredDistance {
    CGAL::Gmpzf numerator, denominator;
};

/// @brief CGAL's polytope distance of two sets of 4 points with Gmpzf arithmetic throughout (exact,
/// degenerate sets included), its solution checked (is_valid) every time.
[[gnu::noinline]] inline HullSquaredDistance cgal_hull_distance(const d3 a[4], const d3 b[4]) {
    using HomogeneousKernel = CGAL::Homogeneous<double>;
    using Distance =
        CGAL::Polytope_distance_d<CGAL::Polytope_distance_d_traits_3<HomogeneousKernel, CGAL::Gmpzf, CGAL::Gmpzf>>;
    HomogeneousKernel::Point_3 p[4], q[4];
    for (int i = 0; i < 4; ++i) {
        p[i] = HomogeneousKernel::Point_3(a[i].x, a[i].y, a[i].z, 1.0);
        q[i] = HomogeneousKernel::Point_3(b[i].x, b[i].y, b[i].z, 1.0);
    }
    const Distance distance(p, p + 4, q, q + 4);
    if (!distance.is_valid()) throw std::runtime_error("CGAL's polytope distance found no valid solution");
    return {distance.squared_distance_numerator(), distance.squared_distance_denominator()};
}

/// @brief Exact oracle for any two sets of 4 points, degenerate ones included: the squared distance
/// between their convex hulls, computed exactly (CGAL's polytope distance with Gmpzf arithmetic
/// throughout: with double as its inner number type it returned an invalid non-zero distance for
/// flat tets sharing a vertex, one coordinate 2^-65), is zero iff the hulls meet. The solution is
/// checked (is_valid) every time.
[[gnu::noinline]] inline bool cgal_hulls_meet(const d3 a[4], const d3 b[4]) { return cgal_hull_distance(a, b).numerator == 0; }

inline void widen(const vec3 v[4], d3 out[4]) {
    for (int i = 0; i < 4; ++i) out[i] = to_d3(v[i]);
}

/// @brief The 44 SAT axes of a pair (unit, double), skipping near-parallel edge pairs at a double
/// threshold (far below float's): any axis gives a valid gap, so this only adds axes.
inline std::vector<d3> sat_axes(const d3 a[4], const d3 b[4]) {
    std::vector<d3> axes;
    const int edges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    auto add = [&](d3 e, d3 f) {
        const d3 c = cross(e, f);
        if (dot(c, c) > 1e-24 * dot(e, e) * dot(f, f)) axes.push_back(normalized(c));
    };
    for (const d3* t : {a, b})
        for (int k = 0; k < 4; ++k) {
            const d3 p0 = t[(k + 1) & 3], p1 = t[(k + 2) & 3], p2 = t[(k + 3) & 3];
            add(p1 - p0, p2 - p0);
        }
    for (auto& ea : edges)
        for (auto& eb : edges) add(a[ea[1]] - a[ea[0]], b[eb[1]] - b[eb[0]]);
    return axes;
}

inline double longest_edge(const d3 a[4], const d3 b[4]) {
    double l2 = 0.0;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) l2 = std::max({l2, dot(a[j] - a[i], a[j] - a[i]), dot(b[j] - b[i], b[j] - b[i])});
    return std::sqrt(l2);
}

/// @brief Overlaps of the projections along a unit axis: moving b along +axis by `up` (or along -axis
/// by `down`) makes the projections touch. The gap is -min(up, down).
inline void overlaps(const d3 a[4], const d3 b[4], d3 axis, double& up, double& down) {
    double alo = 1e300, ahi = -1e300, blo = 1e300, bhi = -1e300;
    for (int i = 0; i < 4; ++i) {
        const double pa = dot(a[i], axis), pb = dot(b[i], axis);
        alo = std::min(alo, pa);
        ahi = std::max(ahi, pa);
        blo = std::min(blo, pb);
        bhi = std::max(bhi, pb);
    }
    up = ahi - blo;
    down = bhi - alo;
}

/// @brief Least overlap over the 44 axes (negative: the largest gap), in input units. Computed in the
/// frame of a[0], where differences of nearby floats are exact in double.
inline double least_overlap(const d3 a_in[4], const d3 b_in[4]) {
    d3 a[4], b[4];
    for (int i = 0; i < 4; ++i) {
        a[i] = a_in[i] - a_in[0];
        b[i] = b_in[i] - a_in[0];
    }
    double least = 1e300;
    for (const d3& axis : sat_axes(a, b)) {
        double up, down;
        overlaps(a, b, axis, up, down);
        least = std::min(least, std::min(up, down));
    }
    return least;
}

/// @brief Signed margin of a pair relative to its size: max SAT gap (or minus the least overlap)
/// divided by the longest edge.
inline double relative_margin(const d3 a[4], const d3 b[4]) { return -least_overlap(a, b) / longest_edge(a, b); }

// ---------------------------------------------------------------------------------------------
// Generators.

/// @brief Deterministic random source for the generators.
class Random {
public:
    explicit Random(std::uint64_t seed) : engine_(seed) {}
    double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(engine_); }
    int index(int n) { return std::uniform_int_distribution<int>(0, n - 1)(engine_); }
    std::int64_t integer(std::int64_t lo, std::int64_t hi) {
        return std::uniform_int_distribution<std::int64_t>(lo, hi)(engine_);
    }
    d3 in_cube(double half) { return {uniform(-half, half), uniform(-half, half), uniform(-half, half)}; }
    d3 direction() {
        for (;;) {
            const d3 v = in_cube(1.0);
            const double l2 = dot(v, v);
            if (l2 > 1e-4 && l2 <= 1.0) return v * (1.0 / std::sqrt(l2));
        }
    }
    /// One of ±{0, 1e-7, 1e-6, 1e-5, 3e-5, 1e-4, 1e-3, 1e-2}: relative offsets around touching.
    double perturbation() {
        constexpr double levels[] = {0.0, 1e-7, 1e-6, 1e-5, 3e-5, 1e-4, 1e-3, 1e-2};
        const double level = levels[index(8)];
        return index(2) ? level : -level;
    }

private:
    std::mt19937_64 engine_;
};

/// @brief Random proper rotation applied to local geometry.
struct Rotation {
    d3 r[3];
    explicit Rotation(Random& rng) {
        const d3 x = rng.direction();
        d3 y = rng.direction();
        y = normalized(y - x * dot(x, y));
        r[0] = x;
        r[1] = y;
        r[2] = cross(x, y);
    }
    d3 operator()(d3 v) const { return r[0] * v.x + r[1] * v.y + r[2] * v.z; }
};

/// @brief Outward unit normal of face k (opposite vertex k) of a non-degenerate tet.
inline d3 outward_normal(const d3 v[4], int k) {
    const d3 p0 = v[(k + 1) & 3], p1 = v[(k + 2) & 3], p2 = v[(k + 3) & 3];
    d3 n = normalized(cross(p1 - p0, p2 - p0));
    if (dot(n, v[k] - p0) > 0) n = n * -1.0;
    return n;
}

/// @brief A random tet around `center` with edges about `size`, not too flat.
inline void random_tet(Random& rng, d3 center, double size, d3 out[4]) {
    for (;;) {
        for (int i = 0; i < 4; ++i) out[i] = center + rng.in_cube(0.5 * size);
        const double volume = std::fabs(dot(out[1] - out[0], cross(out[2] - out[0], out[3] - out[0])));
        if (volume > 1e-3 * size * size * size) return;
    }
}

/// @brief The offset at which translated copy b = a + lambda * dir first touches a (double SAT on the
/// difference body: its faces are a's face normals and cross products of two of a's edges).
inline double touching_translation(const d3 a[4], d3 dir) {
    const std::vector<d3> axes = sat_axes(a, a);
    double lambda = 1e300;
    for (const d3& n : axes) {
        const double along = dot(dir, n);
        if (std::fabs(along) < 1e-12) continue;
        double lo = 1e300, hi = -1e300;
        for (int i = 0; i < 4; ++i) {
            lo = std::min(lo, dot(a[i], n));
            hi = std::max(hi, dot(a[i], n));
        }
        lambda = std::min(lambda, (hi - lo) / std::fabs(along));
    }
    return lambda;
}

/// @brief Builds one pair of the given kind in double, around the origin, with size s.
inline void build_pair(Random& rng, CaseKind kind, double s, d3 a[4], d3 b[4]) {
    const d3 zero{0, 0, 0};
    random_tet(rng, zero, s, a);
    switch (kind) {
    case CaseKind::random:
        random_tet(rng, rng.in_cube(s), s, b);
        return;
    case CaseKind::shared_vertex: {
        const d3 p = a[rng.index(4)];
        b[0] = p;
        for (int i = 1; i < 4; ++i) b[i] = p + rng.in_cube(s);
        break;
    }
    case CaseKind::shared_edge: {
        const int i = rng.index(4), j = (i + 1 + rng.index(3)) & 3;
        const d3 mid = (a[i] + a[j]) * 0.5;
        b[0] = a[i];
        b[1] = a[j];
        b[2] = mid + rng.in_cube(s);
        b[3] = mid + rng.in_cube(s);
        break;
    }
    case CaseKind::shared_face: {
        const int k = rng.index(4);
        const d3 n = outward_normal(a, k);
        const d3 centroid = (a[(k + 1) & 3] + a[(k + 2) & 3] + a[(k + 3) & 3]) * (1.0 / 3.0);
        for (int i = 0; i < 3; ++i) b[i] = a[(k + 1 + i) & 3];
        // Usually on the outer side (touching), sometimes inside (overlapping).
        b[3] = centroid + rng.in_cube(0.3 * s) + n * (s * (rng.index(4) ? 0.5 : -0.3));
        break;
    }
    case CaseKind::vertex_on_face: {
        const int k = rng.index(4);
        const d3 n = outward_normal(a, k);
        double w[3] = {rng.uniform(0.05, 1), rng.uniform(0.05, 1), rng.uniform(0.05, 1)};
        const double sum = w[0] + w[1] + w[2];
        const d3 x = (a[(k + 1) & 3] * w[0] + a[(k + 2) & 3] * w[1] + a[(k + 3) & 3] * w[2]) * (1.0 / sum);
        const d3 apex = x + n * (rng.perturbation() * s);
        const d3 t = normalized(cross(n, rng.direction())), u = cross(n, t);
        b[0] = apex;
        for (int i = 1; i < 4; ++i) {
            const double angle = 2.0943951 * i + rng.uniform(-0.3, 0.3);
            b[i] = apex + n * (s * rng.uniform(0.3, 1.0)) + (t * std::cos(angle) + u * std::sin(angle)) * (0.6 * s);
        }
        break;
    }
    case CaseKind::edge_on_edge: {
        // A plane through an edge of a, with a's body behind it (normal inside the edge's normal cone);
        // b's edge crosses a's edge in that plane and b's body lies in front.
        const int i = rng.index(4), j = (i + 1 + rng.index(3)) & 3;
        int faces[2], f = 0;
        for (int k = 0; k < 4; ++k)
            if (k != i && k != j) faces[f++] = k;
        const double mix = rng.uniform(0.05, 0.95);
        const d3 n = normalized(outward_normal(a, faces[0]) * mix + outward_normal(a, faces[1]) * (1 - mix));
        const d3 e = normalized(a[j] - a[i]);
        const d3 side = cross(n, e);
        const double angle = rng.uniform(0.2, 2.9);
        const d3 d = e * std::cos(angle) + side * std::sin(angle);
        const d3 x = a[i] + (a[j] - a[i]) * rng.uniform(0.1, 0.9) + n * (rng.perturbation() * s);
        b[0] = x - d * (s * rng.uniform(0.2, 0.8));
        b[1] = x + d * (s * rng.uniform(0.2, 0.8));
        b[2] = x + n * (s * rng.uniform(0.3, 1.0)) + side * (s * rng.uniform(-0.5, 0.5));
        b[3] = x + n * (s * rng.uniform(0.3, 1.0)) + e * (s * rng.uniform(-0.5, 0.5));
        break;
    }
    case CaseKind::translated_copy: {
        const d3 dir = rng.direction();
        const double lambda = rng.index(3) ? touching_translation(a, dir) * (1 + rng.perturbation())
                                           : rng.uniform(0.0, 1.5) * s;
        for (int i = 0; i < 4; ++i) b[i] = a[i] + dir * lambda;
        break;
    }
    case CaseKind::sliver: {
        // Square corners with alternating heights h: a nearly flat tet (dihedral angles near 0 and pi).
        const double h = s * (rng.index(2) ? 1e-2 : (rng.index(2) ? 1e-3 : 1e-4));
        const Rotation rotate(rng);
        const d3 corners[4] = {{0.5 * s, 0, h}, {-0.5 * s, 0, h}, {0, 0.5 * s, -h}, {0, -0.5 * s, -h}};
        for (int q = 0; q < 4; ++q) a[q] = rotate(corners[q]);
        if (rng.index(2)) {
            random_tet(rng, rng.in_cube(0.7 * s), s, b);
        } else {
            const Rotation rotate_b(rng);
            const d3 shift = rng.in_cube(0.7 * s);
            for (int q = 0; q < 4; ++q) b[q] = rotate_b(corners[q]) + shift;
        }
        return;
    }
    case CaseKind::face_on_face: {
        // Three vertices of b in the plane of a face of a (moved along its normal), covering part of
        // the face and often reaching past it; the fourth outside.
        const int k = rng.index(4);
        const d3 n = outward_normal(a, k);
        const d3 p = a[(k + 1) & 3], q = a[(k + 2) & 3], r = a[(k + 3) & 3];
        const d3 lift = n * (rng.perturbation() * s);
        for (int i = 0; i < 3; ++i) b[i] = p + (q - p) * rng.uniform(-0.3, 1.0) + (r - p) * rng.uniform(-0.3, 1.0) + lift;
        b[3] = (b[0] + b[1] + b[2]) * (1.0 / 3.0) + n * (s * rng.uniform(0.3, 1.0));
        break;
    }
    case CaseKind::needle: {
        // a: length s along a random axis, width w; b: a random tet or a second needle crossing near a's.
        const double w = s * (rng.index(2) ? 1e-2 : (rng.index(2) ? 1e-3 : 1e-4));
        const Rotation rotate(rng);
        const d3 corners[4] = {{-0.5 * s, 0, 0}, {0.5 * s, 0, 0}, {0, w, 0.3 * w}, {0.1 * s, -0.4 * w, w}};
        for (int q = 0; q < 4; ++q) a[q] = rotate(corners[q]);
        if (rng.index(2)) {
            random_tet(rng, rng.in_cube(0.6 * s), s, b);
        } else {
            const Rotation rotate_b(rng);
            const d3 shift = a[0] + (a[1] - a[0]) * rng.uniform(0.1, 0.9) + rng.in_cube(2 * w);
            for (int q = 0; q < 4; ++q) b[q] = rotate_b(corners[q]) + shift;
        }
        return;
    }
    default: // the lattice kinds are built by build_lattice_pair
        return;
    }
    // Shuffle b's vertices: the tests must not depend on vertex order or orientation.
    std::array<int, 4> order{0, 1, 2, 3};
    for (int q = 3; q > 0; --q) std::swap(order[q], order[rng.index(q + 1)]);
    d3 shuffled[4];
    for (int q = 0; q < 4; ++q) shuffled[q] = b[order[q]];
    std::copy(shuffled, shuffled + 4, b);
}

// ---------------------------------------------------------------------------------------------
// Lattice pairs: integer coordinates with exact contacts, realised as integer * 2^k, which floats hold
// exactly while the integers stay below 2^24.

struct i3 {
    std::int64_t x, y, z;
};
__extension__ typedef __int128 i128; // dot products of lattice vectors reach 2^64
inline i3 operator+(i3 a, i3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline i3 operator-(i3 a, i3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline i3 operator*(i3 a, std::int64_t k) { return {a.x * k, a.y * k, a.z * k}; }
inline i3 operator/(i3 a, std::int64_t k) { return {a.x / k, a.y / k, a.z / k}; } // exact where used
inline i128 dot(i3 a, i3 b) { return i128{a.x} * b.x + i128{a.y} * b.y + i128{a.z} * b.z; }
inline i3 cross(i3 a, i3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline bool is_zero(i3 a) { return a.x == 0 && a.y == 0 && a.z == 0; }

inline i3 lattice_point(Random& rng, std::int64_t r) {
    return {rng.integer(-r, r), rng.integer(-r, r), rng.integer(-r, r)};
}

/// @brief A tet with vertices that are multiples of 8 in [-r, r]^3 (so that eighths of its edges are
/// lattice vectors), not too flat. With r <= 2^20, cross products stay below 2^45 and dot products
/// (128 bits) exact.
inline void lattice_tet(Random& rng, std::int64_t r, i3 out[4]) {
    for (;;) {
        for (int i = 0; i < 4; ++i) out[i] = lattice_point(rng, r / 8) * 8;
        const i128 volume = dot(out[1] - out[0], cross(out[2] - out[0], out[3] - out[0]));
        if (volume > i128{r} * r * r / 64 || volume < -(i128{r} * r * r / 64)) return;
    }
}

/// @brief Outward normal (not normalised) of face k of a lattice tet.
inline i3 outward_normal(const i3 t[4], int k) {
    const i3 p = t[(k + 1) & 3], n = cross(t[(k + 2) & 3] - p, t[(k + 3) & 3] - p);
    return dot(n, t[k] - p) > 0 ? n * -1 : n;
}

/// @brief A lattice vector in [-r, r]^3 strictly on the positive side of n.
inline i3 outward_vector(Random& rng, i3 n, std::int64_t r) {
    for (;;) {
        const i3 w = lattice_point(rng, r);
        if (dot(n, w) > 0) return w;
    }
}

/// @brief One lattice unit along the coordinate where n is largest, toward +n; scaled by -1, 0 or 1 at
/// random (half the time 0): keeps the contact, or moves the second tet out of or into the first.
inline i3 unit_step(Random& rng, i3 n) {
    const std::int64_t ax = n.x < 0 ? -n.x : n.x, ay = n.y < 0 ? -n.y : n.y, az = n.z < 0 ? -n.z : n.z;
    i3 step{0, 0, 0};
    if (ax >= ay && ax >= az) step.x = n.x > 0 ? 1 : -1;
    else if (ay >= az) step.y = n.y > 0 ? 1 : -1;
    else step.z = n.z > 0 ? 1 : -1;
    const int choice = rng.index(4);
    return choice < 2 ? i3{0, 0, 0} : step * (choice == 2 ? 1 : -1);
}

/// @brief Builds one lattice pair of the given kind in [-2r, 2r]^3 (r a multiple of 64).
inline void build_lattice_pair(Random& rng, CaseKind kind, std::int64_t r, i3 a[4], i3 b[4]) {
    lattice_tet(rng, r, a);
    i3 shift{0, 0, 0};
    switch (kind) {
    case CaseKind::lattice_vertex_on_face: {
        const int k = rng.index(4);
        const i3 n = outward_normal(a, k), p = a[(k + 1) & 3], q = a[(k + 2) & 3], s = a[(k + 3) & 3];
        const std::int64_t i = 1 + rng.index(6), j = 1 + rng.index(7 - static_cast<int>(i));
        b[0] = p + ((q - p) * i + (s - p) * j) / 8; // strictly inside the face
        for (int m = 1; m < 4; ++m) b[m] = b[0] + outward_vector(rng, n, r);
        shift = unit_step(rng, n);
        break;
    }
    case CaseKind::lattice_edge_on_edge: {
        // The plane through a's edge (i, j) and a direction d supports a when a's other two vertices
        // lie strictly on one side; b's edge crosses a's edge inside it, b's body on the other side.
        const int i = rng.index(4), j = (i + 1 + rng.index(3)) & 3;
        int others[2], o = 0;
        for (int v = 0; v < 4; ++v)
            if (v != i && v != j) others[o++] = v;
        const i3 e = a[j] - a[i];
        i3 d, n;
        for (;;) {
            d = lattice_point(rng, 32);
            n = cross(e, d);
            const i128 s0 = dot(n, a[others[0]] - a[i]), s1 = dot(n, a[others[1]] - a[i]);
            if (s0 == 0 || s1 == 0 || (s0 > 0) != (s1 > 0)) continue;
            if (s0 > 0) n = n * -1;
            break;
        }
        const i3 m = a[i] + e * (1 + rng.index(7)) / 8;
        b[0] = m - d * rng.integer(r / 64, r / 16);
        b[1] = m + d * rng.integer(r / 64, r / 16);
        b[2] = m + outward_vector(rng, n, r);
        b[3] = m + outward_vector(rng, n, r);
        shift = unit_step(rng, n);
        break;
    }
    case CaseKind::lattice_face_on_face: {
        const int k = rng.index(4);
        const i3 n = outward_normal(a, k), p = a[(k + 1) & 3], q = a[(k + 2) & 3], s = a[(k + 3) & 3];
        do {
            for (int m = 0; m < 3; ++m) b[m] = p + ((q - p) * rng.integer(-4, 10) + (s - p) * rng.integer(-4, 10)) / 8;
        } while (is_zero(cross(b[1] - b[0], b[2] - b[0])));
        b[3] = b[0] + outward_vector(rng, n, r);
        shift = unit_step(rng, n);
        break;
    }
    case CaseKind::lattice_translated_copy: {
        // Moved by a - a' for two vertices: the difference body's vertex, so the copies touch at one point.
        const int i = rng.index(4), j = (i + 1 + rng.index(3)) & 3;
        for (int m = 0; m < 4; ++m) b[m] = a[m] + (a[j] - a[i]);
        shift = unit_step(rng, lattice_point(rng, 1));
        break;
    }
    default: { // lattice_random
        lattice_tet(rng, r, b);
        const i3 center = lattice_point(rng, r);
        for (int m = 0; m < 4; ++m) b[m] = b[m] / 2 + center;
        break;
    }
    }
    std::array<int, 4> order{0, 1, 2, 3};
    for (int q = 3; q > 0; --q) std::swap(order[q], order[rng.index(q + 1)]);
    i3 shuffled[4];
    for (int q = 0; q < 4; ++q) shuffled[q] = b[order[q]] + shift;
    std::copy(shuffled, shuffled + 4, b);
}

/// @brief Where a lattice pair goes: coordinates (lattice point + offset) * 2^exponent, with the
/// lattice as fine as the offset allows while every coordinate stays below 2^24 units.
struct LatticeFrame {
    std::int64_t r;  ///< half extent of the first tet in units
    int exponent;    ///< one unit is 2^exponent
    i3 offset;       ///< in units
};

/// @brief A frame for tets of size about s at distance `offset` from the origin along `direction`:
/// 2^20 units per size (so that products of three coordinates exceed double's 53 bits), coarser when
/// the offset needs it (down to 2^6 units per size).
inline LatticeFrame lattice_frame(double s, double offset, d3 direction) {
    int bits = 20, exponent = static_cast<int>(std::ceil(std::log2(s))) - bits;
    const double limit = 0x1p24 - 0x1p22; // room for the pair itself (|lattice| < 4r <= 2^22)
    while (bits > 6 && std::ldexp(offset, -exponent) > limit) {
        --bits;
        ++exponent;
    }
    const double units = std::min(std::ldexp(offset, -exponent), limit);
    const d3 o = direction * units;
    return LatticeFrame{std::int64_t{1} << bits, exponent,
                        i3{std::llround(o.x), std::llround(o.y), std::llround(o.z)}};
}

inline vec3 realise(i3 p, const LatticeFrame& frame) {
    const i3 q = p + frame.offset;
    return vec3{static_cast<float>(std::ldexp(static_cast<double>(q.x), frame.exponent)),
                static_cast<float>(std::ldexp(static_cast<double>(q.y), frame.exponent)),
                static_cast<float>(std::ldexp(static_cast<double>(q.z), frame.exponent))};
}

/// @brief Generates `per_combination` pairs for every kind, size and offset, with ground truth and
/// margin. Degenerate float tets (possible after rounding far from the origin) are redrawn.
inline std::vector<Case> generate_cases(std::uint64_t seed, int per_combination) {
    Random rng(seed);
    std::vector<Case> cases;
    for (CaseKind kind : k_case_kinds)
        for (double s : k_sizes)
            for (double relative_offset : k_relative_offsets) {
                const double offset = std::min(relative_offset * s, k_max_offset);
                for (int n = 0; n < per_combination; ++n) {
                    for (int attempt = 0; attempt < 100; ++attempt) {
                        Case c{};
                        const d3 direction = rng.direction();
                        if (is_lattice(kind)) {
                            const LatticeFrame frame = lattice_frame(s, offset, direction);
                            i3 a[4], b[4];
                            build_lattice_pair(rng, kind, frame.r, a, b);
                            for (int i = 0; i < 4; ++i) {
                                c.a[i] = realise(a[i], frame);
                                c.b[i] = realise(b[i], frame);
                            }
                        } else {
                            d3 a[4], b[4];
                            build_pair(rng, kind, s, a, b);
                            for (int i = 0; i < 4; ++i) {
                                c.a[i] = to_vec3(a[i] + direction * offset);
                                c.b[i] = to_vec3(b[i] + direction * offset);
                            }
                        }
                        d3 ad[4], bd[4];
                        widen(c.a, ad);
                        widen(c.b, bd);
                        if (degenerate(ad) || degenerate(bd)) continue;
                        c.kind = kind;
                        c.size = s;
                        c.truth = cgal_intersect(ad, bd);
                        c.margin = relative_margin(ad, bd);
                        cases.push_back(c);
                        break;
                    }
                }
            }
    return cases;
}

// ---------------------------------------------------------------------------------------------
// Zero-volume pairs (what --allow-degenerate lets in): points, segments and flat tets, mostly in one
// plane of a lattice, judged by cgal_hulls_meet.

/// @brief A pair in which at least one tet has zero volume.
struct DegenerateCase {
    vec3 a[4];
    vec3 b[4];
    int dim_a, dim_b; ///< dimension of each tet's hull: 0 point, 1 segment, 2 flat, 3 solid
    bool lattice;     ///< exactly representable lattice coordinates (else random floats on a plane z = c)
    bool truth;
};

/// @brief Dimension of the hull of 4 float points (exact, from CGAL's predicates).
inline int hull_dimension(const vec3 t[4]) {
    d3 d[4];
    widen(t, d);
    const Point p[4] = {to_point(d[0]), to_point(d[1]), to_point(d[2]), to_point(d[3])};
    if (!degenerate(d)) return 3;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
            for (int k = j + 1; k < 4; ++k)
                if (!CGAL::collinear(p[i], p[j], p[k])) return 2;
    for (int i = 1; i < 4; ++i)
        if (p[i] != p[0]) return 1;
    return 0;
}

/// @brief Four points of a plane lattice o + i u + j v (small i, j) spanning `dim` dimensions; for
/// dim 3 the fourth leaves the plane along w. `line` is the direction (in (i, j)) used for dim 1.
inline void lattice_flat(Random& rng, int dim, i3 u, i3 v, i3 w, const std::int64_t line[2], i3 out[4]) {
    const auto at = [&](std::int64_t i, std::int64_t j) { return u * i + v * j; };
    const std::int64_t i0 = rng.integer(-3, 3), j0 = rng.integer(-3, 3);
    for (int m = 0; m < 4; ++m) {
        if (dim == 0) {
            out[m] = at(i0, j0);
        } else if (dim == 1) {
            const std::int64_t t = rng.integer(-2, 2);
            out[m] = at(i0 + t * line[0], j0 + t * line[1]);
        } else {
            out[m] = at(rng.integer(-3, 3), rng.integer(-3, 3));
        }
    }
    if (dim == 3) out[3] = out[3] + w * (rng.index(2) ? 1 : -1);
}

/// @brief `count` degenerate pairs: half on plane lattices (exactly coplanar or collinear, shared
/// planes and lines, parallel ones, mixed dimensions, exact contacts), half random floats on a plane
/// z = c (flat against flat or against a solid tet), at sizes 1e-6 to 1e6.
inline std::vector<DegenerateCase> generate_degenerate_cases(std::uint64_t seed, int count) {
    Random rng(seed);
    std::vector<DegenerateCase> cases;
    while (static_cast<int>(cases.size()) < count) {
        DegenerateCase c{};
        const double s = k_sizes[rng.index(k_size_count)];
        c.lattice = cases.size() % 2 == 0;
        if (c.lattice) {
            // Plane vectors of 2..19 bits: small ones give many exact contacts, large ones products
            // that double arithmetic rounds.
            const std::int64_t r = std::int64_t{1} << (2 + rng.index(18));
            i3 u, v, w;
            do {
                u = lattice_point(rng, r);
                v = lattice_point(rng, r);
                w = lattice_point(rng, r);
            } while (dot(cross(u, v), w) == 0);
            std::int64_t line_a[2] = {rng.integer(-2, 2), rng.integer(-2, 2)}, line_b[2] = {line_a[0], line_a[1]};
            if (line_a[0] == 0 && line_a[1] == 0) line_a[0] = line_b[0] = 1;
            if (rng.index(2)) line_b[0] = rng.integer(-2, 2), line_b[1] = 1;
            const int dim_a = rng.index(3), dim_b = rng.index(4); // a always degenerate
            i3 a[4], b[4];
            lattice_flat(rng, dim_a, u, v, w, line_a, a);
            lattice_flat(rng, dim_b, u, v, w, line_b, b);
            const int move = rng.index(4); // keep, into a parallel plane, or by one unit
            for (int m = 0; m < 4; ++m) b[m] = b[m] + (move == 1 ? w : (move == 2 ? unit_step(rng, w) : i3{0, 0, 0}));
            const int exponent = static_cast<int>(std::ceil(std::log2(s))) - (4 + static_cast<int>(std::log2(static_cast<double>(r))));
            const LatticeFrame frame{r, exponent, i3{0, 0, 0}};
            for (int m = 0; m < 4; ++m) {
                c.a[m] = realise(a[m], frame);
                c.b[m] = realise(b[m], frame);
            }
            // Half the time, a flat tet's first vertex (the exact test's origin) is put 2^-30 to 2^-60 times
            // closer to the lattice's origin, still in the plane: differences to it need more bits than a
            // double has, which exercises the error bounds of the plane test.
            const auto near_origin = [&](vec3& vertex) {
                const LatticeFrame tiny{r, exponent - 30 - rng.index(31), i3{0, 0, 0}};
                vertex = realise(u * rng.integer(-3, 3) + v * rng.integer(-3, 3), tiny);
            };
            if (dim_a == 2 && rng.index(2)) near_origin(c.a[0]);
            if (dim_b == 2 && move != 1 && rng.index(2)) near_origin(c.b[0]);
        } else {
            const float z = static_cast<float>(rng.uniform(-1.0, 1.0) * s);
            for (int m = 0; m < 4; ++m) {
                c.a[m] = vec3{static_cast<float>(rng.uniform(-0.5, 0.5) * s), static_cast<float>(rng.uniform(-0.5, 0.5) * s), z};
                c.b[m] = vec3{static_cast<float>(rng.uniform(0.0, 1.0) * s), static_cast<float>(rng.uniform(-0.5, 0.5) * s),
                              rng.index(2) ? z : static_cast<float>(z + rng.uniform(-0.5, 0.5) * s)};
            }
        }
        c.dim_a = hull_dimension(c.a);
        c.dim_b = hull_dimension(c.b);
        if (c.dim_a == 3 && c.dim_b == 3) continue;
        d3 ad[4], bd[4];
        widen(c.a, ad);
        widen(c.b, bd);
        c.truth = cgal_hulls_meet(ad, bd);
        cases.push_back(c);
    }
    return cases;
}

} // namespace kdet::cgal_check
