// Inputs at the edges of float32: every finite coordinate is answered exactly. Scaled by a power of two
// (exact in float while nothing over- or underflows), a pair of meshes gives the very same pairs at
// every size; far from the origin and across nearly all of float's range, every method gives the
// brute-force answer of the exact test.

#include "near_touching.hpp"
#include "test_support.hpp"

#include <kdet/detector.hpp>

#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace kdet::test {
namespace {

/// @brief The mesh in float32 (what the detector stores), shifted, then scaled: the scaling by a power
/// of two is exact wherever the result stays a normal float.
TetMesh in_float(const TetMesh& mesh, double shift, double scale) {
    TetMesh out = mesh;
    for (std::size_t k = 0; k < out.positions.size(); ++k) {
        const float shifted = static_cast<float>(mesh.positions[k]) + static_cast<float>(shift * static_cast<double>(k % 3 + 1));
        out.positions[k] = static_cast<double>(static_cast<float>(static_cast<double>(shifted) * scale));
    }
    return out;
}

/// @brief The octopus (1,140 tets) and its copy shifted by a fraction of an edge: about 10,800 pairs.
struct MeshPair {
    TetMesh a, b;
};

const MeshPair& octopus_pair() {
    static const MeshPair pair = [] {
        const TetMesh mesh = load_model("octopus-low.mesh");
        return MeshPair{in_float(mesh, 0.0, 1.0), in_float(mesh, 0.003, 1.0)};
    }();
    return pair;
}

MeshPair scaled(const MeshPair& pair, double scale) { return {in_float(pair.a, 0.0, scale), in_float(pair.b, 0.0, scale)}; }

/// @brief Pairs (both objects) and each tet's colliding flag, of one detection of a and b (and of a's
/// self-collisions when `self`).
struct Answer {
    std::vector<TetPair> pairs;
    std::vector<std::vector<std::uint8_t>> colliding;
};

Answer detect(const MeshPair& pair, Method method, NarrowPhase test, bool self, Backend backend = Backend::cpu) {
    DetectorOptions options;
    options.method = method;
    options.narrow_phase = test;
    options.backend = backend;
    Detector detector(options);
    const ObjectId a = detector.add_object(pair.a);
    detector.add_object(pair.b);
    detector.set_self_collision(a, self);
    const FrameResult& r = detector.detect();
    return {r.pairs, r.colliding};
}

std::string scale_name(double scale) {
    int exponent = 0;
    std::frexp(scale, &exponent);
    return "scale 2^" + std::to_string(exponent - 1);
}

const double power_of_two_scales[] = {0x1p-100, 0x1p-70, 0x1p-30, 0x1p40, 0x1p70, 0x1p100, 0x1p120};

TEST(Edges, PowerOfTwoScalesGiveTheSamePairsForEveryMethod) {
    const MeshPair& unit = octopus_pair();
    const Answer reference = detect(unit, Method::brute_force_pairs, NarrowPhase::exact, true);
    ASSERT_GT(reference.pairs.size(), 10000u);
    EXPECT_EQ(detect(unit, Method::kdet, NarrowPhase::exact, true).pairs, reference.pairs);
    for (const double scale : power_of_two_scales) {
        SCOPED_TRACE(scale_name(scale));
        const MeshPair pair = scaled(unit, scale);
        EXPECT_EQ(detect(pair, Method::kdet, NarrowPhase::exact, true).pairs, reference.pairs);
        EXPECT_EQ(detect(pair, Method::kdet_no_pairs, NarrowPhase::exact, true).colliding, reference.colliding);
        EXPECT_EQ(detect(pair, Method::brute_force_loop, NarrowPhase::exact, true).colliding, reference.colliding);
    }
    // The brute-force oracle itself, at both ends.
    for (const double scale : {0x1p-100, 0x1p120})
        EXPECT_EQ(detect(scaled(unit, scale), Method::brute_force_pairs, NarrowPhase::exact, true).pairs, reference.pairs)
            << scale_name(scale);
}

TEST(Edges, PowerOfTwoScalesGiveTheSamePairsForEveryFloatTest) {
    const MeshPair& unit = octopus_pair();
    for (const NarrowPhase test : {NarrowPhase::sat, NarrowPhase::sat_no_edges, NarrowPhase::sat_mtv, NarrowPhase::gjk,
                                   NarrowPhase::fast}) {
        SCOPED_TRACE(to_string(test));
        const std::vector<TetPair> reference = detect(unit, Method::kdet, test, false).pairs;
        ASSERT_GT(reference.size(), 10000u);
        for (const double scale : {0x1p-100, 0x1p-70, 0x1p70, 0x1p120})
            EXPECT_EQ(detect(scaled(unit, scale), Method::kdet, test, false).pairs, reference) << scale_name(scale);
    }
}

TEST(Edges, ContactsScaleWithTheScene) {
    // Depth and direction come from the 44-axis SAT in the pair's local frame: scaled by a power of two,
    // the depth scales exactly and the direction stays.
    const auto contacts = [](const MeshPair& pair) {
        DetectorOptions options;
        options.contacts = true;
        Detector detector(options);
        detector.add_object(pair.a);
        detector.add_object(pair.b);
        return detector.detect().contacts;
    };
    const std::vector<Contact> reference = contacts(octopus_pair());
    ASSERT_GT(reference.size(), 10000u);
    for (const double scale : {0x1p-100, 0x1p100}) {
        SCOPED_TRACE(scale_name(scale));
        const std::vector<Contact> scaled_contacts = contacts(scaled(octopus_pair(), scale));
        ASSERT_EQ(scaled_contacts.size(), reference.size());
        for (std::size_t k = 0; k < reference.size(); ++k) {
            ASSERT_EQ(static_cast<double>(scaled_contacts[k].depth), static_cast<double>(reference[k].depth) * scale) << k;
            for (int axis = 0; axis < 3; ++axis)
                ASSERT_EQ(scaled_contacts[k].direction[axis], reference[k].direction[axis]) << k;
        }
    }
}

TEST(Edges, NearTouchingPairsKeepEveryTestsAnswerAtEveryScale) {
    // Pairs around the pre-test's margins and the tests' tolerance, where the float filter of the exact
    // test and the float tests decide by the finest amounts: scaled by a power of two, each test gives the
    // same pairs, with and without the grid.
    const NearTouchingPairs near = near_touching_pairs(64, 11);
    const MeshPair unit{in_float(near.first, 0.0, 1.0), in_float(near.second, 0.0, 1.0)};
    for (const NarrowPhase test : every_narrow_phase_test()) {
        SCOPED_TRACE(to_string(test));
        const std::vector<TetPair> reference = detect(unit, Method::brute_force_loop, test, false).pairs;
        EXPECT_GT(reference.size(), 20u);
        for (const double scale : {0x1p-100, 0x1p-60, 0x1p60, 0x1p100}) {
            const MeshPair pair = scaled(unit, scale);
            EXPECT_EQ(detect(pair, Method::brute_force_loop, test, false).pairs, reference) << scale_name(scale);
            EXPECT_EQ(detect(pair, Method::kdet, test, false).pairs, reference) << scale_name(scale);
        }
    }
}

/// @brief kdet's pairs and flags equal brute force's with the exact test on the same float input.
void expect_brute_force_answer(const MeshPair& pair) {
    const Answer reference = detect(pair, Method::brute_force_pairs, NarrowPhase::exact, true);
    EXPECT_GT(reference.pairs.size(), 1000u);
    EXPECT_EQ(detect(pair, Method::kdet, NarrowPhase::exact, true).pairs, reference.pairs);
    EXPECT_EQ(detect(pair, Method::kdet_no_pairs, NarrowPhase::exact, true).colliding, reference.colliding);
}

TEST(Edges, NearTheLargestFloatEveryMethodGivesTheExactAnswer) {
    // Coordinates up to 3.2e38: differences across the scene overflow float, those inside a tet do not.
    expect_brute_force_answer(scaled(octopus_pair(), 6e38));
    // 1e22: the size at which every pair was lost while squared sizes overflowed.
    expect_brute_force_answer(scaled(octopus_pair(), 1e22));
}

TEST(Edges, TetsWhoseEdgesOverflowFloatGiveTheExactAnswer) {
    // Random tets with coordinates up to 3e38 of both signs, whose edges no float holds, beside small
    // tets at the origin: the face-plane pre-test once took such a pair's longest edge from the small
    // tet alone (the large one's was NaN) and proved pairs 4e37 apart intersecting.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> huge(-3e38, 3e38), size(0.1, 1.0);
    MeshPair pair;
    for (std::uint32_t t = 0; t < 40; ++t) {
        for (int k = 0; k < 4; ++k)
            for (int axis = 0; axis < 3; ++axis) pair.a.positions.push_back(static_cast<float>(huge(rng)));
        const double s = size(rng);
        const double corner[4][3] = {{0, 0, 0}, {s, 0, 0}, {0, s, 0}, {0, 0, s}};
        for (const auto& c : corner)
            for (const double x : c) pair.b.positions.push_back(static_cast<float>(x + 2.0 * (t % 4)));
        for (std::uint32_t k = 0; k < 4; ++k) {
            pair.a.tets.push_back(4 * t + k);
            pair.b.tets.push_back(4 * t + k);
        }
    }
    const Answer reference = detect(pair, Method::brute_force_pairs, NarrowPhase::exact, true);
    EXPECT_GT(reference.pairs.size(), 10u);
    for (const Method method : {Method::kdet, Method::kdet_no_pairs, Method::brute_force_loop}) {
        const Answer found = detect(pair, method, NarrowPhase::exact, true);
        if (method != Method::kdet_no_pairs) {
            EXPECT_EQ(found.pairs, reference.pairs) << to_string(method);
        }
        EXPECT_EQ(found.colliding, reference.colliding) << to_string(method);
    }
}

TEST(Edges, SegmentsLongerThanTheLargestFloatGiveTheExactAnswer) {
    // Found by the property tests: zero-volume tets (segments) through the origin whose lengths exceed
    // the largest float. Every size was infinite, which read as no tet at all (the pair was lost), or
    // the region was wider than the largest float and a box spanned 2^30 cells per axis (out of memory).
    const auto segment = [](double x, double y, double z, double u, double v, double w) {
        return TetMesh{{x, y, z, x, y, z, x, y, z, u, v, w}, {0, 1, 2, 3}};
    };
    const MeshPair crossing{segment(0, 0, 0, 0, 1.5399265e38, 3.0798531e38), segment(0, 0, 1.9249082e38, 0, 0, -1.5399265e38)};
    const MeshPair touching{segment(0, 0, 0, 0, 0, 2.6670430e38), segment(0, 0, 0, 0, 0, -1.0001410e38)};
    for (const MeshPair* pair : {&crossing, &touching}) {
        const Answer reference = detect(*pair, Method::brute_force_pairs, NarrowPhase::exact, true);
        EXPECT_EQ(reference.pairs.size(), 1u);
        EXPECT_EQ(detect(*pair, Method::kdet, NarrowPhase::exact, true).pairs, reference.pairs);
        EXPECT_EQ(detect(*pair, Method::kdet_no_pairs, NarrowPhase::exact, true).colliding, reference.colliding);
    }
}

TEST(Edges, SubnormalCoordinatesGiveTheExactAnswer) {
    // Edges of about 2^-147: every coordinate is subnormal, and the input no longer the octopus exactly.
    expect_brute_force_answer(scaled(octopus_pair(), 0x1p-140));
    expect_brute_force_answer(scaled(octopus_pair(), 1e-30));
}

TEST(Edges, SmallTetsFarFromTheOriginGiveTheExactAnswer) {
    // Edges of a few units at 1e7, where a float's step is 1: coordinates are coarsely quantised.
    const TetMesh mesh = load_model("octopus-low.mesh");
    const MeshPair pair{in_float(in_float(mesh, 0.0, 1000.0), 1e7, 1.0), in_float(in_float(mesh, 0.003, 1000.0), 1e7, 1.0)};
    expect_brute_force_answer(pair);
}

TEST(Edges, CudaBackendAtTheEdgesGivesTheCpuPairs) {
    std::string reason;
    if (!cuda_available(&reason)) GTEST_SKIP() << "CUDA backend not tested: " << reason;
    const MeshPair& unit = octopus_pair();
    const std::vector<TetPair> reference = detect(unit, Method::kdet, NarrowPhase::exact, true).pairs;
    for (const double scale : power_of_two_scales)
        EXPECT_EQ(detect(scaled(unit, scale), Method::kdet, NarrowPhase::exact, true, Backend::cuda).pairs, reference)
            << scale_name(scale);
    for (const double scale : {6e38, 0x1p-140}) {
        const MeshPair pair = scaled(unit, scale);
        EXPECT_EQ(detect(pair, Method::kdet, NarrowPhase::exact, true, Backend::cuda).pairs,
                  detect(pair, Method::kdet, NarrowPhase::exact, true).pairs)
            << scale;
    }
}

} // namespace
} // namespace kdet::test
