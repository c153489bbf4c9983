// Static objects (Detector::set_static): every frame's pairs equal brute force on the same objects with
// the pairs of two static objects (and static self-collision) left out, whatever the tets' sizes, as
// objects turn static and moving again and static objects are moved by set_positions.

#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

namespace kdet {
namespace {

using test::error_message;
using test::moved;
using test::random_soup;

/// The objects of one frame: meshes at their current positions, which are static, which self-collide.
struct Objects {
    std::vector<TetMesh> meshes;
    std::vector<bool> is_static;
    std::vector<bool> self;
};

/// Brute force on every pair, without static flags, then the pairs static objects cannot report removed.
std::vector<TetPair> oracle(const Objects& s) {
    DetectorOptions options;
    options.method = Method::brute_force_loop;
    Detector detector(options);
    for (std::size_t o = 0; o < s.meshes.size(); ++o)
        detector.set_self_collision(detector.add_object(s.meshes[o]), s.self[o]);
    std::vector<TetPair> kept;
    for (const TetPair& p : detector.detect().pairs)
        if (!(s.is_static[p.object_a] && s.is_static[p.object_b])) kept.push_back(p);
    return kept;
}

/// Adds the meshes (positions as given) with their flags.
void add_all(Detector& detector, const Objects& s) {
    for (std::size_t o = 0; o < s.meshes.size(); ++o) {
        const ObjectId id = detector.add_object(s.meshes[o]);
        detector.set_self_collision(id, s.self[o]);
        detector.set_static(id, s.is_static[o]);
    }
}

/// A mix of moving and static soups and meshes whose tet sizes differ by up to 100 times either way.
Objects random_setup(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> coin(0, 1);
    Objects s;
    // A fine static block, coarse and fine soups, and a few tets 100 times the fine ones' size.
    s.meshes.push_back(make_box_mesh(6, 6, 6, 0.17));
    s.meshes.push_back(random_soup(300, 1.0, 2.0, seed * 7 + 1));
    s.meshes.push_back(random_soup(200, 1.0, 0.5, seed * 7 + 2));
    s.meshes.push_back(moved(random_soup(6, 0.5, 0.0, seed * 7 + 3), 0.3, 0.3, 0.3, 0.3));
    s.meshes.push_back(moved(make_box_mesh(3, 3, 3, 0.01), 0.2, 0.5, 0.45, 0.5));
    for (std::size_t o = 0; o < s.meshes.size(); ++o) {
        s.is_static.push_back(coin(rng) != 0);
        s.self.push_back(coin(rng) != 0);
    }
    return s;
}

/// Checks the detector's next frame against the oracle; returns the pairs found.
std::size_t expect_pairs(Detector& detector, const Objects& s, const std::string& what) {
    const std::vector<TetPair> expected = oracle(s);
    const FrameResult& r = detector.detect();
    EXPECT_EQ(r.pairs.size(), expected.size()) << what;
    EXPECT_TRUE(r.pairs == expected) << what;
    return expected.size();
}

TEST(Static, RandomMixesEqualBruteForce) {
    std::size_t pairs = 0;
    for (unsigned seed = 1; seed <= 8; ++seed) {
        const Objects s = random_setup(seed);
        for (Method method : {Method::kdet, Method::brute_force_pairs}) {
            DetectorOptions options;
            options.method = method;
            Detector detector(options);
            add_all(detector, s);
            pairs += expect_pairs(detector, s, "seed " + std::to_string(seed) + ", method " + to_string(method));
        }
    }
    EXPECT_GT(pairs, 1000u);
}

TEST(Static, SizesDifferingHundredTimesBothWays) {
    // A block of tets about 0.03 across against one tet about 3 across that cuts through it, the
    // block static and the tet moving, then the other way round: each side the larger once.
    for (bool big_moves : {true, false}) {
        Objects s;
        s.meshes.push_back(make_box_mesh(12, 12, 12, 0.015));
        s.meshes.push_back(random_soup(1, 1.0, 0.0, 5));
        s.meshes[1].positions = {0.1, 0.1, -1.0, 2.0, 0.1, 0.0, 0.1, 2.0, 0.0, 0.1, 0.1, 2.0};
        s.is_static = {!big_moves, big_moves};
        s.self = {!big_moves, big_moves};
        Detector detector;
        add_all(detector, s);
        EXPECT_GT(expect_pairs(detector, s, big_moves ? "big tet moving" : "big tet static"), 100u);
    }
}

TEST(Static, TogglingAndMovingStaticObjects) {
    Objects s = random_setup(99);
    s.is_static = {true, false, true, false, true};
    Detector detector;
    add_all(detector, s);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> shift(-0.15, 0.15);
    std::size_t pairs = 0;
    for (int frame = 0; frame < 10; ++frame) {
        const std::string what = "frame " + std::to_string(frame);
        pairs += expect_pairs(detector, s, what);
        // Move one object (static or not) by set_positions, and turn another static or moving.
        const std::size_t mover = static_cast<std::size_t>(frame) % s.meshes.size();
        s.meshes[mover] = moved(s.meshes[mover], 0.1, shift(rng), shift(rng), shift(rng));
        detector.set_positions(static_cast<ObjectId>(mover), s.meshes[mover].positions.data(), s.meshes[mover].num_vertices());
        const std::size_t toggled = static_cast<std::size_t>(frame * 3 + 1) % s.meshes.size();
        if (frame % 3 == 2) {
            s.is_static[toggled] = !s.is_static[toggled];
            detector.set_static(static_cast<ObjectId>(toggled), s.is_static[toggled]);
            EXPECT_EQ(detector.is_static(static_cast<ObjectId>(toggled)), s.is_static[toggled]);
        }
    }
    EXPECT_GT(pairs, 1000u);
}

TEST(Static, StaticObjectsKeepTheirPlaceAcrossFrames) {
    // A moving body passing through a static block: the static block is placed once, the body moves.
    Objects s;
    s.meshes.push_back(make_box_mesh(10, 10, 10, 0.1));
    s.meshes.push_back(moved(make_torus_mesh(0.3, 0.1, 800), 0.0, -0.3, 0.5, 0.5));
    s.is_static = {true, false};
    s.self = {false, true};
    Detector detector;
    add_all(detector, s);
    for (int frame = 0; frame < 6; ++frame) {
        EXPECT_GT(expect_pairs(detector, s, "frame " + std::to_string(frame)), 0u);
        s.meshes[1] = moved(s.meshes[1], 0.2, 0.25, 0.0, 0.0);
        detector.set_positions(1, s.meshes[1].positions.data(), s.meshes[1].num_vertices());
    }
}

TEST(Static, AllStaticReportsNothing) {
    Objects s = random_setup(4);
    s.is_static.assign(s.meshes.size(), true);
    Detector detector;
    add_all(detector, s);
    EXPECT_TRUE(detector.detect().pairs.empty());
    EXPECT_TRUE(oracle(s).empty());
}

TEST(Static, BadObjectIdIsAnError) {
    Detector detector;
    detector.add_object(make_box_mesh(1, 1, 1, 1.0));
    EXPECT_EQ(error_message([&] { detector.set_static(3, true); }), "object id 3 out of range (1 objects)");
    EXPECT_EQ(error_message([&] { (void)detector.is_static(1); }), "object id 1 out of range (1 objects)");
    EXPECT_FALSE(detector.is_static(0));
}

TEST(Static, CudaEqualsCpu) {
    std::string reason;
    if (!cuda_available(&reason)) GTEST_SKIP() << "CUDA backend not tested: " << reason;
    for (unsigned seed = 1; seed <= 6; ++seed) {
        const Objects s = random_setup(seed);
        DetectorOptions gpu;
        gpu.backend = Backend::cuda;
        Detector cpu_detector, gpu_detector(gpu);
        add_all(cpu_detector, s);
        add_all(gpu_detector, s);
        const FrameResult& a = cpu_detector.detect();
        const FrameResult& b = gpu_detector.detect();
        EXPECT_TRUE(a.pairs == b.pairs) << "seed " << seed;
        EXPECT_EQ(a.colliding, b.colliding) << "seed " << seed;
    }
}

} // namespace
} // namespace kdet
