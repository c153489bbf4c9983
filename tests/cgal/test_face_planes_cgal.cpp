/// @file test_face_planes_cgal.cpp
/// @brief The face-plane pre-test (src/geometry/face_planes.hpp) against CGAL's exact predicate and
/// against every narrow-phase test: wherever it decides a pair, it must give the exact answer and the
/// answer of every test, in both argument orders, so that running it first changes no reported pair.

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <vector>

#include "geometry/face_planes.hpp"
#include "geometry/tet_intersect.hpp"
#include "narrow_cases.hpp"

namespace {

using kdet::NarrowPhase;
using kdet::PlaneVerdict;
using namespace kdet::cgal_check;

/// Every narrow-phase test the library names, so that a test added later is covered too.
std::vector<NarrowPhase> every_test() {
    std::vector<NarrowPhase> tests;
    for (int v = 0; std::strcmp(kdet::to_string(static_cast<NarrowPhase>(v)), "?") != 0; ++v)
        tests.push_back(static_cast<NarrowPhase>(v));
    return tests;
}

TEST(FacePlanesCgal, DecidesOnlyWhereTheOracleAndEveryTestAgree) {
    const std::vector<Case> cases = generate_cases(0x70726574u, 1500);
    const std::vector<NarrowPhase> tests = every_test();
    ASSERT_GE(tests.size(), 5u);
    long long pairs = 0, separated = 0, intersecting = 0, wrong = 0;
    for (const Case& c : cases) {
        // The pipeline runs the pre-test on pairs whose boxes overlap only (its bounds rely on it).
        if (!kdet::boxes_overlap(kdet::tet_box(c.a), kdet::tet_box(c.b))) continue;
        for (int order = 0; order < 2; ++order) {
            const kdet::vec3* a = order == 0 ? c.a : c.b;
            const kdet::vec3* b = order == 0 ? c.b : c.a;
            ++pairs;
            const kdet::TetPlanes pa = kdet::tet_planes(a), pb = kdet::tet_planes(b);
            const PlaneVerdict verdict = kdet::face_plane_pretest(pa, a, pb, b, false);
            EXPECT_EQ(kdet::face_plane_pretest(pa, a, pb, b, true) == PlaneVerdict::separated,
                      verdict == PlaneVerdict::separated);
            if (verdict == PlaneVerdict::unsure) continue;
            const bool said = verdict == PlaneVerdict::intersecting;
            ++(said ? intersecting : separated);
            bool agree = said == c.truth;
            for (NarrowPhase test : tests)
                agree = agree && kdet::tets_intersect(test, a, b) == said && kdet::tets_intersect(test, b, a) == said;
            if (!agree && ++wrong <= 5) {
                std::printf("pre-test says %s, CGAL %d, margin %.3e, kind %s, size %g\n",
                            said ? "intersecting" : "separated", c.truth, c.margin, case_kind_name(c.kind), c.size);
            }
        }
    }
    std::printf("box-overlapping pairs %lld: pre-test separated %lld, intersecting %lld\n", pairs, separated,
                intersecting);
    EXPECT_EQ(wrong, 0);
    // Not vacuous: the cases hold plenty of pairs it must be able to decide.
    EXPECT_GT(separated, pairs / 20);
    EXPECT_GT(intersecting, pairs / 50);
}

} // namespace
