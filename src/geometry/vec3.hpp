#pragma once
/// @file vec3.hpp
/// @brief A minimal float 3-vector and box used by all per-element code.

#include <kdet/config.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#if defined(__SSE2__) && !defined(__CUDA_ARCH__)
#include <emmintrin.h>
#endif

/// @brief Keeps a rarely taken function out of its callers (KDET_NOINLINE), with its loops rolled on
/// the GPU (KDET_NO_UNROLL): a kernel holds as many registers per thread as the hungriest function it
/// calls, so a rarely taken or wide step must need no more than the rest (see docs/narrow-phase.md).
#if defined(__CUDACC__)
#define KDET_NOINLINE __noinline__
#else
#define KDET_NOINLINE __attribute__((noinline))
#endif
/// @brief Inlines a small step that a hot loop calls (KDET_ALWAYS_INLINE, in place of `inline`), so
/// that what it computes from the loop's invariants is hoisted out of the loop, where GCC otherwise
/// keeps a call and redoes that setup each time.
#if defined(__CUDACC__)
#define KDET_ALWAYS_INLINE __forceinline__
#else
#define KDET_ALWAYS_INLINE inline __attribute__((always_inline))
#endif
#if defined(__CUDA_ARCH__)
#define KDET_NO_UNROLL _Pragma("unroll 1")
#else
#define KDET_NO_UNROLL
#endif
/// @brief A loop over four lanes (the faces of a tet, say) that GCC should turn into vector
/// instructions: kept a loop on the host, since GCC unrolls a loop of four before its vectoriser sees
/// it and then rarely packs the copies again. Left to the compiler under nvcc (whose front end does not
/// know the pragma; the CPU backend is compiled by the host compiler) and in device code.
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__)
#define KDET_VECTOR_LOOP _Pragma("GCC unroll 1")
#else
#define KDET_VECTOR_LOOP
#endif

namespace kdet {

/// @brief Bit i set for each lane i of `lanes` that is ~0u, every lane being 0 or ~0u: how a vector
/// loop's per-lane verdicts become one mask. On the host one instruction per four lanes (the
/// compiler would otherwise mask each lane with its bit and OR them across the vector).
template <int Lanes>
KDET_HD KDET_ALWAYS_INLINE std::uint32_t lane_bits(const std::uint32_t (&lanes)[Lanes]) {
    static_assert(Lanes % 4 == 0 && Lanes <= 32, "whole groups of four lanes, at most 32");
    std::uint32_t bits = 0;
#if defined(__SSE2__) && !defined(__CUDA_ARCH__)
    for (int i = 0; i < Lanes; i += 4)
        bits |= static_cast<std::uint32_t>(
                    _mm_movemask_ps(_mm_castsi128_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(lanes + i)))))
                << i;
#else
    for (int i = 0; i < Lanes; ++i) bits |= (lanes[i] & 1u) << i;
#endif
    return bits;
}

struct vec3 {
    float x, y, z;
};

/// @brief 2^exponent as a float, built from its bits (exact for -126 <= exponent <= 127).
KDET_HD inline float power_of_two(int exponent) {
    const std::uint32_t bits = static_cast<std::uint32_t>(exponent + 127) << 23;
    float value;
    memcpy(&value, &bits, sizeof value);
    return value;
}

/// @brief The exponent e of a finite x = m 2^e with 1/2 <= |m| < 1 (0 for 0), as frexpf gives it, without
/// a library call: the per-tet and per-pair frames ask for it on every element.
KDET_HD inline int frexp_exponent(float x) {
    std::uint32_t bits;
    memcpy(&bits, &x, sizeof bits);
    const int biased = static_cast<int>((bits >> 23) & 0xffu);
    if (biased != 0) return biased - 126;
    if (x == 0.0f) return 0;
    // Subnormal: made normal by an exact scaling first.
    const float normal = x * power_of_two(64);
    memcpy(&bits, &normal, sizeof bits);
    return static_cast<int>((bits >> 23) & 0xffu) - 126 - 64;
}

/// @brief x * 2^exponent for |exponent| <= 252 without a library call: rounded once, as ldexpf rounds
/// it, wherever x * 2^(exponent / 2) is a normal float or 0 (the first product is then exact).
KDET_HD inline float times_power_of_two(float x, int exponent) {
    const int half = exponent / 2;
    return x * power_of_two(half) * power_of_two(exponent - half);
}

/// @brief nextafterf(x, INFINITY) without a library call (on the CPU nextafterf is one, and boxes grown
/// by a margin round each of their bounds outward with it).
KDET_HD inline float next_float_up(float x) {
    if (!(x < INFINITY)) return x; // +inf and NaN
    if (x == 0.0f) return 1.40129846e-45f; // the smallest subnormal, above both zeros
    std::uint32_t bits;
    memcpy(&bits, &x, sizeof bits);
    bits = x > 0.0f ? bits + 1u : bits - 1u;
    memcpy(&x, &bits, sizeof x);
    return x;
}

/// @brief nextafterf(x, -INFINITY) without a library call.
KDET_HD inline float next_float_down(float x) { return -next_float_up(-x); }

KDET_HD inline vec3 make_vec3(float x, float y, float z) { return vec3{x, y, z}; }
KDET_HD inline vec3 operator+(vec3 a, vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
KDET_HD inline vec3 operator-(vec3 a, vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
KDET_HD inline vec3 operator-(vec3 a) { return {-a.x, -a.y, -a.z}; }
KDET_HD inline vec3 operator*(vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
KDET_HD inline vec3 operator*(float s, vec3 a) { return {a.x * s, a.y * s, a.z * s}; }
KDET_HD inline vec3 operator/(vec3 a, float s) { return {a.x / s, a.y / s, a.z / s}; }
KDET_HD inline float dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
KDET_HD inline vec3 cross(vec3 a, vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
KDET_HD inline float length_squared(vec3 a) { return dot(a, a); }
KDET_HD inline float min_f(float a, float b) { return a < b ? a : b; }
KDET_HD inline float max_f(float a, float b) { return a > b ? a : b; }
KDET_HD inline float max_abs(vec3 a) { return max_f(fabsf(a.x), max_f(fabsf(a.y), fabsf(a.z))); }
/// @brief a * 2^exponent coordinate by coordinate (times_power_of_two).
KDET_HD inline vec3 times_power_of_two(vec3 a, int exponent) {
    return {times_power_of_two(a.x, exponent), times_power_of_two(a.y, exponent), times_power_of_two(a.z, exponent)};
}
KDET_HD inline vec3 min_v(vec3 a, vec3 b) { return {min_f(a.x, b.x), min_f(a.y, b.y), min_f(a.z, b.z)}; }
KDET_HD inline vec3 max_v(vec3 a, vec3 b) { return {max_f(a.x, b.x), max_f(a.y, b.y), max_f(a.z, b.z)}; }
KDET_HD inline float component(vec3 a, int axis) { return axis == 0 ? a.x : (axis == 1 ? a.y : a.z); }

/// @brief Axis-aligned box, closed on both ends.
struct Aabb {
    vec3 lo, hi;
};

KDET_HD inline bool boxes_overlap(const Aabb& a, const Aabb& b) {
    return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y &&
           a.lo.z <= b.hi.z && b.lo.z <= a.hi.z;
}

/// @brief The smallest box holding both (an empty box, lo above hi, leaves the other as it is).
KDET_HD inline Aabb box_union(const Aabb& a, const Aabb& b) { return {min_v(a.lo, b.lo), max_v(a.hi, b.hi)}; }

/// @brief Where both boxes are; lo above hi on some axis when they are apart.
KDET_HD inline Aabb box_intersection(const Aabb& a, const Aabb& b) { return {max_v(a.lo, b.lo), min_v(a.hi, b.hi)}; }

KDET_HD inline bool box_holds(const Aabb& b, vec3 p) {
    // One branch for the six comparisons: most points a search meets are outside the box.
    return (p.x >= b.lo.x) & (p.x <= b.hi.x) & (p.y >= b.lo.y) & (p.y <= b.hi.y) & (p.z >= b.lo.z) & (p.z <= b.hi.z);
}

KDET_HD inline Aabb tet_box(const vec3 v[4]) {
    Aabb b{min_v(min_v(v[0], v[1]), min_v(v[2], v[3])), max_v(max_v(v[0], v[1]), max_v(v[2], v[3]))};
    return b;
}

} // namespace kdet
