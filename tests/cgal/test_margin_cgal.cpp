/// @file test_margin_cgal.cpp
/// @brief The margin decision (DetectorOptions::margin, geometry/tet_distance.hpp) against an exact
/// oracle: the squared distance of the two tets' hulls from CGAL's polytope distance with Gmpzf
/// arithmetic throughout (exact, degenerate tets included; narrow_cases.hpp), compared with m^2
/// exactly. Pairs at their own distance rounded to float and one float either side, parallel faces
/// and edges, coincident vertices, slivers, sizes 2^-20 to 2^20; a real mesh's pairs whole; the
/// distances against the oracle's within 1e-6 of the pair's size.

#include <gtest/gtest.h>

#include <kdet/detector.hpp>
#include <kdet/io.hpp>
#include <kdet/prepare.hpp>

#include <cmath>
#include <cstdlib>
#include <random>
#include <set>
#include <vector>

#include "geometry/face_planes.hpp"
#include "geometry/slabs.hpp"
#include "geometry/tet_distance.hpp"
#include "geometry/tet_intersect.hpp"
#include "pipeline/bounding_boxes.hpp"
#include "narrow_cases.hpp"
#include "../nearby_tets.hpp"

namespace kdet {
namespace {

using Gmpzf = CGAL::Gmpzf;
using cgal_check::cgal_hull_distance;
using cgal_check::d3;
using cgal_check::HullSquaredDistance;
using cgal_check::widen;

/// The oracle's squared distance of two tets given as floats.
HullSquaredDistance cgal_squared_distance(const vec3 a[4], const vec3 b[4]) {
    d3 da[4], db[4];
    widen(a, da);
    widen(b, db);
    return cgal_hull_distance(da, db);
}

/// Exactly: is the squared distance at most margin^2?
bool oracle_within(const HullSquaredDistance& d, float margin) {
    const Gmpzf m(static_cast<double>(margin));
    return d.numerator <= m * m * d.denominator;
}

double oracle_distance(const HullSquaredDistance& d) {
    return std::sqrt(CGAL::to_double(d.numerator) / CGAL::to_double(d.denominator));
}

/// kdet's decision for one pair, as a Detector makes it: the exact test, then the margin.
bool kdet_within(const vec3 a[4], const vec3 b[4], float margin) {
    bool exact_stage = false;
    return tets_intersect(NarrowPhase::exact, a, b, exact_stage) || narrow::disjoint_tets_within(a, b, margin);
}

/// Checks a pair at its own distance rounded to float, and one float either side.
void expect_exact_around(const vec3 a[4], const vec3 b[4], const char* what, int& checked) {
    const HullSquaredDistance d = cgal_squared_distance(a, b);
    const float near = static_cast<float>(oracle_distance(d));
    for (float m : {near, std::nextafter(near, 0.0f), std::nextafter(near, INFINITY),
                     std::nextafter(std::nextafter(near, 0.0f), 0.0f)}) {
        EXPECT_EQ(kdet_within(a, b, m), oracle_within(d, m)) << what << " margin " << m << " distance " << oracle_distance(d);
        ++checked;
    }
}

vec3 scaled(vec3 v, float s) { return {v.x * s, v.y * s, v.z * s}; }

TEST(MarginCgal, ConstructedCasesAtEverySizeAreDecidedAsTheOracleDoes) {
    const float h = 0.1f;
    const vec3 cases[][2][4] = {
        // Parallel faces, overlapping.
        {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.25f, 0.25f, -1}}, {{0.125f, 0.125f, h}, {1.125f, 0.125f, h}, {0.125f, 1.125f, h}, {0.25f, 0.25f, 1.5f}}},
        // Parallel edges, side by side.
        {{{0, 0, 0}, {1, 0, 0}, {0, -1, -1}, {0.5f, -1, 0}}, {{0.25f, h, 0}, {1.25f, h, 0}, {0.5f, 1, 1}, {0.5f, 1, 0}}},
        // Crossed edges.
        {{{-1, 0, 0}, {1, 0, 0}, {0, 1, -1}, {0, -1, -1}}, {{0, -1, h}, {0, 1, h}, {1, 0, 1.5f}, {-1, 0, 1.5f}}},
        // Coincident vertices (touching).
        {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{1, 0, 0}, {2, 0, 0}, {1, 1, 0}, {1, 0, 1}}},
        // A sliver (flat square) under a vertex, and a needle.
        {{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, {{0.5f, 0.5f, h}, {1, 0.5f, 1}, {0.5f, 1, 1}, {0.75f, 0.75f, 2}}},
        {{{0, 0, 0}, {1, 1e-4f, 0}, {2, 0, 1e-4f}, {3, 1e-4f, 1e-4f}}, {{1.5f, h, 0}, {1.5f, 1, 0}, {2, 1, 1}, {1, 1, 1}}},
        // A slanted face and a vertex.
        {{{4, -3, 0}, {-4, 3, 0}, {0, 0, 2}, {-1.5f, -2, 0}}, {{0.3f, 0.4f, 0.5f}, {3.3f, 4.4f, 0.5f}, {3.3f, 4.4f, 1.5f}, {4.3f, 1.4f, 0.5f}}},
    };
    int checked = 0;
    for (int exponent : {-20, -3, 0, 7, 20})
        for (const auto& c : cases) {
            const float s = std::ldexp(1.0f, exponent);
            vec3 a[4], b[4];
            for (int k = 0; k < 4; ++k) {
                a[k] = scaled(c[0][k], s);
                b[k] = scaled(c[1][k], s);
            }
            expect_exact_around(a, b, "constructed", checked);
        }
    EXPECT_GT(checked, 100);
}

TEST(MarginCgal, RandomPairsNearTheirDistanceAreDecidedAsTheOracleDoes) {
    std::mt19937 rng(45);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    int checked = 0;
    for (int n = 0; n < 300; ++n) {
        const float size = std::pow(10.0f, static_cast<float>(n % 13) - 6.0f); // 1e-6 .. 1e6
        vec3 a[4], b[4];
        const vec3 offset{3 * size, unit(rng) * size, unit(rng) * size};
        for (int k = 0; k < 4; ++k) {
            a[k] = {unit(rng) * size, unit(rng) * size, unit(rng) * size};
            // Some pairs get a flat b (its last vertex in the plane of the others), some a shared point.
            b[k] = {unit(rng) * size + offset.x, unit(rng) * size + offset.y, unit(rng) * size + offset.z};
        }
        if (n % 5 == 1) b[3] = {(b[0].x + b[1].x) / 2, (b[0].y + b[1].y) / 2, (b[0].z + b[1].z) / 2};
        if (n % 7 == 2) b[0] = a[0];
        expect_exact_around(a, b, "random", checked);
    }
    EXPECT_GT(checked, 1000);
}

/// test::random_nearby_tets, some with a flat b (its last vertex on an edge).
void random_near_pair(std::mt19937& rng, int n, float size, vec3 a[4], vec3 b[4]) {
    test::random_nearby_tets(rng, size, a, b);
    if (n % 5 == 1) b[3] = {(b[0].x + b[1].x) / 2, (b[0].y + b[1].y) / 2, (b[0].z + b[1].z) / 2};
}

TEST(MarginCgal, MarginsFromHalfToTwiceTheDistanceAreDecidedAsTheOracleDoes) {
    // Margins 2^-k of the distance either side of it, k from 1 to 40: the closest features found in double
    // decide the pairs far from their margin, the scan of every feature pair those within rounding of it.
    std::mt19937 rng(4546);
    int checked = 0, within = 0;
    for (int n = 0; n < 200; ++n) {
        const float size = std::pow(10.0f, static_cast<float>(n % 13) - 6.0f);
        vec3 a[4], b[4];
        random_near_pair(rng, n, size, a, b);
        const HullSquaredDistance d = cgal_squared_distance(a, b);
        const double distance = oracle_distance(d);
        for (int k : {1, 4, 12, 20, 28, 36, 40})
            for (int side : {-1, 1}) {
                const float m = static_cast<float>(distance * (1.0 + side * std::ldexp(1.0, -k)));
                const bool expected = oracle_within(d, m);
                EXPECT_EQ(kdet_within(a, b, m), expected) << "size " << size << " margin " << m << " distance " << distance;
                within += expected;
                ++checked;
            }
    }
    EXPECT_GT(checked, 2000);
    EXPECT_GT(within, checked / 3);
    EXPECT_LT(within, 2 * checked / 3);
}

TEST(MarginCgal, ADirectionProvesOnlyPairsFartherApartThanTheMargin) {
    // narrow::separated_along certifies a direction whatever its source: the pair's own closest
    // direction, tilted a little or a lot, at margins around the distance.
    std::mt19937 rng(4547);
    std::uniform_real_distribution<double> tilt(-1.0, 1.0);
    int proven = 0, tried = 0;
    for (int n = 0; n < 200; ++n) {
        const float size = std::pow(10.0f, static_cast<float>(n % 13) - 6.0f);
        vec3 a[4], b[4];
        random_near_pair(rng, n, size, a, b);
        narrow::dvec3 da[4], db[4], on_a, on_b;
        for (int k = 0; k < 4; ++k) {
            da[k] = narrow::widen(a[k]);
            db[k] = narrow::widen(b[k]);
        }
        const double distance = narrow::disjoint_tets_distance(da, db, on_a, on_b);
        const HullSquaredDistance d = cgal_squared_distance(a, b);
        for (double amount : {0.0, 1e-12, 1e-6, 1e-2, 1.0}) {
            const narrow::dvec3 n_dir = (on_b - on_a) + narrow::dvec3{tilt(rng) * amount * distance,
                                                                      tilt(rng) * amount * distance,
                                                                      tilt(rng) * amount * distance};
            for (double fraction : {0.5, 0.999, 1.0 - 1e-9, 1.0, 1.0 + 1e-9}) {
                const float m = static_cast<float>(distance * fraction);
                const bool far = narrow::separated_along(narrow::margin_filter(a, b, m), a, b, n_dir);
                EXPECT_FALSE(far && oracle_within(d, m)) << "size " << size << " margin " << m << " tilt " << amount;
                proven += far;
                ++tried;
            }
        }
    }
    // The untilted direction proves the pairs at half their distance, and more (the test is not empty).
    EXPECT_GT(proven, tried / 5);
}

TEST(MarginCgal, ThePreTestsSeparateOnlyPairsFartherApartThanTheMargin) {
    // With a margin the face planes and the slabs reject the candidates they prove farther apart than
    // it (face_plane_reach, slabs.hpp): random pairs of sizes 1e-6..1e6, at margins from half their
    // distance to one float beyond it, wherever their boxes grown by the margin overlap (the only pairs
    // the pipeline pre-tests).
    std::mt19937 rng(4545);
    long long tried = 0, planes_separated = 0, slabs_separated = 0;
    for (int n = 0; n < 400; ++n) {
        const float size = std::pow(10.0f, static_cast<float>(n % 13) - 6.0f);
        vec3 a[4], b[4];
        test::random_nearby_tets(rng, size, a, b);
        const HullSquaredDistance d = cgal_squared_distance(a, b);
        const float distance = static_cast<float>(oracle_distance(d));
        const TetPlanes pa = tet_planes(a), pb = tet_planes(b);
        for (float m : {0.5f * distance, 0.9f * distance, 0.99f * distance, std::nextafter(distance, 0.0f), distance,
                        std::nextafter(distance, INFINITY)}) {
            if (!(m > 0.0f) || !boxes_overlap(grown_box(tet_box(a), half_margin(m)), grown_box(tet_box(b), half_margin(m))))
                continue;
            ++tried;
            const bool within = oracle_within(d, m);
            for (const bool a_first : {true, false}) {
                const bool separated = a_first ? face_plane_pretest(pa, a, pb, b, false, m) == PlaneVerdict::separated
                                               : face_plane_pretest(pb, b, pa, a, false, m) == PlaneVerdict::separated;
                EXPECT_FALSE(separated && within) << "planes, size " << size << " margin " << m << " distance " << distance;
                planes_separated += separated;
            }
            const bool slabs = slabs_separate(tet_slabs(a, pa.longest, m), tet_slabs(b, pb.longest, m));
            EXPECT_FALSE(slabs && within) << "slabs, size " << size << " margin " << m << " distance " << distance;
            slabs_separated += slabs;
        }
    }
    // Both pre-tests still reject pairs well beyond the margin (the assertions above are not empty).
    EXPECT_GT(tried, 800);
    EXPECT_GT(planes_separated, tried / 10);
    EXPECT_GT(slabs_separated, tried / 50);
}

TEST(MarginCgal, ARealMeshsPairsAndDistancesAreTheOracles) {
    const char* dir = std::getenv("KDET_DATA_DIR");
    if (!dir || !*dir) setenv("KDET_DATA_DIR", KDET_DEFAULT_DATA_DIR, 1);
    const TetMesh mesh = read_tet_mesh(data_path("octopus-low.mesh"));
    std::vector<vec3> p(mesh.num_vertices());
    for (std::size_t v = 0; v < p.size(); ++v)
        p[v] = {static_cast<float>(mesh.positions[3 * v]), static_cast<float>(mesh.positions[3 * v + 1]),
                static_cast<float>(mesh.positions[3 * v + 2])};
    const auto corners = [&](std::uint32_t t, vec3 out[4]) {
        for (int k = 0; k < 4; ++k) out[k] = p[mesh.tets[4 * t + k]];
    };
    const double* e0 = &mesh.positions[3 * mesh.tets[0]];
    const double* e1 = &mesh.positions[3 * mesh.tets[1]];
    const float margin = static_cast<float>(0.5 * std::sqrt((e0[0] - e1[0]) * (e0[0] - e1[0]) + (e0[1] - e1[1]) * (e0[1] - e1[1]) +
                                                            (e0[2] - e1[2]) * (e0[2] - e1[2])));
    DetectorOptions o;
    o.margin = margin;
    o.distances = true;
    Detector detector(o);
    detector.set_self_collision(detector.add_object(mesh), true);
    const FrameResult& r = detector.detect();
    std::set<std::pair<std::uint32_t, std::uint32_t>> reported;
    for (const TetPair& pair : r.pairs) reported.insert({pair.tet_a, pair.tet_b});
    // The oracle is slow: the distances of an even sample of the pairs.
    for (std::size_t k = 0; k < r.pairs.size(); k += 1 + r.pairs.size() / 300) {
        vec3 a[4], b[4];
        corners(r.pairs[k].tet_a, a);
        corners(r.pairs[k].tet_b, b);
        const double d = oracle_distance(cgal_squared_distance(a, b));
        EXPECT_NEAR(r.distances[k], d, 1e-6 * 4 * margin) << r.pairs[k].tet_a << " " << r.pairs[k].tet_b;
    }
    // Every pair of tets that share no vertex and whose boxes lie within the margin: by the oracle where
    // a double computation puts it within a thousandth of the margin, else by that computation.
    std::size_t judged = 0, by_oracle = 0;
    for (std::uint32_t i = 0; i < mesh.num_tets(); ++i)
        for (std::uint32_t j = i + 1; j < mesh.num_tets(); ++j) {
            bool shared = false;
            for (int x = 0; x < 4; ++x)
                for (int y = 0; y < 4; ++y) shared = shared || mesh.tets[4 * i + x] == mesh.tets[4 * j + y];
            if (shared) continue;
            vec3 a[4], b[4];
            corners(i, a);
            corners(j, b);
            const Aabb ba = tet_box(a), bb = tet_box(b);
            if (ba.lo.x - bb.hi.x > margin || bb.lo.x - ba.hi.x > margin || ba.lo.y - bb.hi.y > margin ||
                bb.lo.y - ba.hi.y > margin || ba.lo.z - bb.hi.z > margin || bb.lo.z - ba.hi.z > margin)
                continue;
            d3 da[4], db[4];
            widen(a, da);
            widen(b, db);
            narrow::dvec3 wa[4], wb[4], x, y;
            for (int k = 0; k < 4; ++k) {
                wa[k] = {da[k].x, da[k].y, da[k].z};
                wb[k] = {db[k].x, db[k].y, db[k].z};
            }
            bool exact_stage = false;
            const double d = tets_intersect(NarrowPhase::exact, a, b, exact_stage) ? 0.0 : narrow::disjoint_tets_distance(wa, wb, x, y);
            const bool near = std::fabs(d - margin) < 1e-3 * margin;
            const bool expected = near ? oracle_within(cgal_hull_distance(da, db), margin) : d <= margin;
            EXPECT_EQ(reported.count({i, j}) != 0, expected) << i << " " << j << " distance " << d;
            ++judged;
            by_oracle += near;
        }
    EXPECT_GT(judged, r.pairs.size());
    EXPECT_GT(by_oracle, 0u);
    EXPECT_GT(r.pairs.size(), 0u);
}

} // namespace
} // namespace kdet
