// Positions handed over in the backend's memory and results left there. On the CPU backend the
// backend's memory is host memory, so the same calls are checked here on every machine.

#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace kdet {
namespace {

std::vector<float> as_float(const TetMesh& m) { return std::vector<float>(m.positions.begin(), m.positions.end()); }

void expect_rejected(const DetectorOptions& options, const std::string& naming) {
    try {
        Detector detector(options);
        FAIL() << "expected kdet::Error naming " << naming;
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(naming), std::string::npos) << e.what();
    }
}

TEST(DetectorOptions, InvalidSettingsAreRejectedByName) {
    DetectorOptions o;
    o.block_size = 0;
    expect_rejected(o, "block size");
    o.block_size = 2048;
    expect_rejected(o, "block size");
    o = DetectorOptions{};
    o.bucket_capacity = 0;
    expect_rejected(o, "bucket capacity");
    o = DetectorOptions{};
    int not_a_stream = 0;
    o.cuda_stream = &not_a_stream; // never used as a stream: the CPU backend rejects any
    expect_rejected(o, "cuda_stream");
}

TEST(DeviceApi, ResultsLeftInBackendMemoryEqualTheHostResults) {
    const TetMesh a = test::random_soup(1500, 4.0, 2.0, 91), b = test::random_soup(1500, 4.0, 2.0, 92);
    DetectorOptions host_options, device_options;
    host_options.contacts = device_options.contacts = true;
    device_options.results_to_host = false;
    Detector host(host_options), device(device_options);
    for (Detector* d : {&host, &device}) {
        d->set_self_collision(d->add_object(a), true);
        d->add_object(b);
    }
    const FrameResult expected = host.detect();
    const FrameResult& r = device.detect();
    ASSERT_GT(expected.pairs.size(), 20u);
    EXPECT_TRUE(r.pairs.empty());
    EXPECT_TRUE(r.colliding.empty());
    EXPECT_EQ(r.counts.colliding_pairs, expected.counts.colliding_pairs);
    EXPECT_EQ(r.counts.colliding_tets, expected.counts.colliding_tets);

    const DeviceResults dr = device.device_results();
    ASSERT_EQ(dr.pair_count, expected.pairs.size());
    ASSERT_EQ(dr.tet_count, a.num_tets() + b.num_tets());
    ASSERT_NE(dr.contacts, nullptr);
    for (std::size_t k = 0; k < dr.pair_count; ++k) {
        const TetPair& p = expected.pairs[k];
        const std::uint64_t key = (std::uint64_t{device.first_tet(p.object_a) + p.tet_a} << 32) |
                                  (device.first_tet(p.object_b) + p.tet_b);
        ASSERT_EQ(dr.pair_keys[k], key) << k;
        EXPECT_EQ(dr.contacts[k].depth, expected.contacts[k].depth);
    }
    for (std::uint32_t o = 0; o < 2; ++o)
        for (std::size_t t = 0; t < expected.colliding[o].size(); ++t)
            ASSERT_EQ(dr.colliding[device.first_tet(o) + t] != 0, expected.colliding[o][t] != 0);
}

TEST(DeviceApi, PositionsGivenInBackendMemoryDriveTheDetection) {
    const TetMesh a = test::random_soup(800, 3.0, 1.0, 93), b = test::random_soup(800, 3.0, 1.0, 94);
    const TetMesh b_moved = test::moved(b, 0.4, 0.3, 0.0, 0.0);
    Detector detector;
    detector.add_object(a);
    const ObjectId ib = detector.add_object(b);
    const std::vector<float> moved_xyz = as_float(b_moved);
    detector.set_positions_on_device(ib, moved_xyz.data(), b.num_vertices());
    const auto expected = collide(a, b_moved);
    std::vector<IndexPair> got;
    for (const TetPair& p : detector.detect().pairs) got.emplace_back(p.tet_a, p.tet_b);
    EXPECT_EQ(got, expected);

    // Adding an object keeps the positions that only the backend held.
    detector.add_object(test::random_soup(10, 100.0, 0.0, 95));
    got.clear();
    for (const TetPair& p : detector.detect().pairs)
        if (p.object_a == 0 && p.object_b == 1) got.emplace_back(p.tet_a, p.tet_b);
    EXPECT_EQ(got, expected);
}

TEST(DeviceApi, NonFinitePositionsInBackendMemoryAreRejectedAndNeverUsed) {
    const TetMesh a = test::random_soup(300, 2.0, 1.0, 96);
    Detector detector;
    const ObjectId id = detector.add_object(a);
    detector.set_self_collision(id, true);
    const std::vector<TetPair> before = detector.detect().pairs;
    ASSERT_FALSE(before.empty());
    std::vector<float> xyz = as_float(a);
    xyz[7] = std::numeric_limits<float>::infinity();
    EXPECT_THROW(detector.set_positions_on_device(id, xyz.data(), a.num_vertices()), Error);
    EXPECT_THROW(detector.set_positions_on_device(id, xyz.data(), a.num_vertices() - 1), Error);
    // The rejected positions never became current: the detector still sees the last good ones.
    EXPECT_EQ(detector.detect().pairs, before);
}

} // namespace
} // namespace kdet
