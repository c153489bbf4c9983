/// @file test_face_planes_cgal.cpp
/// @brief The face-plane pre-test (src/geometry/face_planes.hpp) against CGAL's exact predicate and
/// against every narrow-phase test: wherever it decides a pair, it must give the exact answer and the
/// answer of every test, in both argument orders, so that running it first changes no reported pair.

#include <gtest/gtest.h>

#include <cstdio>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "geometry/face_planes.hpp"
#include "geometry/tet_intersect.hpp"
#include "../near_touching.hpp"
#include "narrow_cases.hpp"

namespace {

using kdet::NarrowPhase;
using kdet::PlaneVerdict;
using namespace kdet::cgal_check;

/// The pre-test's verdict on a pair (both argument orders) where it decides, against CGAL and every
/// test; counts the decisions and prints the first few disagreements.
struct VerdictCheck {
    std::vector<NarrowPhase> tests = kdet::test::every_narrow_phase_test();
    long long pairs = 0, separated = 0, intersecting = 0, wrong = 0;

    void check(const kdet::vec3 a[4], const kdet::vec3 b[4], bool truth, const char* what) {
        ++pairs;
        const kdet::TetPlanes pa = kdet::tet_planes(a), pb = kdet::tet_planes(b);
        const PlaneVerdict verdict = kdet::face_plane_pretest(pa, a, pb, b, false);
        EXPECT_EQ(kdet::face_plane_pretest(pa, a, pb, b, true) == PlaneVerdict::separated,
                  verdict == PlaneVerdict::separated);
        if (verdict == PlaneVerdict::unsure) return;
        const bool said = verdict == PlaneVerdict::intersecting;
        ++(said ? intersecting : separated);
        bool agree = said == truth;
        for (NarrowPhase test : tests)
            agree = agree && kdet::tets_intersect(test, a, b) == said && kdet::tets_intersect(test, b, a) == said;
        if (!agree && ++wrong <= 5)
            std::printf("pre-test says %s, CGAL %d: %s\n", said ? "intersecting" : "separated", truth, what);
    }
};

TEST(FacePlanesCgal, DecidesOnlyWhereTheOracleAndEveryTestAgree) {
    const std::vector<Case> cases = generate_cases(0x70726574u, 1500);
    VerdictCheck check;
    ASSERT_GE(check.tests.size(), 5u);
    for (const Case& c : cases) {
        // The pipeline runs the pre-test on pairs whose boxes overlap only (its bounds rely on it).
        if (!kdet::boxes_overlap(kdet::tet_box(c.a), kdet::tet_box(c.b))) continue;
        char what[96];
        std::snprintf(what, sizeof what, "margin %.3e, kind %s, size %g", c.margin, case_kind_name(c.kind), c.size);
        check.check(c.a, c.b, c.truth, what);
        check.check(c.b, c.a, c.truth, what);
    }
    std::printf("box-overlapping pairs %lld: pre-test separated %lld, intersecting %lld\n", check.pairs,
                check.separated, check.intersecting);
    EXPECT_EQ(check.wrong, 0);
    // Not vacuous: the cases hold plenty of pairs it must be able to decide (a vertex inside the other
    // tet proves about 2.7 % of them intersecting, edges through the other tet 12 % in all).
    EXPECT_GT(check.separated, check.pairs / 20);
    EXPECT_GT(check.intersecting, check.pairs / 10);
}

/// Pairs placed within three margins of the pre-test's decision and near the tests' tolerance: where
/// it decides, CGAL and every test agree, and it does decide a good part of them.
TEST(FacePlanesCgal, NearItsMarginItDecidesOnlyWhatEveryTestDecides) {
    const kdet::test::NearTouchingPairs pairs = kdet::test::near_touching_pairs(512, 0x6e656172u);
    VerdictCheck check;
    const std::size_t count = pairs.first.tets.size() / 4;
    for (std::size_t i = 0; i < count; ++i) {
        kdet::vec3 a[4], b[4];
        d3 ad[4], bd[4];
        for (int v = 0; v < 4; ++v) {
            const double* p = &pairs.first.positions[3 * pairs.first.tets[4 * i + v]];
            const double* q = &pairs.second.positions[3 * pairs.second.tets[4 * i + v]];
            a[v] = kdet::make_vec3(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
            b[v] = kdet::make_vec3(static_cast<float>(q[0]), static_cast<float>(q[1]), static_cast<float>(q[2]));
        }
        widen(a, ad);
        widen(b, bd);
        const bool truth = cgal_intersect(ad, bd);
        char what[48];
        std::snprintf(what, sizeof what, "near-touching pair %zu", i);
        check.check(a, b, truth, what);
        check.check(b, a, truth, what);
    }
    std::printf("near-touching pairs %lld: pre-test separated %lld, intersecting %lld\n", check.pairs,
                check.separated, check.intersecting);
    EXPECT_EQ(check.wrong, 0);
    EXPECT_GT(check.separated, check.pairs / 4);
    // A point inside each face by twice its separation margin proves 21 % of them intersecting.
    EXPECT_GT(check.intersecting, check.pairs / 6);
}

/// Face k of a tet, in double: its outward unit normal, a point on it, its centroid, and its
/// separation margin (2^-15 / s + 2^-16) L^2 / l_f for a pair whose longest edge is `longest` (s, l_f:
/// the sine and the shorter of the two edges at its largest angle, which build the pre-test's normal).
struct FaceOf {
    d3 normal, point, centroid;
    double margin;
};

FaceOf face_of(const d3 v[4], int k, double longest) {
    const d3 f0 = v[(k + 1) % 4], f1 = v[(k + 2) % 4], f2 = v[(k + 3) % 4];
    auto length = [](d3 e) { return std::sqrt(dot(e, e)); };
    FaceOf face;
    face.normal = normalized(cross(f1 - f0, f2 - f0));
    if (dot(face.normal, v[k] - f0) > 0.0) face.normal = face.normal * -1.0;
    face.point = f0;
    face.centroid = (f0 + f1 + f2) * (1.0 / 3.0);
    const double l01 = length(f1 - f0), l02 = length(f2 - f0), l12 = length(f2 - f1);
    const double top = std::max({l01, l02, l12});
    const double first = top == l01 ? l02 : l01, second = top == l12 ? l02 : l12;
    const double sine = length(cross(f1 - f0, f2 - f0)) / (first * second);
    face.margin = (std::ldexp(1.0, -15) / sine + std::ldexp(1.0, -16)) * longest * longest / std::min(first, second);
    return face;
}

/// A well-shaped tet, away from the origin, and its longest and shortest edges.
struct ShapedTet {
    kdet::vec3 v[4] = {kdet::make_vec3(1.0f, 1.0f, 1.0f), kdet::make_vec3(2.0f, 1.1f, 1.0f),
                       kdet::make_vec3(1.2f, 2.0f, 1.1f), kdet::make_vec3(1.3f, 1.2f, 2.0f)};
    d3 wide[4];
    double longest = 0.0, shortest = 1e300;
    ShapedTet() {
        widen(v, wide);
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j) {
                const double l = std::sqrt(dot(wide[j] - wide[i], wide[j] - wide[i]));
                longest = std::max(longest, l);
                shortest = std::min(shortest, l);
            }
    }
};

/// A tet and its mirror image across one face, moved apart along that face's normal: the pre-test
/// separates them once the gap exceeds that face's own margin, (2^-15 / s + 2^-16) L^2 / l_f, which for
/// a well-shaped face is a small part of the owner's worst case 2^-9 L^2 / l, and not below it.
TEST(FacePlanesCgal, EachFaceSeparatesByItsOwnMargin) {
    const ShapedTet a;
    VerdictCheck check;
    for (int k = 0; k < 4; ++k) {
        const FaceOf face = face_of(a.wide, k, a.longest);
        ASSERT_LT(8.0 * face.margin, std::ldexp(1.0, -9) * a.longest * a.longest / a.shortest) << "face " << k;
        for (const double gap : {0.5 * face.margin, 2.0 * face.margin}) {
            // The mirror image across the face, moved out by the gap: its copy of the face lies parallel
            // to the original, `gap` away, and only that pair of faces can separate the two.
            kdet::vec3 b[4];
            for (int v = 0; v < 4; ++v) {
                const double beyond = v == k ? -2.0 * dot(face.normal, a.wide[v] - face.point) : 0.0;
                b[v] = to_vec3(a.wide[v] + face.normal * (beyond + gap));
            }
            d3 bd[4];
            widen(b, bd);
            ASSERT_FALSE(cgal_intersect(a.wide, bd)) << "face " << k << ", gap " << gap;
            const kdet::TetPlanes pa = kdet::tet_planes(a.v), pb = kdet::tet_planes(b);
            const bool separated = kdet::face_plane_pretest(pa, a.v, pb, b, false) == PlaneVerdict::separated;
            EXPECT_EQ(separated, gap > face.margin) << "face " << k << ", gap " << gap << ", margin " << face.margin;
            check.check(a.v, b, false, "mirror image");
        }
    }
    EXPECT_EQ(check.wrong, 0);
}

/// A tet with one vertex pushed through a face of another, the rest beyond that face: the pre-test
/// proves them intersecting once the vertex lies deeper than twice that face's separation margin (its
/// inside margin; the vertex is far inside the other three faces), and not before.
TEST(FacePlanesCgal, EachFaceProvesAnIntersectionByTwiceItsMargin) {
    const ShapedTet a;
    VerdictCheck check;
    for (int k = 0; k < 4; ++k) {
        const FaceOf face = face_of(a.wide, k, a.longest);
        // Far below 2^-11 L^2 / l, a margin for the whole tet from its shortest edge: only the face's own
        // margin proves these pairs.
        ASSERT_LT(8.0 * face.margin, std::ldexp(1.0, -11) * a.longest * a.longest / a.shortest) << "face " << k;
        for (const double depth : {1.5 * face.margin, 3.0 * face.margin}) {
            const d3 out = face.normal * (0.5 * a.longest);
            const d3 tip = face.centroid - face.normal * depth;
            const d3 along = normalized(face.point - face.centroid) * (0.4 * a.longest);
            const d3 across = normalized(cross(face.normal, along)) * (0.4 * a.longest);
            const d3 bd_exact[4] = {tip, face.centroid + out + along, face.centroid + out - along + across,
                                    face.centroid + out - along - across};
            kdet::vec3 b[4];
            for (int v = 0; v < 4; ++v) b[v] = to_vec3(bd_exact[v]);
            d3 bd[4];
            widen(b, bd);
            ASSERT_TRUE(cgal_intersect(a.wide, bd)) << "face " << k << ", depth " << depth;
            const kdet::TetPlanes pa = kdet::tet_planes(a.v), pb = kdet::tet_planes(b);
            const bool proven = kdet::face_plane_pretest(pa, a.v, pb, b, false) == PlaneVerdict::intersecting;
            EXPECT_EQ(proven, depth > 2.0 * face.margin) << "face " << k << ", depth " << depth;
            check.check(a.v, b, true, "vertex through a face");
        }
    }
    EXPECT_EQ(check.wrong, 0);
}

/// A pair whose only contact is an edge of one tet passing through the other (no vertex of either lies
/// inside the other) is proven intersecting from the distances at the edge's ends; lifted so that the
/// edge passes beside the tet (the boxes still overlap), it is not.
TEST(FacePlanesCgal, AnEdgeThroughTheOtherTetProvesAnIntersection) {
    const kdet::vec3 a[4] = {kdet::make_vec3(0, 0, 0), kdet::make_vec3(1, 0, 0), kdet::make_vec3(0, 1, 0),
                             kdet::make_vec3(0, 0, 1)};
    for (const float lift : {0.0f, 0.7f}) {
        // The edge from the first vertex to the second runs along x at height 0.2 + lift.
        const kdet::vec3 b[4] = {kdet::make_vec3(-1, 0.2f, 0.2f + lift), kdet::make_vec3(2, 0.2f, 0.2f + lift),
                                 kdet::make_vec3(0.3f, 3, 0.2f + lift), kdet::make_vec3(0.3f, 0.2f, 3 + lift)};
        d3 ad[4], bd[4];
        widen(a, ad);
        widen(b, bd);
        const bool truth = cgal_intersect(ad, bd);
        EXPECT_EQ(truth, lift == 0.0f);
        const kdet::TetPlanes pa = kdet::tet_planes(a), pb = kdet::tet_planes(b);
        for (int j = 0; j < 4; ++j) { // no vertex inside the other tet: only the edge can prove it
            float distance_a[4], distance_b[4];
            kdet::plane_distances(pb, a[j], distance_a);
            kdet::plane_distances(pa, b[j], distance_b);
            EXPECT_GT(std::max({distance_a[0], distance_a[1], distance_a[2], distance_a[3]}), 0.0f);
            EXPECT_GT(std::max({distance_b[0], distance_b[1], distance_b[2], distance_b[3]}), 0.0f);
        }
        EXPECT_EQ(kdet::face_plane_pretest(pa, a, pb, b, false) == PlaneVerdict::intersecting, truth) << "lift " << lift;
        EXPECT_EQ(kdet::face_plane_pretest(pb, b, pa, a, false) == PlaneVerdict::intersecting, truth) << "lift " << lift;
    }
}

} // namespace
