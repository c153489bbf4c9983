/// @file test_margin.cpp
/// @brief Pairs within a margin (DetectorOptions::margin) and their distances: pairs built at a known
/// float distance reported at that margin and not one float below it, at sizes from 2^-20 to 2^20;
/// every method the same set as brute force; distances and closest points against the construction
/// and a double reference; the CUDA backend bit for bit as the CPU's. tests/cgal/test_margin_cgal.cpp
/// holds the exact oracle.

#include "nearby_tets.hpp"
#include "test_support.hpp"

#include "geometry/tet_distance.hpp"
#include "geometry/tet_intersect.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/option_table.hpp>

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace kdet {
namespace {

using Tet = std::vector<float>; ///< 12 coordinates

TetMesh mesh_of(const std::vector<Tet>& tets) {
    TetMesh m;
    for (const Tet& t : tets) {
        for (float c : t) m.positions.push_back(c);
        const auto base = static_cast<std::uint32_t>(m.tets.size());
        for (std::uint32_t k = 0; k < 4; ++k) m.tets.push_back(base + k);
    }
    return m;
}

Tet scaled(const Tet& t, float s) {
    Tet out = t;
    for (float& c : out) c *= s;
    return out;
}

const Method every_method[] = {Method::kdet, Method::brute_force_loop, Method::brute_force_pairs};

FrameResult detect_pair(const std::vector<Tet>& a, const std::vector<Tet>& b, DetectorOptions options) {
    Detector d(options);
    d.add_object(mesh_of(a));
    d.add_object(mesh_of(b));
    return d.detect();
}

/// A case built at a known distance: tet a, tet b, the distance (a float), the closest points.
struct KnownCase {
    const char* name;
    Tet a, b;
    float distance;
    float on_a[3], on_b[3];
};

/// Tets whose distance is the float h by construction (every coordinate exact in float).
std::vector<KnownCase> known_cases(float h) {
    std::vector<KnownCase> cases;
    // Parallel faces: a's face on z = 0, b's on z = h, overlapping in x and y.
    cases.push_back({"parallel faces", {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.25f, 0.25f, -1},
                     {0.125f, 0.125f, h, 1.125f, 0.125f, h, 0.125f, 1.125f, h, 0.25f, 0.25f, h + 1}, h,
                     {0.125f, 0.125f, 0}, {0.125f, 0.125f, h}});
    // Crossed edges: a's top edge along x at z = 0, b's bottom edge along y at z = h.
    cases.push_back({"crossed edges", {-1, 0, 0, 1, 0, 0, 0, 1, -1, 0, -1, -1},
                     {0, -1, h, 0, 1, h, 1, 0, h + 1, -1, 0, h + 1}, h, {0, 0, 0}, {0, 0, h}});
    // Vertex over a face: b's lowest vertex above a's face z = 0.
    cases.push_back({"vertex and face", {-2, -2, 0, 2, -2, 0, 0, 2, 0, 0, 0, -1},
                     {0.25f, 0.25f, h, 1, 0.25f, h + 1, 0.25f, 1, h + 1, 0.5f, 0.5f, h + 2}, h,
                     {0.25f, 0.25f, 0}, {0.25f, 0.25f, h}});
    // Vertex and vertex along (3, 4, 0) / 5: distance 5 t, t = h / 5 rounded to 18 bits after the point
    // so that 3 t, 4 t and 5 t are exact.
    const float t = std::ldexp(std::round(std::ldexp(h / 5, 18)), -18);
    cases.push_back({"vertices 3-4-5", {0, 0, 0, -1, 0, 0, 0, -1, 0, 0, 0, -1},
                     {3 * t, 4 * t, 0, 3 * t + 1, 4 * t, 0, 3 * t, 4 * t + 1, 0, 3 * t, 4 * t, 1}, 5 * t,
                     {0, 0, 0}, {3 * t, 4 * t, 0}});
    // A slanted face (normal (3, 4, 0) / 5) and a vertex 5 t in front of it: degree-6 polynomials.
    cases.push_back({"slanted face", {4, -3, 0, -4, 3, 0, 0, 0, 2, -1.5f, -2, 0},
                     {3 * t, 4 * t, 0.5f, 3 * t + 3, 4 * t + 4, 0.5f, 3 * t + 3, 4 * t + 4, 1.5f, 3 * t + 4, 4 * t + 1, 0.5f},
                     5 * t, {0, 0, 0.5f}, {3 * t, 4 * t, 0.5f}});
    // A sliver (four points in one plane, z = 0) under a vertex.
    cases.push_back({"sliver", {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0},
                     {0.5f, 0.5f, h, 1, 0.5f, h + 1, 0.5f, 1, h + 1, 0.75f, 0.75f, h + 2}, h, {0.5f, 0.5f, 0},
                     {0.5f, 0.5f, h}});
    return cases;
}

TEST(Margin, PairsAtTheMarginAreReportedAndOneFloatFurtherAreNot) {
    for (int exponent : {-20, -7, 0, 9, 20}) {
        const float s = std::ldexp(1.0f, exponent);
        for (float h : {0.1f, 0.375f, 1.0f / 3.0f}) {
            for (const KnownCase& c0 : known_cases(h)) {
                const KnownCase c{c0.name, scaled(c0.a, s), scaled(c0.b, s), c0.distance * s, {}, {}};
                SCOPED_TRACE(std::string(c.name) + " at 2^" + std::to_string(exponent) + ", h " + std::to_string(h));
                for (Method method : every_method) {
                    DetectorOptions o;
                    o.method = method;
                    o.margin = c.distance;
                    EXPECT_EQ(detect_pair({c.a}, {c.b}, o).pairs.size(), 1u) << to_string(method);
                    o.margin = std::nextafter(c.distance, 0.0f);
                    EXPECT_EQ(detect_pair({c.a}, {c.b}, o).pairs.size(), 0u) << to_string(method);
                    o.margin = std::nextafter(c.distance, std::numeric_limits<float>::infinity());
                    EXPECT_EQ(detect_pair({c.a}, {c.b}, o).pairs.size(), 1u) << to_string(method);
                }
                DetectorOptions flags;
                flags.method = Method::kdet_no_pairs;
                flags.margin = c.distance;
                EXPECT_EQ(detect_pair({c.a}, {c.b}, flags).colliding[0][0], 1);
                flags.margin = std::nextafter(c.distance, 0.0f);
                EXPECT_EQ(detect_pair({c.a}, {c.b}, flags).colliding[0][0], 0);
            }
        }
    }
}

TEST(Margin, DistancesAndClosestPointsMatchTheConstruction) {
    for (int exponent : {-20, 0, 20}) {
        const float s = std::ldexp(1.0f, exponent);
        for (const KnownCase& c : known_cases(0.375f)) {
            SCOPED_TRACE(c.name);
            DetectorOptions o;
            o.margin = 2 * c.distance * s;
            o.distances = true;
            const FrameResult r = detect_pair({scaled(c.a, s)}, {scaled(c.b, s)}, o);
            ASSERT_EQ(r.distances.size(), 1u);
            ASSERT_EQ(r.closest_points.size(), 1u);
            // Stated tolerance: 1e-6 of the pair's size (about 1), in double rounded to float.
            const float tolerance = 1e-6f * 4 * s;
            EXPECT_NEAR(r.distances[0], c.distance * s, tolerance);
            const ClosestPoints& p = r.closest_points[0];
            float gap = 0;
            for (int k = 0; k < 3; ++k) gap += (p.on_b[k] - p.on_a[k]) * (p.on_b[k] - p.on_a[k]);
            EXPECT_NEAR(std::sqrt(gap), c.distance * s, tolerance);
            // Parallel faces have many closest pairs; the others one.
            if (std::string(c.name) != "parallel faces" && std::string(c.name) != "sliver")
                for (int k = 0; k < 3; ++k) {
                    EXPECT_NEAR(p.on_a[k], c.on_a[k] * s, tolerance);
                    EXPECT_NEAR(p.on_b[k], c.on_b[k] * s, tolerance);
                }
        }
    }
}

TEST(Margin, IntersectingAndTouchingPairsHaveDistanceZeroAndACommonPoint) {
    // b shares a's vertex position (not its index: another object), and c overlaps a deeply.
    const Tet a = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const Tet b = {1, 0, 0, 2, 0, 0, 1, 1, 0, 1, 0, 1};
    const Tet c = {0.1f, 0.1f, 0.1f, 1.1f, 0.1f, 0.1f, 0.1f, 1.1f, 0.1f, 0.1f, 0.1f, 1.1f};
    DetectorOptions o;
    o.margin = 0.5f;
    o.distances = true;
    o.contacts = true;
    const FrameResult r = detect_pair({a}, {b, c}, o);
    ASSERT_EQ(r.pairs.size(), 2u);
    ASSERT_EQ(r.distances.size(), 2u);
    ASSERT_EQ(r.contacts.size(), 2u);
    for (std::size_t k = 0; k < 2; ++k) {
        EXPECT_EQ(r.distances[k], 0.0f);
        const ClosestPoints& p = r.closest_points[k];
        for (int i = 0; i < 3; ++i) EXPECT_EQ(p.on_a[i], p.on_b[i]);
        // The common point lies in a (x, y, z >= 0, sum <= 1) up to rounding.
        EXPECT_GE(std::min({p.on_a[0], p.on_a[1], p.on_a[2]}), -1e-6f);
        EXPECT_LE(p.on_a[0] + p.on_a[1] + p.on_a[2], 1.0f + 1e-6f);
    }
    EXPECT_EQ(r.pairs[0].tet_b, 0u);
    EXPECT_EQ(r.pairs[1].tet_b, 1u);
    EXPECT_GT(r.contacts[1].depth, 0.0f); // the overlapping pair keeps its depth
}

TEST(Margin, TheCommonPointOfAPairWithATetWithoutVolumeLiesOnIt) {
    // Regression (found by python/tests/test_properties_margin.py): a point tet, or a flat one, inside a
    // tet took the other tet's vertex as the common point, since every point read as inside a tet
    // without volume (all its orientations 0).
    const Tet big = {-1, -1, -1, 3, -1, -1, -1, 3, -1, -1, -1, 3};
    const Tet point = {0.25f, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f};
    const Tet flat = {0, 0, 0.5f, 0.5f, 0, 0.5f, 0, 0.5f, 0.5f, 0.25f, 0.25f, 0.5f};
    DetectorOptions o;
    o.distances = true;
    for (const bool big_first : {true, false}) {
        const FrameResult with_point = big_first ? detect_pair({big}, {point}, o) : detect_pair({point}, {big}, o);
        ASSERT_EQ(with_point.pairs.size(), 1u);
        for (int i = 0; i < 3; ++i) {
            EXPECT_EQ(with_point.closest_points[0].on_a[i], 0.25f) << big_first;
            EXPECT_EQ(with_point.closest_points[0].on_b[i], 0.25f) << big_first;
        }
        const FrameResult with_flat = big_first ? detect_pair({big}, {flat}, o) : detect_pair({flat}, {big}, o);
        ASSERT_EQ(with_flat.pairs.size(), 1u);
        const ClosestPoints& p = with_flat.closest_points[0];
        EXPECT_EQ(p.on_a[2], 0.5f) << big_first;
        EXPECT_GE(std::min(p.on_a[0], p.on_a[1]), 0.0f) << big_first;
        EXPECT_LE(p.on_a[0] + p.on_a[1], 0.5f) << big_first;
    }
}

/// The set of pairs of `result` as (a, b) global-ish keys.
std::set<std::pair<std::uint64_t, std::uint64_t>> pair_set(const FrameResult& result) {
    std::set<std::pair<std::uint64_t, std::uint64_t>> s;
    for (const TetPair& p : result.pairs)
        s.insert({(std::uint64_t{p.object_a} << 32) | p.tet_a, (std::uint64_t{p.object_b} << 32) | p.tet_b});
    return s;
}

/// Every method on the same objects, self-collision on, at `margin`: the same pairs as brute force,
/// and kdet_no_pairs flags the tets of those pairs.
FrameResult expect_methods_agree(const std::vector<TetMesh>& meshes, float margin, bool distances = false) {
    FrameResult reference;
    for (Method method : {Method::brute_force_pairs, Method::brute_force_loop, Method::kdet, Method::kdet_no_pairs}) {
        DetectorOptions o;
        o.method = method;
        o.margin = margin;
        o.distances = distances && method != Method::kdet_no_pairs;
        Detector d(o);
        for (const TetMesh& m : meshes) d.set_self_collision(d.add_object(m), true);
        const FrameResult r = d.detect();
        if (method == Method::brute_force_pairs) {
            reference = r;
            continue;
        }
        if (method == Method::kdet_no_pairs) {
            EXPECT_EQ(r.colliding, reference.colliding);
            continue;
        }
        EXPECT_EQ(r.pairs, reference.pairs) << to_string(method) << " at margin " << margin;
        EXPECT_EQ(r.distances, reference.distances) << to_string(method);
    }
    return reference;
}

/// The distance of two tets of a result's objects from the library's double computation, for the
/// brute-force check of a soup: independent of the exact decision it checks.
double approximate_distance(const TetMesh& ma, std::uint32_t ta, const TetMesh& mb, std::uint32_t tb) {
    vec3 a[4], b[4];
    for (int k = 0; k < 4; ++k) {
        const double* p = &ma.positions[3 * ma.tets[4 * ta + k]];
        const double* q = &mb.positions[3 * mb.tets[4 * tb + k]];
        a[k] = vec3{static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])};
        b[k] = vec3{static_cast<float>(q[0]), static_cast<float>(q[1]), static_cast<float>(q[2])};
    }
    narrow::dvec3 da[4], db[4], x, y;
    for (int k = 0; k < 4; ++k) {
        da[k] = narrow::widen(a[k]);
        db[k] = narrow::widen(b[k]);
    }
    bool exact_stage = false;
    if (tets_intersect(NarrowPhase::exact, a, b, exact_stage)) return 0.0;
    return narrow::disjoint_tets_distance(da, db, x, y);
}

TEST(Margin, GjkFindsTheClosestFeaturesThatTryingEveryPairFinds) {
    // The margin's decision takes GJK's closest points and feature pair first: their distance is the
    // exhaustive one's, the pair's conditions hold just beyond it and its direction proves the tets
    // apart just below it, at sizes 1e-6..1e6, with parallel faces and flat tets among them.
    std::mt19937 rng(49);
    int found = 0, tried = 0;
    for (int n = 0; n < 2000; ++n) {
        const float size = std::pow(10.0f, static_cast<float>(n % 13) - 6.0f);
        vec3 a[4], b[4];
        test::random_nearby_tets(rng, size, a, b);
        if (n % 5 == 1) b[3] = {(b[0].x + b[1].x) / 2, (b[0].y + b[1].y) / 2, (b[0].z + b[1].z) / 2};
        if (n % 7 == 3) // b's face 3 parallel to a's face 3, shifted along x
            for (int k = 0; k < 3; ++k) b[k] = {a[k].x + 2.5f * size, a[k].y + 0.25f * size, a[k].z};
        bool exact_stage = false;
        if (tets_intersect(NarrowPhase::exact, a, b, exact_stage)) continue;
        ++tried;
        narrow::dvec3 da[4], db[4], x, y, gx, gy;
        for (int k = 0; k < 4; ++k) {
            da[k] = narrow::widen(a[k]);
            db[k] = narrow::widen(b[k]);
        }
        narrow::ClosestFeatures every{}, gjk{};
        const double d = std::sqrt(narrow::closest_features(da, db, x, y, every));
        narrow::MinkowskiSimplex simplex;
        if (!narrow::gjk_closest_points(da, db, gx, gy, simplex) || !narrow::simplex_features(simplex, gjk)) continue;
        ++found;
        const narrow::dvec3 gap = gy - gx;
        const double gd = std::sqrt(narrow::dot(gap, gap));
        EXPECT_NEAR(gd, d, 1e-9 * size) << n;
        const float beyond = static_cast<float>(d * (1.0 + 1e-6)), below = static_cast<float>(d * (1.0 - 1e-6));
        const narrow::ExactMaker exact{beyond};
        EXPECT_TRUE(narrow::features_within(narrow::margin_filter(a, b, beyond), exact, a, b, gjk)) << n << " kind " << gjk.kind;
        EXPECT_TRUE(narrow::features_within(narrow::margin_filter(a, b, beyond), exact, a, b, every)) << n;
        EXPECT_TRUE(narrow::separated_along(narrow::margin_filter(a, b, below), a, b, gap)) << n;
        EXPECT_FALSE(narrow::separated_along(narrow::margin_filter(a, b, beyond), a, b, gap)) << n;
    }
    EXPECT_GT(tried, 1500);
    EXPECT_GT(found, tried * 99 / 100);
}

TEST(Margin, GjkFindsTheClosestPointsOfARealMeshsNearPairs) {
    // A mesh's pairs within a margin hold many nearly coplanar features (neighbours' neighbours), where
    // GJK's simplex turns flat: every such pair's GJK distance is the exhaustive one's.
    const TetMesh m = test::load_model("bunny.mesh");
    DetectorOptions o;
    o.margin = 0.001f;
    Detector d(o);
    d.set_self_collision(d.add_object(m), true);
    const FrameResult r = d.detect();
    ASSERT_GT(r.pairs.size(), 10000u);
    std::size_t compared = 0;
    for (const TetPair& pair : r.pairs) {
        narrow::dvec3 a[4], b[4], x, y, gx, gy;
        vec3 fa[4], fb[4];
        for (int k = 0; k < 4; ++k) {
            const double* p = &m.positions[3 * m.tets[4 * pair.tet_a + k]];
            const double* q = &m.positions[3 * m.tets[4 * pair.tet_b + k]];
            fa[k] = vec3{static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])};
            fb[k] = vec3{static_cast<float>(q[0]), static_cast<float>(q[1]), static_cast<float>(q[2])};
            a[k] = narrow::widen(fa[k]);
            b[k] = narrow::widen(fb[k]);
        }
        bool exact_stage = false;
        if (tets_intersect(NarrowPhase::exact, fa, fb, exact_stage)) continue;
        narrow::ClosestFeatures features{};
        narrow::MinkowskiSimplex simplex;
        const double every = std::sqrt(narrow::closest_features(a, b, x, y, features));
        if (!narrow::gjk_closest_points(a, b, gx, gy, simplex)) continue;
        EXPECT_NEAR(std::sqrt(narrow::squared_distance(gx, gy)), every, 1e-9) << pair.tet_a << " " << pair.tet_b;
        ++compared;
    }
    EXPECT_GT(compared, r.pairs.size() * 9 / 10);
}

TEST(Margin, EveryMethodFindsTheSamePairsInSoupsAndTheyLieWithinTheMargin) {
    const TetMesh a = test::random_soup(250, 4.0, 2.0, 7), b = test::random_soup(250, 4.0, 2.0, 8);
    for (float margin : {0.0f, 0.01f, 0.1f, 0.6f}) {
        const FrameResult r = expect_methods_agree({a, b}, margin, true);
        // Brute force in double over every pair of different objects: reported pairs lie within the
        // margin, the others beyond it, both up to the double computation's error.
        const auto reported = pair_set(r);
        std::size_t checked = 0;
        for (std::uint32_t i = 0; i < a.num_tets(); ++i)
            for (std::uint32_t j = 0; j < b.num_tets(); ++j) {
                const double d = approximate_distance(a, i, b, j);
                const bool in = reported.count({i, (std::uint64_t{1} << 32) | j}) != 0;
                if (std::fabs(d - margin) < 1e-5) continue;
                EXPECT_EQ(in, d <= margin) << i << " " << j << " distance " << d << " margin " << margin;
                ++checked;
            }
        EXPECT_GT(checked, 0u);
        for (std::size_t k = 0; k < r.pairs.size(); ++k) EXPECT_LE(r.distances[k], margin * (1 + 1e-5f) + 1e-6f);
    }
}

// The pairs found apart, which the margin's kernel decides afterwards, outgrow a candidate buffer of
// one slot (kdet_no_pairs keeps them there, the brute-force methods pass them all as candidates): the
// frame grows it and runs again, losing none.
TEST(Margin, PairsLeftToTheMarginOutgrowingTheirBufferAreAllDecided) {
    const TetMesh a = test::random_soup(200, 4.0, 2.0, 11), b = test::random_soup(200, 4.0, 2.0, 12);
    for (Method method : {Method::kdet, Method::kdet_no_pairs, Method::brute_force_loop, Method::brute_force_pairs}) {
        FrameResult results[2];
        for (int tiny = 0; tiny < 2; ++tiny) {
            DetectorOptions o;
            o.method = method;
            o.margin = 0.3f;
            o.initial_candidate_capacity = tiny ? 1 : 0;
            Detector d(o);
            d.add_object(a);
            d.add_object(b);
            results[tiny] = d.detect();
        }
        EXPECT_EQ(results[1].pairs, results[0].pairs) << to_string(method);
        EXPECT_EQ(results[1].colliding, results[0].colliding) << to_string(method);
        EXPECT_GT(results[0].counts.colliding_tets, 0u) << to_string(method);
        EXPECT_GT(results[1].counts.buffer_regrows, 0u) << to_string(method);
    }
}

TEST(Margin, AtZeroTheResultIsTodays) {
    const TetMesh m = test::load_model("octopus-low.mesh");
    const TetMesh moved = test::moved(m, 0.3, 0.05 * test::extent_of(m), 0.0, 0.0);
    DetectorOptions zero;
    zero.margin = 0.0f;
    Detector today, with_zero(zero);
    for (Detector* d : {&today, &with_zero}) {
        d->set_self_collision(d->add_object(m), true);
        d->add_object(moved);
    }
    const FrameResult& expected = today.detect();
    EXPECT_FALSE(expected.pairs.empty());
    EXPECT_EQ(with_zero.detect().pairs, expected.pairs);
}

TEST(Margin, RealMeshSelfCollisionUpToTwiceTheEdge) {
    const TetMesh m = test::load_model("octopus-low.mesh");
    // A typical edge of the mesh: its first tet's first edge.
    const double* p = &m.positions[3 * m.tets[0]];
    const double* q = &m.positions[3 * m.tets[1]];
    const double edge = std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
    std::size_t previous = 0;
    for (double share : {0.01, 0.1, 2.0}) {
        const FrameResult r = expect_methods_agree({m}, static_cast<float>(share * edge));
        EXPECT_GT(r.pairs.size(), previous) << "a larger margin keeps every pair and adds some";
        previous = r.pairs.size();
    }
}

TEST(Margin, TheOptionIsCheckedEverywhere) {
    for (float bad : {-1.0f, std::nanf(""), std::numeric_limits<float>::infinity()}) {
        DetectorOptions o;
        o.margin = bad;
        EXPECT_NE(test::error_message([&] { Detector d(o); }).find("margin"), std::string::npos);
    }
    const OptionInfo* margin = find_option("margin");
    ASSERT_NE(margin, nullptr);
    DetectorOptions o;
    margin->parse("0.25", o, "--margin");
    EXPECT_EQ(o.margin, 0.25f);
    EXPECT_EQ(margin->text(o), "0.25");
    for (const char* bad : {"-1", "nan", "inf", "1e39", "x", "", "0.5m"})
        EXPECT_EQ(test::error_message([&] { margin->parse(bad, o, "--margin"); }),
                  std::string("invalid value '") + bad + "' for --margin: expected a finite number >= 0");
    EXPECT_EQ(test::error_message([&] { margin->set_real(o, -2.0); }), "margin: expected a finite number >= 0, got -2");
    EXPECT_EQ(o.margin, 0.25f) << "a refused value leaves the options as they were";
}

#ifdef KDET_CLI_PATH
/// `kdet ARGUMENTS` with its output in `out_file`; returns the exit code.
int run_kdet(const std::string& arguments, const std::string& out_file) {
    const int status = std::system((std::string(KDET_CLI_PATH) + " " + arguments + " > " + out_file + " 2>&1").c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::vector<std::string> lines_of(const std::string& path) {
    std::ifstream in(path);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

TEST(Margin, CollideWritesPairsAndDistancesWithinTheMargin) {
    test::use_default_data_dir();
    const std::string mesh = data_path("octopus-low.mesh");
    const std::string dir = ::testing::TempDir();
    const std::string pairs = dir + "margin_pairs.txt", distances = dir + "margin_distances.txt", out = dir + "margin_out.txt";
    ASSERT_EQ(run_kdet("collide " + mesh + " --self --margin 0.05 --pairs " + pairs + " --distances " + distances, out), 0);
    const std::vector<std::string> pair_lines = lines_of(pairs), distance_lines = lines_of(distances);
    ASSERT_EQ(pair_lines.size(), distance_lines.size());
    ASSERT_FALSE(pair_lines.empty());
    for (std::size_t k = 0; k < pair_lines.size(); ++k) {
        std::istringstream fields(distance_lines[k]);
        std::uint32_t i, j;
        double distance, point[6];
        ASSERT_TRUE(fields >> i >> j >> distance >> point[0] >> point[1] >> point[2] >> point[3] >> point[4] >> point[5]);
        EXPECT_LT(i, j);
        EXPECT_EQ(pair_lines[k], std::to_string(i) + " " + std::to_string(j));
        EXPECT_GE(distance, 0.0);
        EXPECT_LE(distance, 0.05 * (1 + 1e-6));
    }
    const std::vector<std::string> printed = lines_of(out);
    EXPECT_NE(std::find(printed.begin(), printed.end(), "margin            0.05"), printed.end());
    for (const char* bad : {"-1", "nan", "inf", "x"}) {
        EXPECT_EQ(run_kdet("collide " + mesh + " --self --margin " + bad, out), 2) << bad;
        EXPECT_EQ(lines_of(out), std::vector<std::string>{std::string("kdet collide: invalid value '") + bad +
                                                          "' for --margin: expected a finite number >= 0"});
    }
}
#endif

TEST(Margin, CudaMatchesTheCpuBitForBit) {
    std::string reason;
    if (!cuda_available(&reason)) GTEST_SKIP() << "CUDA backend not tested: " << reason;
    const TetMesh a = test::random_soup(1500, 4.0, 2.0, 17), b = test::random_soup(1500, 4.0, 2.0, 18);
    for (Method method : {Method::kdet, Method::kdet_no_pairs, Method::brute_force_loop, Method::brute_force_pairs})
        for (float margin : {0.0f, 0.02f, 0.3f}) {
            FrameResult results[2];
            for (Backend backend : {Backend::cpu, Backend::cuda}) {
                DetectorOptions o;
                o.backend = backend;
                o.method = method;
                o.margin = margin;
                o.distances = method != Method::kdet_no_pairs;
                o.contacts = o.distances;
                Detector d(o);
                d.set_self_collision(d.add_object(a), true);
                d.add_object(b);
                results[backend == Backend::cuda] = d.detect();
            }
            const FrameResult &cpu = results[0], &cuda = results[1];
            EXPECT_EQ(cuda.pairs, cpu.pairs) << to_string(method) << " " << margin;
            EXPECT_EQ(cuda.colliding, cpu.colliding);
            EXPECT_EQ(cuda.distances, cpu.distances);
            ASSERT_EQ(cuda.closest_points.size(), cpu.closest_points.size());
            EXPECT_EQ(std::memcmp(cuda.closest_points.data(), cpu.closest_points.data(),
                                  cpu.closest_points.size() * sizeof(ClosestPoints)),
                      0);
        }
}

} // namespace
} // namespace kdet
