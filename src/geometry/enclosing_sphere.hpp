#pragma once
/// @file enclosing_sphere.hpp
/// @brief Diameter of the minimum enclosing sphere of a tetrahedron: the size that picks its grid layer.
///
/// The minimum sphere is one of 11 candidates: the 6 edge spheres, the 4 face circumspheres and the
/// tet's circumsphere. We keep the smallest candidate that contains all four vertices, then set the
/// radius to the farthest vertex so the result always encloses the tet, whatever the rounding.

#include "geometry/vec3.hpp"

#include <cfloat>
#include <cmath>

namespace kdet {

namespace sphere_detail {

/// @brief local_frame's answer for a tet whose coordinate differences overflow float.
constexpr int sphere_unbounded = 1000;

struct Candidate {
    vec3 center;
    float radius_squared;
    bool valid;
};

KDET_HD inline float farthest_squared(const vec3 p[4], vec3 center) {
    float r2 = 0.0f;
    for (int k = 0; k < 4; ++k) r2 = max_f(r2, length_squared(p[k] - center));
    return r2;
}

KDET_HD inline void consider(const vec3 p[4], vec3 center, float radius_squared, float scale_squared, Candidate& best) {
    // Relative slack: a candidate that encloses the points up to rounding counts as enclosing.
    const float slack = 1e-5f * scale_squared;
    if (!(radius_squared < best.radius_squared)) return;
    for (int k = 0; k < 4; ++k)
        if (length_squared(p[k] - center) > radius_squared + slack) return;
    best = Candidate{center, radius_squared, true};
}

/// @brief The points in a frame whose origin is the first of them: the formulas stay accurate far from
/// the origin. A tet whose largest coordinate difference lies outside [2^-16, 2^16] is also scaled by
/// the power of two that brings it into [1/2, 1), so that no product of the formulas (up to the fifth
/// power of a length) overflows or underflows, however large or small the tet; inside that range the
/// scaling would change no bit of the result (it is exact), so it is skipped. Returns the exponent that
/// undoes the scaling (0 when unscaled), or sphere_unbounded when a coordinate difference overflows
/// (or is not finite).
KDET_HD inline int local_frame(const vec3 v[4], vec3 p[4]) {
    p[0] = make_vec3(0.0f, 0.0f, 0.0f);
    float largest = 0.0f;
    for (int k = 1; k < 4; ++k) {
        p[k] = v[k] - v[0];
        largest = max_f(largest, max_abs(p[k]));
    }
    if (largest >= 0x1p-16f && largest <= 0x1p16f) return 0;
    if (!(largest <= FLT_MAX)) return sphere_unbounded;
    const int exponent = frexp_exponent(largest);
    for (int k = 1; k < 4; ++k) p[k] = times_power_of_two(p[k], -exponent);
    return exponent;
}

/// @brief A length computed in local_frame's frame, in the caller's: at most the largest float.
KDET_HD inline float unscaled_length(float length, int exponent) {
    return exponent == 0 ? length : min_f(times_power_of_two(length, exponent), FLT_MAX);
}

KDET_HD inline float longest_edge_squared(const vec3 p[4]) {
    float longest = 0.0f;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) longest = max_f(longest, length_squared(p[i] - p[j]));
    return longest;
}

} // namespace sphere_detail

/// @brief Diameter of the smallest sphere enclosing the four points (never smaller than the true one
/// by more than rounding, never larger than the longest-edge bound sqrt(3) * true diameter), or the
/// largest float where no float holds it: the grid needs sizes only monotone, and finite (an infinite
/// smallest size would read as no tet at all).
KDET_HD inline float enclosing_sphere_diameter(const vec3 v[4]) {
    using sphere_detail::consider;
    vec3 p[4];
    const int exponent = sphere_detail::local_frame(v, p);
    if (exponent == sphere_detail::sphere_unbounded) return FLT_MAX;
    const float scale_squared = sphere_detail::longest_edge_squared(p);

    sphere_detail::Candidate best{make_vec3(0.0f, 0.0f, 0.0f), 3.4e38f, false};
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
            consider(p, (p[i] + p[j]) * 0.5f, 0.25f * length_squared(p[i] - p[j]), scale_squared, best);

    const int faces[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
    for (const auto& f : faces) {
        const vec3 a = p[f[0]];
        const vec3 u = p[f[1]] - a;
        const vec3 w = p[f[2]] - a;
        const vec3 n = cross(u, w);
        const float n2 = length_squared(n);
        if (n2 <= 0.0f) continue;
        const vec3 offset = cross(length_squared(u) * w - length_squared(w) * u, n) / (2.0f * n2);
        consider(p, a + offset, length_squared(offset), scale_squared, best);
    }

    const vec3 u = p[1], w = p[2], t = p[3];
    const float det = dot(u, cross(w, t));
    if (det != 0.0f) {
        const vec3 offset =
            (length_squared(u) * cross(w, t) + length_squared(w) * cross(t, u) + length_squared(t) * cross(u, w)) /
            (2.0f * det);
        consider(p, offset, length_squared(offset), scale_squared, best);
    }

    vec3 center = best.center;
    if (!best.valid) center = (p[0] + p[1] + p[2] + p[3]) * 0.25f; // only for non-finite input
    const float radius = sqrtf(sphere_detail::farthest_squared(p, center));
    return sphere_detail::unscaled_length(2.0f * radius * (1.0f + 4.0f * 1.1920929e-7f), exponent);
}

/// @brief The longest edge of the tet, in the frame enclosing_sphere_diameter computes in (at most the
/// largest float, as that).
KDET_HD inline float longest_edge(const vec3 v[4]) {
    vec3 p[4];
    const int exponent = sphere_detail::local_frame(v, p);
    if (exponent == sphere_detail::sphere_unbounded) return FLT_MAX;
    return sphere_detail::unscaled_length(sqrtf(sphere_detail::longest_edge_squared(p)), exponent);
}

/// @brief Bounds on enclosing_sphere_diameter from the tet's longest edge D. The sphere holds both ends
/// of every edge, so its diameter is at least D; by Jung's theorem a set of diameter D in space lies in
/// a sphere of diameter sqrt(3/2) D (the regular tet needs all of it). Each bound is widened by a
/// thousandth, far beyond the rounding of either computation.
struct SphereDiameterBounds {
    float lower, upper;
};
KDET_HD inline SphereDiameterBounds sphere_diameter_bounds(float longest_edge) {
    return SphereDiameterBounds{longest_edge * 0.999f, longest_edge * 1.2260f};
}

} // namespace kdet
