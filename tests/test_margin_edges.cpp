/// @file test_margin_edges.cpp
/// @brief Margins and query points at the ends of float32 (issue 48): pairs built at a float distance
/// from subnormal to near the largest float, and far from the origin, are reported at their distance and
/// not one float below it by every method; margins up to the largest float hold exactly the pairs within
/// them; points at subnormal coordinates and near the largest float are located exactly, with `within`
/// from subnormal to beyond float's range; refused values name the argument and its range in one line.
/// The CUDA backend gives the CPU's answers to the bit (skipped without a GPU).

#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/locate.hpp>

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace kdet::test {
namespace {

constexpr float largest = std::numeric_limits<float>::max();
constexpr float smallest = std::numeric_limits<float>::denorm_min();

/// A tet given as four points, each exactly a float (checked): the pair's distance is then the
/// construction's, with nothing rounded.
TetMesh exact_tet(const std::vector<double>& xyz) {
    for (const double c : xyz) EXPECT_EQ(static_cast<double>(static_cast<float>(c)), c) << "not a float: " << c;
    return TetMesh{xyz, {0, 1, 2, 3}};
}

/// The float nearest x, for coordinates whose rounding moves no feature that the distance depends on.
double rounded(double x) { return static_cast<float>(x); }

/// Two tets a float distance h apart, at scale s around z0 (parallel faces) or (crossed edges).
struct BuiltPair {
    const char* name;
    TetMesh a, b;
    float h;
};

BuiltPair parallel_faces(double z0, double s, double h) {
    return {"parallel faces", exact_tet({0, 0, z0, s, 0, z0, 0, s, z0, s / 4, s / 4, z0 - s}),
            exact_tet({s / 8, s / 8, z0 + h, s + s / 8, s / 8, z0 + h, s / 8, s + s / 8, z0 + h, s / 4, s / 4, rounded(z0 + h + s)}),
            static_cast<float>(h)};
}

BuiltPair crossed_edges(double z0, double s, double h) {
    return {"crossed edges", exact_tet({-s, 0, z0, s, 0, z0, 0, s / 2, z0 - s, 0, -s / 2, z0 - s}),
            exact_tet({0, -s, z0 + h, 0, s, z0 + h, s / 2, 0, rounded(z0 + h + s), -s / 2, 0, rounded(z0 + h + s)}),
            static_cast<float>(h)};
}

/// The pairs built at the ends: subnormal distances, 1e-30, sizes down to subnormal coordinates and up
/// to the largest float, and far from the origin where a float's step is 2^104.
std::vector<BuiltPair> built_pairs() {
    std::vector<BuiltPair> pairs;
    for (auto* build : {&parallel_faces, &crossed_edges}) {
        pairs.push_back(build(0, 1, smallest));
        pairs.push_back(build(0, 1, static_cast<double>(1e-30f)));
        pairs.push_back(build(0, 0x1p-100, 0x1p-120));
        pairs.push_back(build(0, 0x1p-140, 0x1p-149));
        pairs.push_back(build(0, 0x1p100, 0x1p90));
        pairs.push_back(build(0, 0x1p126, 0x1p120));
        pairs.push_back(build(0x1p127, 0x1p110, 0x1p104));
        pairs.push_back(build(-0x3p126, 0x1p112, 0x1p105));
        pairs.push_back(build(1e7, 1, 1)); // where a float's step is 1
    }
    return pairs;
}

FrameResult detect_at(const TetMesh& a, const TetMesh& b, float margin, Method method, Backend backend = Backend::cpu) {
    DetectorOptions options;
    options.method = method;
    options.margin = margin;
    options.distances = method != Method::kdet_no_pairs;
    options.backend = backend;
    Detector detector(options);
    detector.add_object(a);
    detector.add_object(b);
    return detector.detect();
}

const Method every_method[] = {Method::kdet, Method::kdet_no_pairs, Method::brute_force_loop, Method::brute_force_pairs};

/// Whether the result holds the one pair of two one-tet objects (its pairs, or both flags).
bool has_the_pair(const FrameResult& r, Method method) {
    if (method != Method::kdet_no_pairs) return r.pairs.size() == 1;
    return r.colliding.at(0).at(0) && r.colliding.at(1).at(0);
}

TEST(MarginEdges, PairsAtTheEndsOfFloatAreReportedAtTheirDistanceAndNotOneFloatBelow) {
    for (const BuiltPair& p : built_pairs()) {
        const std::string name = std::string(p.name) + " h " + std::to_string(p.h);
        for (const Method method : every_method) {
            const FrameResult at = detect_at(p.a, p.b, p.h, method);
            ASSERT_TRUE(has_the_pair(at, method)) << name << " " << to_string(method);
            EXPECT_FALSE(has_the_pair(detect_at(p.a, p.b, std::nextafter(p.h, 0.0f), method), method))
                << name << " " << to_string(method);
            EXPECT_TRUE(has_the_pair(detect_at(p.a, p.b, largest, method), method)) << name << " " << to_string(method);
            if (method == Method::kdet_no_pairs) continue;
            // The distance within a float step or two of h (rounded from double), never beyond the margin's
            // next float either way.
            EXPECT_NEAR(at.distances.at(0), p.h, 2.0f * (std::nextafter(p.h, largest) - p.h)) << name;
        }
    }
}

/// Tets of two far corners: `a` near (-x, -x, -x), `b` near (x, x, x), each of extent s.
BuiltPair far_corners(double x, double s) {
    return {"far corners", exact_tet({-x, -x, -x, -x - s, -x, -x, -x, -x - s, -x, -x, -x, -x - s}),
            exact_tet({x, x, x, x + s, x, x, x, x + s, x, x, x, x + s}), 0.0f};
}

TEST(MarginEdges, HugeMarginsHoldExactlyThePairsWithinThem) {
    // Vertex to vertex along the diagonal: 2x sqrt(3) apart. At x = 2^125 that is about 1.5e38, within the
    // largest float; at x = 1.25 * 2^126 about 3.7e38, beyond it: no float margin holds the pair.
    const BuiltPair near_pair = far_corners(0x1p125, 0x1p120), beyond = far_corners(0x1.4p126, 0x1p120);
    const double near_distance = 2.0 * 0x1p125 * std::sqrt(3.0);
    const float below = static_cast<float>(near_distance * (1 - 1e-6)), above = static_cast<float>(near_distance * (1 + 1e-6));
    for (const Method method : every_method) {
        EXPECT_TRUE(has_the_pair(detect_at(near_pair.a, near_pair.b, largest, method), method)) << to_string(method);
        EXPECT_TRUE(has_the_pair(detect_at(near_pair.a, near_pair.b, above, method), method)) << to_string(method);
        EXPECT_FALSE(has_the_pair(detect_at(near_pair.a, near_pair.b, below, method), method)) << to_string(method);
        EXPECT_FALSE(has_the_pair(detect_at(beyond.a, beyond.b, largest, method), method)) << to_string(method);
    }
    // A soup at scale 1 under a margin of 1e30 and of the largest float: every pair of the two objects.
    const TetMesh a = random_soup(40, 4.0, 2.0, 11), b = random_soup(30, 4.0, 2.0, 12);
    for (const float margin : {1e30f, largest})
        for (const Method method : every_method) {
            const FrameResult r = detect_at(a, b, margin, method);
            if (method != Method::kdet_no_pairs) {
                EXPECT_EQ(r.pairs.size(), 40u * 30u) << to_string(method) << " margin " << margin;
            }
            for (const auto& flags : r.colliding)
                for (const std::uint8_t f : flags) EXPECT_TRUE(f) << to_string(method);
        }
}

TEST(MarginEdges, MarginsWithCoordinatesNearTheLargestFloatGiveBruteForcePairs) {
    // Tets with coordinates up to 3e38 of both signs (edges that no float holds) beside small ones: every
    // method gives brute force's pairs at margins up to the largest float, with distances within them.
    std::mt19937 rng(48);
    std::uniform_real_distribution<double> huge(-3e38, 3e38), unit(0.0, 1.0);
    TetMesh large, small;
    for (std::uint32_t t = 0; t < 24; ++t) {
        for (int k = 0; k < 12; ++k) large.positions.push_back(static_cast<float>(huge(rng)));
        for (int k = 0; k < 12; ++k) small.positions.push_back(static_cast<float>(1e37 * (unit(rng) + (k % 3 == 0 ? t : 0))));
        for (std::uint32_t k = 0; k < 4; ++k) {
            large.tets.push_back(4 * t + k);
            small.tets.push_back(4 * t + k);
        }
    }
    for (const float margin : {1e36f, 1e37f, 1e38f, largest}) {
        const FrameResult reference = detect_at(large, small, margin, Method::brute_force_pairs);
        EXPECT_GT(reference.pairs.size(), 0u);
        for (const float d : reference.distances) EXPECT_LE(d, margin * (1 + 1e-6f)); // rounded from double
        for (const Method method : {Method::kdet, Method::brute_force_loop}) {
            const FrameResult r = detect_at(large, small, margin, method);
            EXPECT_EQ(r.pairs, reference.pairs) << to_string(method) << " margin " << margin;
            EXPECT_EQ(r.distances, reference.distances) << to_string(method) << " margin " << margin;
        }
        EXPECT_EQ(detect_at(large, small, margin, Method::kdet_no_pairs).colliding, reference.colliding) << margin;
    }
}

TEST(MarginEdges, RefusedMarginsNameTheOptionAndTheRange) {
    for (const float bad : {-smallest, -largest, -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity()}) {
        DetectorOptions options;
        options.margin = bad;
        const std::string message = error_message([&] { Detector detector(options); });
        EXPECT_NE(message.find("margin"), std::string::npos) << message;
        EXPECT_NE(message.find(">= 0"), std::string::npos) << message;
        EXPECT_NE(message.find(bad < 0 ? "-" : "inf"), std::string::npos) << "the value as given: " << message;
    }
}

/// The unit corner tet at `origin` with edges `s`, every coordinate a float (checked).
TetMesh corner_tet(double origin, double s) {
    return exact_tet({origin, origin, origin, origin + s, origin, origin, origin, origin + s, origin, origin, origin, origin + s});
}

/// Per point, the tets found for it (one tet: 0 or 1 entries) and the first hit's distance (or -1).
struct Located {
    std::vector<std::size_t> hits;
    std::vector<double> distances;
};

Located locate_points(const TetMesh& mesh, const std::vector<double>& xyz, double within, Backend backend = Backend::cpu) {
    LocateOptions how;
    how.within = within;
    DetectorOptions options;
    options.backend = backend;
    const LocateResult r = locate(mesh, xyz, how, options);
    Located out;
    for (std::size_t p = 0; p + 1 < r.offsets.size(); ++p) {
        out.hits.push_back(r.offsets[p + 1] - r.offsets[p]);
        out.distances.push_back(r.offsets[p + 1] > r.offsets[p] ? r.distances[r.offsets[p]] : -1.0);
    }
    return out;
}

TEST(LocateEdges, SubnormalPointsAndWithinAreLocatedExactly) {
    // The corner tet of edge 2^-140 (subnormal coordinates): a point a float step inside its corner, on
    // it, and one step outside (at 2^-149, the least float) along each axis.
    const TetMesh tet = corner_tet(0.0, 0x1p-140);
    const double step = smallest;
    const std::vector<double> points = {step, step, step, 0, 0, 0, -step, step, step, step, -step, step, step, step, -step};
    const Located exact = locate_points(tet, points, 0.0);
    EXPECT_EQ(exact.hits, (std::vector<std::size_t>{1, 1, 0, 0, 0}));
    // Within twice the least float (the nearest tet's distance is computed in double), the points outside
    // get the tet at the least float's distance; within half of it, none.
    const Located near = locate_points(tet, points, 2 * step);
    EXPECT_EQ(near.hits, (std::vector<std::size_t>{1, 1, 1, 1, 1}));
    for (std::size_t p = 2; p < 5; ++p) EXPECT_EQ(near.distances[p], step);
    EXPECT_EQ(locate_points(tet, points, step / 2).hits, exact.hits);
}

TEST(LocateEdges, PointsNearTheLargestFloatAreLocatedExactly) {
    // The corner tet at 2^127 with edges 2^126 (its far vertices at 1.5 * 2^127, 2.6e38): points inside,
    // on a face, and a float step (2^103 below 2^127) outside the face x = 2^127.
    const double o = 0x1p127, s = 0x1p126, step = 0x1p103;
    const TetMesh tet = corner_tet(o, s);
    const std::vector<double> points = {o + s / 4, o + s / 4, o + s / 4, o + s / 2, o + s / 2, o, o - step, o + s / 4, o + s / 4,
                                        o + s, o + s, o + s};
    EXPECT_EQ(locate_points(tet, points, 0.0).hits, (std::vector<std::size_t>{1, 1, 0, 0}));
    const Located near = locate_points(tet, points, 2 * step);
    EXPECT_EQ(near.hits, (std::vector<std::size_t>{1, 1, 1, 0}));
    EXPECT_NEAR(near.distances[2], step, 1e-12 * step);
    EXPECT_EQ(locate_points(tet, points, step / 2).hits, (std::vector<std::size_t>{1, 1, 0, 0}));
    // Within 1e300 (beyond float, a finite double): every point gets the tet, the corner (s, s, s) from
    // the far face x + y + z = 3o + s at (2s) / sqrt(3), in double.
    const Located all = locate_points(tet, points, 1e300);
    EXPECT_EQ(all.hits, (std::vector<std::size_t>{1, 1, 1, 1}));
    EXPECT_NEAR(all.distances[3], 2 * s / std::sqrt(3.0), 1e-12 * s);
    // A point at the other end of float's range: farther than the largest float, still finite in double.
    const Located across = locate_points(tet, {-largest, -largest, -largest}, 1e300);
    ASSERT_EQ(across.hits, std::vector<std::size_t>{1});
    EXPECT_GT(across.distances[0], static_cast<double>(largest));
    EXPECT_TRUE(std::isfinite(across.distances[0]));
}

TEST(LocateEdges, RefusedPointsAndWithinNameTheArgument) {
    const TetMesh tet = corner_tet(0.0, 1.0);
    for (const double bad : {-1e-300, -1.0, std::numeric_limits<double>::infinity(), std::nan("")}) {
        const std::string message = error_message([&] { locate_points(tet, {0, 0, 0}, bad); });
        EXPECT_NE(message.find("within"), std::string::npos) << message;
        EXPECT_NE(message.find("not negative"), std::string::npos) << message;
    }
    // -1e-300 is negative, not zero: the message says so.
    EXPECT_EQ(error_message([&] { locate_points(tet, {0, 0, 0}, -1e-300); }).find("-0.0"), std::string::npos);
    for (const double beyond : {1e39, -1e39, std::numeric_limits<double>::infinity()}) {
        const std::string message = error_message([&] { locate_points(tet, {0, 0, 0, 0, beyond, 0}, 0.0); });
        EXPECT_NE(message.find("point 1"), std::string::npos) << message;
        EXPECT_NE(message.find("float range"), std::string::npos) << message;
    }
}

TEST(MarginEdges, CudaAtTheEndsGivesTheCpuAnswers) {
    std::string reason;
    if (!cuda_available(&reason)) GTEST_SKIP() << "CUDA backend not tested: " << reason;
    for (const BuiltPair& p : built_pairs())
        for (const float margin : {p.h, std::nextafter(p.h, 0.0f), largest}) {
            const FrameResult cpu = detect_at(p.a, p.b, margin, Method::kdet);
            const FrameResult gpu = detect_at(p.a, p.b, margin, Method::kdet, Backend::cuda);
            EXPECT_EQ(gpu.pairs, cpu.pairs) << p.name << " " << margin;
            EXPECT_EQ(gpu.distances, cpu.distances) << p.name << " " << margin;
        }
    const BuiltPair far = far_corners(0x1p125, 0x1p120);
    EXPECT_EQ(detect_at(far.a, far.b, largest, Method::kdet, Backend::cuda).pairs, detect_at(far.a, far.b, largest, Method::kdet).pairs);
    const TetMesh tiny = corner_tet(0.0, 0x1p-140), huge = corner_tet(0x1p127, 0x1p126);
    const double step = smallest;
    for (const double within : {0.0, step, 1e300}) {
        const std::vector<double> tiny_points = {step, step, step, -step, step, step};
        const std::vector<double> huge_points = {0x1p127 - 0x1p103, 0x1p127 + 0x1p124, 0x1p127 + 0x1p124, -largest, -largest, -largest};
        for (const auto& [mesh, points] : {std::pair{&tiny, &tiny_points}, std::pair{&huge, &huge_points}}) {
            const Located cpu = locate_points(*mesh, *points, within), gpu = locate_points(*mesh, *points, within, Backend::cuda);
            EXPECT_EQ(gpu.hits, cpu.hits) << within;
            EXPECT_EQ(gpu.distances, cpu.distances) << within;
        }
    }
}

} // namespace
} // namespace kdet::test
