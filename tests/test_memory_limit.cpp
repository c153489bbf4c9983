// A frame whose pairs the memory cannot hold fails at once, with a one-line kdet::Error naming its pairs
// and their bytes, and leaves the detector usable: DetectorOptions::memory_limit stands in for a memory
// that runs out (the same check refuses a failed allocation), on every method that builds pairs and on
// both backends.

#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace kdet {
namespace {

using test::error_message;

/// A few tets around the pile, some of them in it: a scene of a few pairs.
TetMesh small_neighbour() { return test::random_soup(40, 1.0, 0.3, 7); }

/// The pairs a refusal names: "the frame has N candidate pairs", "at least N candidate pairs" (a lower
/// bound refused it before the count) or "N colliding pairs" (0 if none).
std::uint64_t pairs_named(const std::string& message) {
    const std::string lead = "the frame has ", bound = "at least ";
    std::size_t at = message.find(lead);
    if (at == std::string::npos || message.find(" pairs", at) == std::string::npos) return 0;
    at += lead.size();
    if (message.compare(at, bound.size(), bound) == 0) at += bound.size();
    return std::stoull(message.substr(at));
}

constexpr std::uint32_t pile = 300;
constexpr std::uint64_t pile_pairs = std::uint64_t{pile} * (pile - 1) / 2;

/// The pairs of a fresh detector without a limit: the oracle of the frames after a refused one.
std::vector<TetPair> fresh_pairs(const DetectorOptions& options, const TetMesh& a, const TetMesh& b, bool self_a) {
    DetectorOptions unlimited = options;
    unlimited.memory_limit = 0;
    Detector detector(unlimited);
    const ObjectId ia = detector.add_object(a);
    detector.add_object(b);
    detector.set_self_collision(ia, self_a);
    return detector.detect().pairs;
}

class MemoryLimit : public ::testing::TestWithParam<std::tuple<Backend, Method>> {
protected:
    void SetUp() override {
        std::string reason;
        if (std::get<0>(GetParam()) == Backend::cuda && !cuda_available(&reason)) GTEST_SKIP() << reason;
        options_.backend = std::get<0>(GetParam());
        options_.method = std::get<1>(GetParam());
        // The pile's pairs take more than this with their window (24 bytes a pair, and 8 more per
        // candidate), the rest of the scene far less.
        options_.memory_limit = 600000;
    }
    DetectorOptions options_;
};

TEST_P(MemoryLimit, AFirstFrameTooLargeFailsNamingItsPairsAndBytesAndTheDetectorRecovers) {
    const TetMesh a = test::identical_tets(pile), b = small_neighbour();
    Detector detector(options_);
    const ObjectId ia = detector.add_object(a);
    detector.add_object(b);
    detector.set_self_collision(ia, true);
    const std::string message = error_message([&] { detector.detect(); });
    // kdet counts its candidates before the narrow phase; brute force's candidates are its colliding
    // pairs. Either way the pile's pairs and those of the tets in it.
    EXPECT_GE(pairs_named(message), pile_pairs) << message;
    EXPECT_NE(message.find(" bytes ("), std::string::npos) << message;
    EXPECT_NE(message.find("memory_limit 600000"), std::string::npos) << message;
    EXPECT_LE(detector.memory_bytes(), options_.memory_limit);

    // The same detector answers the smaller scene, as a fresh one does, and refuses the large one again.
    detector.set_self_collision(ia, false);
    const std::vector<TetPair> expected = fresh_pairs(options_, a, b, false);
    ASSERT_FALSE(expected.empty());
    EXPECT_EQ(detector.detect().pairs, expected);
    EXPECT_LE(detector.memory_bytes(), options_.memory_limit);
    detector.set_self_collision(ia, true);
    EXPECT_GE(pairs_named(error_message([&] { detector.detect(); })), pile_pairs);
    detector.set_self_collision(ia, false);
    EXPECT_EQ(detector.detect().pairs, expected);
}

TEST_P(MemoryLimit, ALaterFrameThatOutgrowsTheLimitFailsAtItsCountAndTheNextFrameIsExact) {
    const TetMesh a = test::identical_tets(pile), b = small_neighbour();
    Detector detector(options_);
    const ObjectId ia = detector.add_object(a);
    detector.add_object(b);
    const std::vector<TetPair> expected = fresh_pairs(options_, a, b, false);
    EXPECT_EQ(detector.detect().pairs, expected); // a first frame that fits: later frames count as they go
    detector.set_self_collision(ia, true);
    const std::string message = error_message([&] { detector.detect(); });
    // Either the candidates or the colliding pairs (brute force's candidates are its colliding pairs)
    // outgrow the limit first: both are the pile's pairs, and more.
    EXPECT_NE(message.find(" bytes ("), std::string::npos) << message;
    EXPECT_GE(pairs_named(message), pile_pairs) << message;
    detector.set_self_collision(ia, false);
    EXPECT_EQ(detector.detect().pairs, expected);
    EXPECT_LE(detector.memory_bytes(), options_.memory_limit);
}

TEST_P(MemoryLimit, WithoutALimitTheSameFramesAreAnswered) {
    DetectorOptions options = options_;
    options.memory_limit = 0;
    Detector detector(options);
    const ObjectId ia = detector.add_object(test::identical_tets(pile));
    detector.set_self_collision(ia, true);
    EXPECT_EQ(detector.detect().pairs.size(), pile_pairs);
}

TEST_P(MemoryLimit, AFrameWithoutPairsNeedsNoRoomEvenUnderALimitBelowTheDetectorsOwn) {
    // The detector's own buffers take more than this limit leaves: no room for a single candidate. A
    // frame that has none is answered, as its first frame, after a refused one and when apart again.
    DetectorOptions options = options_;
    options.memory_limit = 1000;
    const TetMesh a = test::identical_tets(pile), b = test::moved(small_neighbour(), 0.0, 100.0, 0.0, 0.0);
    Detector detector(options);
    const ObjectId ia = detector.add_object(a);
    const ObjectId ib = detector.add_object(b);
    EXPECT_TRUE(detector.detect().pairs.empty());
    detector.set_self_collision(ia, true);
    const std::string refused = error_message([&] { detector.detect(); });
    EXPECT_GT(pairs_named(refused), 0u) << refused;
    EXPECT_NE(refused.find("memory_limit 1000"), std::string::npos) << refused;
    EXPECT_NE(refused.find("(the limit is below what the detector holds for the scene alone)"), std::string::npos) << refused;
    detector.set_self_collision(ia, false);
    EXPECT_TRUE(detector.detect().pairs.empty());
    const TetMesh near = small_neighbour();
    detector.set_positions(ib, near.positions.data(), near.num_vertices());
    EXPECT_NE(error_message([&] { detector.detect(); }).find("memory_limit 1000"), std::string::npos);
}

std::string case_name(const ::testing::TestParamInfo<std::tuple<Backend, Method>>& info) {
    return std::string(to_string(std::get<0>(info.param))) + "_" + to_string(std::get<1>(info.param));
}

INSTANTIATE_TEST_SUITE_P(PairMethods, MemoryLimit,
                         ::testing::Combine(::testing::Values(Backend::cpu, Backend::cuda),
                                            ::testing::Values(Method::kdet, Method::brute_force_loop,
                                                              Method::brute_force_pairs)),
                         case_name);

TEST(MemoryLimit, AFirstFrameThatOverflowsItsGuessCountsAndGrowsOnceToTheExactNeed) {
    // A buffer far too small for the pile: the search counts what it lacks and grows once (one regrow),
    // and the window fits too, so a limit just above the need is enough.
    DetectorOptions options;
    options.initial_candidate_capacity = 16;
    Detector detector(options);
    const ObjectId ia = detector.add_object(test::identical_tets(pile));
    detector.set_self_collision(ia, true);
    const FrameResult& r = detector.detect();
    EXPECT_EQ(r.pairs.size(), pile_pairs);
    EXPECT_EQ(r.counts.buffer_regrows, 1u);
}

TEST(MemoryLimit, AFirstFrameWhoseGuessItsPairsFillToTheLastSlotFinishes) {
    // A first buffer of exactly the frame's candidates (or about that many): the items that start
    // once it is full have none to store, which no growth changes; they must finish all the same.
    const TetMesh pile_mesh = test::identical_tets(40);
    const TetMesh apart = test::moved(test::random_soup(3000, 1.0, 0.3, 11), 0.0, 50.0, 0.0, 0.0);
    const auto run = [&](std::size_t capacity, int threads) {
        DetectorOptions options;
        options.initial_candidate_capacity = capacity;
        options.threads = threads;
        Detector detector(options);
        const ObjectId ia = detector.add_object(pile_mesh);
        detector.add_object(apart);
        detector.set_self_collision(ia, true);
        const FrameResult& r = detector.detect();
        return std::make_pair(r.pairs, r.counts.candidates);
    };
    const auto [expected, candidates] = run(0, 1);
    ASSERT_EQ(expected.size(), 40u * 39u / 2u);
    for (const int threads : {1, 2})
        for (std::size_t capacity = candidates - 2; capacity <= candidates + 2; ++capacity)
            EXPECT_EQ(run(capacity, threads).first, expected) << capacity << " slots, " << threads << " threads";
}

} // namespace
} // namespace kdet
