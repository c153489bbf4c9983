/// @file test_exact_cgal.cpp
/// @brief The `exact` narrow-phase test against CGAL on every generated kind, size and offset (both
/// argument orders), on zero-volume tets (judged by CGAL's exact polytope distance), and the contact
/// that sat_mtv gives every pair it reports. narrow_phase_report runs the same checks on 2 million
/// pairs and more (docs/narrow-phase.md).

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "geometry/tet_intersect.hpp"
#include "narrow_cases.hpp"

namespace {

using kdet::vec3;
using namespace kdet::cgal_check;

const std::vector<Case>& exact_cases() {
    static const std::vector<Case> cases = generate_cases(0x6578616374u, 2000);
    return cases;
}

void print_pair(const vec3* a, const vec3* b) {
    for (const vec3* t : {a, b})
        for (int i = 0; i < 4; ++i) std::printf("    {%a, %a, %a}\n", t[i].x, t[i].y, t[i].z);
}

TEST(ExactCgal, AgreesWithCgalOnEveryKindSizeAndOffset) {
    long long wrong = 0, calls = 0, exact_stage[k_case_kind_count] = {}, pairs[k_case_kind_count] = {};
    for (const Case& c : exact_cases()) {
        for (int order = 0; order < 2; ++order) {
            bool stage = false;
            const bool got = order == 0 ? kdet::tets_intersect_exact(c.a, c.b, stage)
                                        : kdet::tets_intersect_exact(c.b, c.a, stage);
            ++calls;
            ++pairs[static_cast<int>(c.kind)];
            exact_stage[static_cast<int>(c.kind)] += stage;
            if (got != c.truth && ++wrong <= 5) {
                std::printf("exact says %d, CGAL %d: kind=%s size=%g margin=%.3e order %d\n", got, c.truth,
                            case_kind_name(c.kind), c.size, c.margin, order);
                print_pair(c.a, c.b);
            }
        }
    }
    std::printf("%lld calls; reached the exact stage, per kind:\n", calls);
    for (CaseKind kind : k_case_kinds)
        std::printf("  %-24s %7lld of %7lld\n", case_kind_name(kind), exact_stage[static_cast<int>(kind)],
                    pairs[static_cast<int>(kind)]);
    EXPECT_GE(calls, 1000000);
    EXPECT_EQ(wrong, 0);
}

TEST(ExactCgal, AgreesWithCgalOnZeroVolumeTets) {
    const std::vector<DegenerateCase> cases = generate_degenerate_cases(0x666c6174u, 6000);
    long long wrong = 0, intersecting = 0, by_dimensions[4][4] = {};
    for (const DegenerateCase& c : cases) {
        intersecting += c.truth;
        ++by_dimensions[c.dim_a][c.dim_b];
        for (int order = 0; order < 2; ++order) {
            const bool got = order == 0 ? kdet::tets_intersect_exact(c.a, c.b) : kdet::tets_intersect_exact(c.b, c.a);
            if (got != c.truth && ++wrong <= 5) {
                std::printf("exact says %d, CGAL %d: dimensions %d and %d, %s, order %d\n", got, c.truth, c.dim_a,
                            c.dim_b, c.lattice ? "lattice" : "plane z = c", order);
                print_pair(c.a, c.b);
            }
        }
    }
    std::printf("%zu pairs, %lld intersecting; by hull dimensions (rows: first tet 0..3):\n", cases.size(), intersecting);
    for (const auto& row : by_dimensions) std::printf("  %6lld %6lld %6lld %6lld\n", row[0], row[1], row[2], row[3]);
    // Every combination of a degenerate first tet with every second tet occurs, touching pairs included.
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 4; ++b) EXPECT_GT(by_dimensions[a][b], 20) << a << " " << b;
    EXPECT_GT(intersecting, static_cast<long long>(cases.size() / 10));
    EXPECT_EQ(wrong, 0);
}

/// sat_mtv computes the contacts of the pairs a test reports: every pair exact reports gets one, with
/// depth 0 up to sat_mtv's float rounding when the tets only touch (the slack of MtvSeparatesAndIsLeast).
TEST(ExactCgal, EveryReportedPairGetsAContact) {
    long long missing = 0, deep_touching = 0, touching = 0;
    double worst = 0.0;
    for (const Case& c : exact_cases()) {
        if (!kdet::tets_intersect_exact(c.a, c.b)) continue;
        float depth = -1.0f;
        vec3 direction{0, 0, 0};
        if (!kdet::tets_intersect_sat_mtv(c.a, c.b, depth, direction) && ++missing <= 5) print_pair(c.a, c.b);
        if (bucket_of(c.margin) != Bucket::touching) continue;
        ++touching;
        d3 a[4], b[4];
        widen(c.a, a);
        widen(c.b, b);
        worst = std::max(worst, depth / longest_edge(a, b));
        if (depth > 1.5e-5 * longest_edge(a, b) && ++deep_touching <= 5) {
            std::printf("touching pair with depth %g (%g of the longest edge):\n", depth, depth / longest_edge(a, b));
            print_pair(c.a, c.b);
        }
    }
    std::printf("%lld touching pairs, largest depth %g of the longest edge\n", touching, worst);
    EXPECT_GT(touching, 10000);
    EXPECT_EQ(missing, 0);
    EXPECT_EQ(deep_touching, 0);
}

} // namespace
