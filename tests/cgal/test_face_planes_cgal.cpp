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
        const PlaneVerdict verdict = kdet::face_plane_pretest(pa, a, pb, b, false, 0.0f);
        EXPECT_EQ(kdet::face_plane_pretest(pa, a, pb, b, true, 0.0f) == PlaneVerdict::separated,
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
/// separation margin (2^-15 / s + 2^-16) A / l_f (s, l_f: the sine and the shorter of the two edges at
/// its largest angle, which build the pre-test's normal) for the area A = `scale`: L^2 for a pair whose
/// longest edge is L; l_P L for its inside margin, l_P the tet's own longest edge.
struct FaceOf {
    d3 normal, point, centroid;
    double margin;
};

FaceOf face_of(const d3 v[4], int k, double scale) {
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
    face.margin = (std::ldexp(1.0, -15) / sine + std::ldexp(1.0, -16)) * scale / std::min(first, second);
    return face;
}

/// The longest and shortest edges of a tet.
struct EdgeLengths {
    double longest = 0.0, shortest = 1e300;
};

EdgeLengths edge_lengths(const d3 v[4]) {
    EdgeLengths e;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
            const double l = std::sqrt(dot(v[j] - v[i], v[j] - v[i]));
            e.longest = std::max(e.longest, l);
            e.shortest = std::min(e.shortest, l);
        }
    return e;
}

/// A well-shaped tet, away from the origin, and its longest and shortest edges.
struct ShapedTet {
    kdet::vec3 v[4] = {kdet::make_vec3(1.0f, 1.0f, 1.0f), kdet::make_vec3(2.0f, 1.1f, 1.0f),
                       kdet::make_vec3(1.2f, 2.0f, 1.1f), kdet::make_vec3(1.3f, 1.2f, 2.0f)};
    d3 wide[4];
    double longest = 0.0, shortest = 1e300;
    ShapedTet() {
        widen(v, wide);
        const EdgeLengths e = edge_lengths(wide);
        longest = e.longest;
        shortest = e.shortest;
    }
};

/// A tet and its mirror image across one face, moved apart along that face's normal: the pre-test
/// separates them once the gap exceeds that face's own margin, (2^-15 / s + 2^-16) L^2 / l_f, which for
/// a well-shaped face is a small part of the owner's worst case 2^-9 L^2 / l, and not below it.
TEST(FacePlanesCgal, EachFaceSeparatesByItsOwnMargin) {
    const ShapedTet a;
    VerdictCheck check;
    for (int k = 0; k < 4; ++k) {
        const FaceOf face = face_of(a.wide, k, a.longest * a.longest);
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
            const bool separated = kdet::face_plane_pretest(pa, a.v, pb, b, false, 0.0f) == PlaneVerdict::separated;
            EXPECT_EQ(separated, gap > face.margin) << "face " << k << ", gap " << gap << ", margin " << face.margin;
            check.check(a.v, b, false, "mirror image");
        }
    }
    EXPECT_EQ(check.wrong, 0);
}

/// A tet with one vertex pushed through a face of another, the rest beyond that face: the pre-test
/// proves them intersecting once the vertex lies deeper than that face's inside margin (twice its
/// separation margin taken with l_P L for L^2: l_P the owner's longest edge, L the pair's; the vertex
/// is far inside the other three faces), and not before. With the pushing tet of about the owner's size
/// and with one 8 times larger, whose depth the pair's L^2 would have left unproven.
TEST(FacePlanesCgal, EachFaceProvesAnIntersectionByItsInsideMargin) {
    const ShapedTet a;
    VerdictCheck check;
    for (const double size : {1.0, 8.0})
        for (int k = 0; k < 4; ++k) {
            const FaceOf unit_face = face_of(a.wide, k, 1.0);
            const d3 out = unit_face.normal * (0.5 * size * a.longest);
            const d3 along = normalized(unit_face.point - unit_face.centroid) * (0.4 * size * a.longest);
            const d3 across = normalized(cross(unit_face.normal, along)) * (0.4 * size * a.longest);
            // The pushing tet's longest edge, from its three far vertices (the tip's edges are shorter).
            const double b_longest = std::sqrt(dot(along * 2.0 - across, along * 2.0 - across));
            const double pair_longest = std::max(a.longest, b_longest);
            const FaceOf face = face_of(a.wide, k, a.longest * pair_longest);
            // Far below 2^-11 l_P L / l, a margin for the whole tet from its shortest edge: only the face's
            // own margin proves these pairs.
            ASSERT_LT(8.0 * face.margin, std::ldexp(1.0, -11) * a.longest * pair_longest / a.shortest) << "face " << k;
            // The deeper vertex lies within the inside margin the pair's L^2 would give.
            if (size > 1.0) {
                ASSERT_LT(3.0 * face.margin, 2.0 * face_of(a.wide, k, pair_longest * pair_longest).margin);
            }
            for (const double depth : {1.5 * face.margin, 3.0 * face.margin}) {
                const d3 tip = face.centroid - face.normal * depth;
                const d3 bd_exact[4] = {tip, face.centroid + out + along, face.centroid + out - along + across,
                                        face.centroid + out - along - across};
                kdet::vec3 b[4];
                for (int v = 0; v < 4; ++v) b[v] = to_vec3(bd_exact[v]);
                d3 bd[4];
                widen(b, bd);
                ASSERT_TRUE(cgal_intersect(a.wide, bd)) << "face " << k << ", depth " << depth;
                const kdet::TetPlanes pa = kdet::tet_planes(a.v), pb = kdet::tet_planes(b);
                ASSERT_NEAR(pb.longest, b_longest, 1e-5 * b_longest);
                const bool proven = kdet::face_plane_pretest(pa, a.v, pb, b, false, 0.0f) == PlaneVerdict::intersecting;
                EXPECT_EQ(proven, depth > 2.0 * face.margin) << "size " << size << ", face " << k << ", depth " << depth;
                check.check(a.v, b, true, "vertex through a face");
            }
        }
    EXPECT_EQ(check.wrong, 0);
}

/// Random pairs of a small tet and one 4 to 64 times larger, pushed with a vertex through a face of the
/// small one to within three inside margins of that face (l_P L for L^2: the margins this pairing
/// shrinks most), at sizes six decades apart and away from the origin: wherever the pre-test decides,
/// CGAL and every test agree, and every pair pushed in beyond one and a half margins is proven (the
/// pair's L^2 would have proven none of them: L is at least 3.6 times the small tet's longest edge).
TEST(FacePlanesCgal, GradedPairsNearTheInsideMarginAreDecidedOnlyWhereEveryTestAgrees) {
    Random rng(0x67726164u);
    VerdictCheck check;
    int pushed_in = 0;
    for (const double size : {1e-3, 1.0, 1e3})
        for (int n = 0; n < 600; ++n) {
            d3 ad[4];
            double longest = 0.0, shortest = 0.0;
            kdet::vec3 a[4];
            do {
                const d3 centre = rng.direction() * (rng.uniform(0.0, 100.0) * size);
                for (int v = 0; v < 4; ++v) a[v] = to_vec3(centre + rng.in_cube(size));
                widen(a, ad);
                const EdgeLengths e = edge_lengths(ad);
                longest = e.longest, shortest = e.shortest;
                // Well shaped: each vertex at least a fifth of the longest edge above its opposite face.
                for (int f = 0; f < 4 && shortest >= 0.1 * longest; ++f) {
                    const FaceOf face = face_of(ad, f, 1.0);
                    if (-dot(face.normal, ad[f] - face.point) < 0.2 * longest) shortest = 0.0;
                }
            } while (shortest < 0.1 * longest);
            const int k = rng.index(4);
            const double scale = std::ldexp(1.0, 2 + rng.index(5)) * longest; // 4 to 64 times a's longest edge
            const FaceOf unit_face = face_of(ad, k, 1.0);
            const d3 along = normalized(unit_face.point - unit_face.centroid), across = cross(unit_face.normal, along);
            const double turn = rng.uniform(0.0, 6.283185307179586);
            const d3 u = along * std::cos(turn) + across * std::sin(turn), w = cross(unit_face.normal, u);
            const d3 base = unit_face.centroid + unit_face.normal * (0.5 * scale);
            const d3 far[3] = {base + u * (0.4 * scale), base - u * (0.4 * scale) + w * (0.4 * scale),
                               base - u * (0.4 * scale) - w * (0.4 * scale)};
            double b_longest = 0.0;
            for (int i = 0; i < 3; ++i)
                for (int j = i + 1; j < 3; ++j) b_longest = std::max(b_longest, std::sqrt(dot(far[j] - far[i], far[j] - far[i])));
            const double inside = 2.0 * face_of(ad, k, longest * std::max(longest, b_longest)).margin;
            const double depth = inside * rng.uniform(-3.0, 3.0);
            kdet::vec3 b[4] = {to_vec3(unit_face.centroid - unit_face.normal * depth), to_vec3(far[0]), to_vec3(far[1]),
                               to_vec3(far[2])};
            std::rotate(b, b + rng.index(4), b + 4);
            d3 bd[4];
            widen(b, bd);
            char what[64];
            std::snprintf(what, sizeof what, "graded pair, size %g, depth %.2f inside margins", size, depth / inside);
            const bool truth = cgal_intersect(ad, bd);
            check.check(a, b, truth, what);
            check.check(b, a, truth, what);
            if (depth > 1.5 * inside) {
                // Far enough in for the vertex alone to prove it, whichever tet goes first.
                ++pushed_in;
                const kdet::TetPlanes pa = kdet::tet_planes(a), pb = kdet::tet_planes(b);
                EXPECT_EQ(kdet::face_plane_pretest(pa, a, pb, b, false, 0.0f), PlaneVerdict::intersecting) << what;
                EXPECT_EQ(kdet::face_plane_pretest(pb, b, pa, a, false, 0.0f), PlaneVerdict::intersecting) << what;
            }
        }
    std::printf("graded pairs %lld: pre-test separated %lld, intersecting %lld; %d pushed in beyond 1.5 margins\n",
                check.pairs, check.separated, check.intersecting, pushed_in);
    EXPECT_EQ(check.wrong, 0);
    EXPECT_GT(pushed_in, 300);
}

/// A flat tet counts as solid, so that a point inside it can prove an intersection, once each face lies
/// above its opposite vertex by more than the face's separation margin for the tet alone, (2^-15 / s +
/// 2^-16) l_P^2 / l_f: here the lowest such height is below 2^-9 l_P^2 / l, the whole tet's former
/// clearance, and the vertex of a tet that touches nothing else of it, put at its centroid, proves the pair.
TEST(FacePlanesCgal, AFlatTetWhoseFacesClearTheirOwnMarginsIsSolid) {
    const kdet::vec3 a[4] = {kdet::make_vec3(1.0f, 1.0f, 1.0f), kdet::make_vec3(2.0f, 1.0f, 1.0f),
                             kdet::make_vec3(1.0f, 2.0f, 1.0f), kdet::make_vec3(1.3f, 1.3f, 1.004f)};
    d3 ad[4];
    widen(a, ad);
    const auto [longest, shortest] = edge_lengths(ad);
    const d3 centroid = (ad[0] + ad[1] + ad[2] + ad[3]) * 0.25;
    // The tip at the centroid, the rest of the other tet above it: nothing but the tip lies in the flat tet.
    const kdet::vec3 b[4] = {to_vec3(centroid), kdet::make_vec3(1.2f, 1.2f, 2.0f), kdet::make_vec3(1.6f, 1.2f, 2.0f),
                             kdet::make_vec3(1.3f, 1.6f, 2.0f)};
    d3 bd[4];
    widen(b, bd);
    const double b_longest = edge_lengths(bd).longest;
    double lowest = 1e300;
    for (int k = 0; k < 4; ++k) {
        const FaceOf own = face_of(ad, k, longest * longest);
        const double height = -dot(own.normal, ad[k] - own.point);
        EXPECT_GT(height, 4.0 * own.margin) << "face " << k;
        lowest = std::min(lowest, height);
        const FaceOf inside = face_of(ad, k, longest * std::max(longest, b_longest));
        EXPECT_GT(-dot(inside.normal, centroid - inside.point), 4.0 * inside.margin) << "face " << k;
    }
    EXPECT_LT(lowest, std::ldexp(1.0, -9) * longest * longest / shortest);
    ASSERT_TRUE(cgal_intersect(ad, bd));
    const kdet::TetPlanes pa = kdet::tet_planes(a), pb = kdet::tet_planes(b);
    EXPECT_EQ(pa.solid, 1u);
    EXPECT_EQ(kdet::face_plane_pretest(pa, a, pb, b, false, 0.0f), PlaneVerdict::intersecting);
    EXPECT_EQ(kdet::face_plane_pretest(pb, b, pa, a, false, 0.0f), PlaneVerdict::intersecting);
    VerdictCheck check;
    check.check(a, b, true, "vertex inside a flat tet");
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
        EXPECT_EQ(kdet::face_plane_pretest(pa, a, pb, b, false, 0.0f) == PlaneVerdict::intersecting, truth) << "lift " << lift;
        EXPECT_EQ(kdet::face_plane_pretest(pb, b, pa, a, false, 0.0f) == PlaneVerdict::intersecting, truth) << "lift " << lift;
    }
}

} // namespace
