#pragma once
/// @file narrow_cases.hpp
/// @brief Tetrahedron pairs for validating the narrow phase against CGAL: deterministic generators of
/// hard cases, the exact oracle, and double-precision SAT quantities (margin, least overlap).
///
/// Shared by the CGAL tests and the narrow-phase report. Everything here is test code: CGAL is never a
/// dependency of the kdet library.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
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
};
constexpr CaseKind k_case_kinds[] = {CaseKind::random,         CaseKind::shared_vertex, CaseKind::shared_edge,
                                     CaseKind::shared_face,    CaseKind::vertex_on_face, CaseKind::edge_on_edge,
                                     CaseKind::translated_copy, CaseKind::sliver};
constexpr int k_case_kind_count = 8;

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
    }
    return "?";
}

/// @brief Tet sizes and offsets from the origin (relative to the size, capped at 1e6 absolute).
constexpr double k_sizes[] = {1.0, 1e-3, 1e-6};
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
    }
    // Shuffle b's vertices: the tests must not depend on vertex order or orientation.
    std::array<int, 4> order{0, 1, 2, 3};
    for (int q = 3; q > 0; --q) std::swap(order[q], order[rng.index(q + 1)]);
    d3 shuffled[4];
    for (int q = 0; q < 4; ++q) shuffled[q] = b[order[q]];
    std::copy(shuffled, shuffled + 4, b);
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
                        d3 a[4], b[4];
                        build_pair(rng, kind, s, a, b);
                        const d3 shift = rng.direction() * offset;
                        Case c{};
                        for (int i = 0; i < 4; ++i) {
                            c.a[i] = to_vec3(a[i] + shift);
                            c.b[i] = to_vec3(b[i] + shift);
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

} // namespace kdet::cgal_check
