// Minimum enclosing sphere against an independent iterative solver, ordered-float atomics, and exact
// scaling by powers of two.

#include "exec/atomic.hpp"
#include "geometry/enclosing_sphere.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace kdet {
namespace {

using Point = std::array<double, 3>;

double distance(const Point& a, const Point& b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/// Badoiu-Clarkson: step toward the farthest point with shrinking steps; converges to the minimum
/// enclosing ball, independently of the 11-candidate construction.
double iterative_diameter(const std::array<Point, 4>& p) {
    Point c = p[0];
    for (int k = 1; k <= 200000; ++k) {
        int far = 0;
        for (int i = 1; i < 4; ++i)
            if (distance(c, p[i]) > distance(c, p[far])) far = i;
        for (int a = 0; a < 3; ++a) c[a] += (p[far][a] - c[a]) / (k + 1);
    }
    double r = 0;
    for (const Point& q : p) r = std::max(r, distance(c, q));
    return 2 * r;
}

double diameter_of(const std::array<Point, 4>& p) {
    vec3 v[4];
    for (int i = 0; i < 4; ++i)
        v[i] = vec3{static_cast<float>(p[i][0]), static_cast<float>(p[i][1]), static_cast<float>(p[i][2])};
    return enclosing_sphere_diameter(v);
}

TEST(EnclosingSphere, KnownShapes) {
    // Regular tet with edge 1: circumradius sqrt(6)/4.
    const std::array<Point, 4> regular = {Point{0, 0, 0}, Point{1, 0, 0}, Point{0.5, std::sqrt(3.0) / 2, 0},
                                          Point{0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3.0)}};
    EXPECT_NEAR(diameter_of(regular), std::sqrt(6.0) / 2, 1e-5);
    // A needle: the longest edge decides.
    const std::array<Point, 4> needle = {Point{0, 0, 0}, Point{10, 0, 0}, Point{5, 0.1, 0}, Point{5, 0, 0.1}};
    EXPECT_NEAR(diameter_of(needle), 10.0, 1e-4);
    // Right-angle corner of a unit cube: the big face's circumcircle (hypotenuse face) is not minimal,
    // the circumsphere is: diameter sqrt(3).
    const std::array<Point, 4> corner = {Point{0, 0, 0}, Point{1, 0, 0}, Point{0, 1, 0}, Point{0, 0, 1}};
    EXPECT_NEAR(diameter_of(corner), 2.0 * std::sqrt(2.0 / 3.0) , 1e-5);
}

TEST(EnclosingSphere, MatchesAnIterativeSolverAndEnclosesEveryVertex) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (int i = 0; i < 300; ++i) {
        const double scale = std::pow(10.0, 3 * unit(rng));
        const Point offset = {1000 * unit(rng), 1000 * unit(rng), 1000 * unit(rng)};
        std::array<Point, 4> p;
        for (auto& q : p)
            for (int a = 0; a < 3; ++a) // float-rounded, as the library stores them; every 5th tet is flat-ish
                q[a] = static_cast<float>(offset[a] + scale * unit(rng) * (a == 2 && i % 5 == 0 ? 0.01 : 1.0));
        const double d = diameter_of(p);
        const double reference = iterative_diameter(p);
        EXPECT_NEAR(d, reference, 2e-3 * reference) << "tet " << i;
        double longest = 0;
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b) longest = std::max(longest, distance(p[a], p[b]));
        EXPECT_GE(d, longest * (1 - 1e-6));
    }
}

TEST(EnclosingSphere, LiesWithinTheBoundsOfTheLongestEdge) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    const float a = std::sqrt(0.5f);
    const vec3 regular[4] = {{1, 0, -a}, {-1, 0, -a}, {0, 1, a}, {0, -1, a}}; // edge 2
    for (int i = 0; i < 20000; ++i) {
        // Random tets at scales over six decades, far from the origin; every 4th flat, every 4th a needle;
        // every 50th the regular tet at the origin, which needs the whole of Jung's bound.
        const bool is_regular = i % 50 == 0;
        const float scale = std::pow(10.0f, 3.0f * unit(rng));
        const vec3 offset = is_regular ? vec3{0, 0, 0} : vec3{100.0f * unit(rng), 100.0f * unit(rng), 100.0f * unit(rng)};
        vec3 v[4];
        for (int k = 0; k < 4; ++k) {
            vec3 q = is_regular ? regular[k] : vec3{unit(rng), unit(rng), unit(rng)};
            if (!is_regular && i % 4 == 1) q.z *= 1e-3f;
            if (!is_regular && i % 4 == 2) q.y *= 1e-3f, q.z *= 1e-3f;
            v[k] = offset + q * scale;
        }
        const float d = enclosing_sphere_diameter(v);
        const SphereDiameterBounds bounds = sphere_diameter_bounds(longest_edge(v));
        EXPECT_LE(bounds.lower, d) << "tet " << i;
        EXPECT_GE(bounds.upper, d) << "tet " << i;
        if (is_regular) {
            EXPECT_GT(d, 0.998f * bounds.upper) << "the regular tet fills the bound";
        }
    }
}

TEST(OrderedFloat, PreservesOrderAndRoundTrips) {
    const float values[] = {-3.4e38f, -1.0f, -1e-30f, -0.0f, 0.0f, 1e-30f, 2.5f, 3.4e38f};
    for (std::size_t i = 0; i + 1 < sizeof values / sizeof *values; ++i) {
        EXPECT_LE(float_to_ordered(values[i]), float_to_ordered(values[i + 1]));
        EXPECT_EQ(ordered_to_float(float_to_ordered(values[i])), values[i]);
    }
}

} // namespace

TEST(PowerOfTwo, ScalesAsLdexpfRoundsWhereTheFirstHalfStepIsExact) {
    const float values[] = {0.0f, 1.0f, -1.0f, 0.75f, 1.5f, 3.4641016f, 0.5f + 0x1p-24f, 1.9999999f, 0x1p-60f, 0x1p60f};
    for (const float x : values)
        for (int exponent = -252; exponent <= 252; ++exponent) {
            // The documented range: x * 2^(exponent / 2) a normal float or 0, and finite.
            const float half = std::ldexp(x, exponent / 2);
            if (x != 0.0f && (std::fabs(half) < FLT_MIN || !std::isfinite(half))) continue;
            const float expected = std::ldexp(x, exponent), got = times_power_of_two(x, exponent);
            ASSERT_EQ(std::memcmp(&expected, &got, sizeof got), 0) << x << " * 2^" << exponent << ": " << got;
        }
    for (int exponent = -126; exponent <= 127; ++exponent) ASSERT_EQ(power_of_two(exponent), std::ldexp(1.0f, exponent));
}

TEST(NextFloat, StepsAsNextafterfForEveryKindOfFloat) {
    std::vector<float> values = {0.0f, -0.0f, FLT_TRUE_MIN, -FLT_TRUE_MIN, FLT_MIN, -FLT_MIN, FLT_MAX, -FLT_MAX,
                                 INFINITY, -INFINITY, 1.0f, -1.0f, 0x1p-126f - 0x1p-149f};
    std::mt19937 rng(11);
    for (int i = 0; i < 100000; ++i) {
        const std::uint32_t bits = static_cast<std::uint32_t>(rng());
        float x;
        std::memcpy(&x, &bits, sizeof x);
        values.push_back(x);
    }
    for (const float x : values) {
        const float up = nextafterf(x, INFINITY), down = nextafterf(x, -INFINITY);
        const float got_up = next_float_up(x), got_down = next_float_down(x);
        if (std::isnan(x)) {
            EXPECT_TRUE(std::isnan(got_up) && std::isnan(got_down));
            continue;
        }
        ASSERT_EQ(std::memcmp(&up, &got_up, sizeof up), 0) << x;
        ASSERT_EQ(std::memcmp(&down, &got_down, sizeof down), 0) << x;
    }
}

TEST(PowerOfTwo, FrexpExponentIsFrexpfsForEveryFiniteFloat) {
    // Every binary exponent, normal and subnormal, each with a few mantissas and both signs.
    for (int e = -149; e <= 127; ++e)
        for (const float m : {1.0f, 1.5f, 1.9999999f})
            for (const float sign : {1.0f, -1.0f}) {
                const float x = sign * std::ldexp(m, e);
                if (x == 0.0f || !std::isfinite(x)) continue;
                int expected = 0;
                std::frexp(x, &expected);
                ASSERT_EQ(frexp_exponent(x), expected) << x;
            }
    EXPECT_EQ(frexp_exponent(0.0f), 0);
    EXPECT_EQ(frexp_exponent(FLT_MAX), 128);
    EXPECT_EQ(frexp_exponent(FLT_TRUE_MIN), -148);
}

} // namespace kdet
