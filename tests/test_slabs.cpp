// The slabs pre-test (src/geometry/slabs.hpp): a pair it separates lies apart by more than its margin,
// whatever the rounding, near the origin and far from it; each direction separates pairs that the
// boxes cannot; non-finite bounds separate nothing.

#include "geometry/slabs.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

namespace kdet {
namespace {

using Point = std::array<double, 3>;

/// The slab directions in the order of slabs.hpp.
constexpr double k_directions[slab_directions][3] = {{1, 1, 1},  {1, 1, -1}, {1, -1, 1}, {-1, 1, 1},
                                                     {1, 1, 0},  {1, -1, 0}, {1, 0, 1},  {1, 0, -1}};

double direction_length(int d) {
    return std::sqrt(k_directions[d][0] * k_directions[d][0] + k_directions[d][1] * k_directions[d][1] +
                     k_directions[d][2] * k_directions[d][2]);
}

double along(const vec3& v, int d) {
    return k_directions[d][0] * v.x + k_directions[d][1] * v.y + k_directions[d][2] * v.z; // exact in double
}

double longest_edge(const vec3 v[4]) {
    double longest = 0;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
            const double dx = double(v[i].x) - v[j].x, dy = double(v[i].y) - v[j].y, dz = double(v[i].z) - v[j].z;
            longest = std::max(longest, std::sqrt(dx * dx + dy * dy + dz * dz));
        }
    return longest;
}

/// The largest gap between the two tets' exact projections along a slab direction, over its length.
double largest_slab_gap(const vec3 a[4], const vec3 b[4]) {
    double gap = -INFINITY;
    for (int d = 0; d < slab_directions; ++d) {
        double lo_a = INFINITY, hi_a = -INFINITY, lo_b = INFINITY, hi_b = -INFINITY;
        for (int k = 0; k < 4; ++k) {
            lo_a = std::min(lo_a, along(a[k], d)), hi_a = std::max(hi_a, along(a[k], d));
            lo_b = std::min(lo_b, along(b[k], d)), hi_b = std::max(hi_b, along(b[k], d));
        }
        gap = std::max(gap, std::max(lo_b - hi_a, lo_a - hi_b) / direction_length(d));
    }
    return gap;
}

TetSlabs slabs_of(const vec3 v[4], float margin = 0.0f) {
    return tet_slabs(v, static_cast<float>(longest_edge(v)), margin);
}

/// The first direction along which the widened slabs are disjoint, or -1.
int separating_direction(const TetSlabs& a, const TetSlabs& b) {
    for (int d = 0; d < slab_directions; ++d)
        if (a.hi[d] < b.lo[d] || b.hi[d] < a.lo[d]) return d;
    return -1;
}

/// Two random tets of `size` about a centre up to `offset` sizes from the origin, b moved along slab
/// direction d so that its lowest projection lies `gap` (in units of the direction's length) above a's
/// highest.
void place_pair(std::mt19937& rng, int d, double offset, double size, double gap, vec3 a[4], vec3 b[4]) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double length = direction_length(d);
    Point centre{offset * size * unit(rng), offset * size * unit(rng), offset * size * unit(rng)};
    std::array<Point, 4> pa, pb;
    for (auto* tet : {&pa, &pb})
        for (Point& p : *tet)
            for (int c = 0; c < 3; ++c) p[c] = centre[c] + size * (unit(rng) - 0.5);
    auto project = [&](const Point& p) { return (k_directions[d][0] * p[0] + k_directions[d][1] * p[1] + k_directions[d][2] * p[2]) / length; };
    double hi_a = -INFINITY, lo_b = INFINITY;
    for (const Point& p : pa) hi_a = std::max(hi_a, project(p));
    for (const Point& p : pb) lo_b = std::min(lo_b, project(p));
    const double shift = hi_a + gap - lo_b;
    for (int k = 0; k < 4; ++k) {
        a[k] = vec3{float(pa[k][0]), float(pa[k][1]), float(pa[k][2])};
        b[k] = vec3{float(pb[k][0] + shift * k_directions[d][0] / length), float(pb[k][1] + shift * k_directions[d][1] / length),
                    float(pb[k][2] + shift * k_directions[d][2] / length)};
    }
}

TEST(Slabs, SeparateOnlyPairsFartherApartThanTheMarginAtAnyDistanceFromTheOrigin) {
    // Pairs placed at a chosen gap along a slab direction, from deep overlap to a hundredth of the pair's
    // size apart, log-uniformly around the margin (5.6e-4 of the longest edge), at offsets from the
    // origin up to 10^6 times their size, where the coordinates' rounding exceeds the margin.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int separated_along[slab_directions] = {};
    long long pairs = 0, separated = 0, below_margin = 0;
    for (double offset : {0.0, 1e3, 1e6})
        for (int n = 0; n < 20000; ++n) {
            const double size = std::exp2(20.0 * unit(rng) - 10.0);
            const int d = n % slab_directions;
            const double gap = (unit(rng) < 0.25 ? -0.5 : 1.0) * size * std::exp2(-20.0 * unit(rng));
            vec3 a[4], b[4];
            place_pair(rng, d, offset, size, gap, a, b);
            ++pairs;
            const int by = separating_direction(slabs_of(a), slabs_of(b));
            EXPECT_EQ(by >= 0, slabs_separate(slabs_of(a), slabs_of(b)));
            if (by < 0) continue;
            ++separated;
            ++separated_along[by];
            const double margin = 0x1p-10 / std::sqrt(3.0) * std::max(longest_edge(a), longest_edge(b));
            if (largest_slab_gap(a, b) <= margin && ++below_margin <= 5)
                ADD_FAILURE() << "separated at a gap of " << largest_slab_gap(a, b) / margin << " margins, offset " << offset;
        }
    EXPECT_EQ(below_margin, 0);
    // Every lane separates some pairs: a direction computed wrongly, or never compared, would not.
    for (int d = 0; d < slab_directions; ++d) EXPECT_GT(separated_along[d], pairs / 40) << "direction " << d;
    EXPECT_LT(separated, pairs);
}

TEST(Slabs, WithAMarginSeparateOnlyPairsFartherApartThanIt) {
    // DetectorOptions::margin widens the slabs: a pair they separate lies more than the margin apart
    // along a direction, so farther than the margin. Margins from 2^-12 to 4 of the tets' size, gaps
    // (along the direction's length, a lower bound of the distance) log-uniform from a quarter to four
    // times the margin, which the slabs see scaled by up to sqrt(3).
    std::mt19937 rng(45);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    long long pairs = 0, separated = 0, within = 0;
    for (double offset : {0.0, 1e3})
        for (int n = 0; n < 20000; ++n) {
            const double size = std::exp2(20.0 * unit(rng) - 10.0);
            const float margin = static_cast<float>(size * std::exp2(14.0 * unit(rng) - 12.0));
            const double gap = margin * std::exp2(4.0 * unit(rng) - 2.0);
            vec3 a[4], b[4];
            place_pair(rng, n % slab_directions, offset, size, gap, a, b);
            ++pairs;
            if (!slabs_separate(slabs_of(a, margin), slabs_of(b, margin))) continue;
            ++separated;
            if (largest_slab_gap(a, b) <= margin && ++within <= 5)
                ADD_FAILURE() << "separated at a gap of " << largest_slab_gap(a, b) / margin << " margins, offset " << offset;
        }
    EXPECT_EQ(within, 0);
    // Pairs farther than sqrt(3) margins along a face or space diagonal are separated.
    EXPECT_GT(separated, pairs / 10);
    EXPECT_LT(separated, pairs);
}

TEST(Slabs, SeparateACornerThatTheBoxesCannot) {
    // b sits beyond a's slanted face, inside a's box: only the diagonal (1, 1, 1) separates them.
    const vec3 a[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    vec3 b[4];
    for (int k = 0; k < 4; ++k) b[k] = a[k] * 0.2f + vec3{0.5f, 0.5f, 0.5f};
    EXPECT_TRUE(slabs_separate(slabs_of(a), slabs_of(b)));
    EXPECT_EQ(separating_direction(slabs_of(a), slabs_of(b)), 0);
    // Moved to touch a's face (vertex (1/3, 1/3, 1/3) of b on it) they are not separated.
    for (vec3& v : b) v = v - vec3{0.5f - 1.0f / 3.0f, 0.5f - 1.0f / 3.0f, 0.5f - 1.0f / 3.0f};
    EXPECT_FALSE(slabs_separate(slabs_of(a), slabs_of(b)));
}

TEST(Slabs, NonFiniteBoundsSeparateNothing) {
    // Projections that overflow give infinite bounds, and an infinite widening NaN ones.
    const vec3 a[4] = {{3e38f, 3e38f, 3e38f}, {3.1e38f, 3e38f, 3e38f}, {3e38f, 3.1e38f, 3e38f}, {3e38f, 3e38f, 3.1e38f}};
    vec3 b[4] = {a[0], {2.9e38f, 3e38f, 3e38f}, {3e38f, 2.9e38f, 3e38f}, {3e38f, 3e38f, 2.9e38f}};
    EXPECT_FALSE(slabs_separate(slabs_of(a), slabs_of(b)));
    TetSlabs nan_slabs = slabs_of(a);
    for (float& lo : nan_slabs.lo) lo = NAN;
    EXPECT_FALSE(slabs_separate(nan_slabs, slabs_of(b)));
}

} // namespace
} // namespace kdet
