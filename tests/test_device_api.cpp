// Positions handed over in the backend's memory and results left there. On the CPU backend the
// backend's memory is host memory, so the same calls are checked here on every machine.

#include "device_like_exec.hpp"
#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>

#include <gtest/gtest.h>

#include <cstdint>

#include <cmath>
#include <functional>
#include <limits>

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
    expect_rejected(o, "block_size: expected a positive number, got 0");
    o.block_size = 2048;
    expect_rejected(o, "block size 2048 out of range [1, 1024]");
    // Every option of the table is checked, in the table's words: threads (0 leaves it to OpenMP),
    // an enum cast from an integer, a margin that is not a distance.
    o = DetectorOptions{};
    o.threads = -1;
    expect_rejected(o, "threads: expected a positive number, got -1");
    o.threads = 100000;
    expect_rejected(o, "threads 100000 out of range [1, 1024]");
    o = DetectorOptions{};
    o.method = static_cast<Method>(99);
    expect_rejected(o, "method: 99 is not one of its values (kdet, kdet_no_pairs, brute_force_loop or brute_force_pairs)");
    o = DetectorOptions{};
    o.hash = static_cast<HashFunction>(-1);
    expect_rejected(o, "hash: -1 is not one of its values");
    o = DetectorOptions{};
    o.margin = -0.5f;
    expect_rejected(o, "margin: expected a finite number >= 0, got -0.5");
    o = DetectorOptions{};
    o.memory_limit = SIZE_MAX; // any count: no limit in effect
    EXPECT_NO_THROW(Detector{o});
    o = DetectorOptions{};
    o.bucket_capacity = 4097;
    expect_rejected(o, "bucket capacity 4097 out of range [0, 4096]");
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
    const device_like::BackendMemoryReadable readable;
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

std::vector<IndexPair> pairs_of(const FrameResult& r, ObjectId a, ObjectId b) {
    std::vector<IndexPair> got;
    for (const TetPair& p : r.pairs)
        if (p.object_a == a && p.object_b == b) got.emplace_back(p.tet_a, p.tet_b);
    return got;
}

void expect_error_naming(const std::function<void()>& call, const std::string& naming) {
    try {
        call();
        FAIL() << "expected kdet::Error naming " << naming;
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(naming), std::string::npos) << e.what();
    }
}

TEST(DeviceApi, NonFinitePositionsInBackendMemoryAreRejectedByTheNextFrameAndNeverUsed) {
    const TetMesh a = test::random_soup(300, 2.0, 1.0, 96), b = test::random_soup(300, 2.0, 1.0, 97);
    Detector detector;
    detector.add_object(a);
    const ObjectId id = detector.add_object(b);
    detector.set_self_collision(id, true);
    const std::vector<TetPair> before = detector.detect().pairs;
    ASSERT_FALSE(before.empty());
    std::vector<float> xyz = as_float(test::moved(b, 5.0, 0.0, 0.0, 0.0));
    xyz[3 * 7 + 1] = std::numeric_limits<float>::infinity();
    EXPECT_THROW(detector.set_positions_on_device(id, xyz.data(), b.num_vertices() - 1), Error);
    // Handing them over waits for nothing; the frame that checks them says which vertex is bad.
    detector.set_positions_on_device(id, xyz.data(), b.num_vertices());
    expect_error_naming([&] { detector.detect(); }, "object 1: vertex 7 of the positions given on the device");
    {
        DeviceResults discarded = detector.device_results();
        const device_like::BackendMemoryReadable readable;
        EXPECT_EQ(discarded.pair_count, 0u);
        for (std::size_t t = 0; t < discarded.tet_count; ++t) ASSERT_EQ(discarded.colliding[t], 0u) << t;
    }
    // The rejected positions never became current: the detector still sees the last good ones.
    EXPECT_EQ(detector.detect().pairs, before);

    detector.set_positions_on_device(id, xyz.data(), b.num_vertices());
    detector.detect_async();
    EXPECT_THROW(detector.finish(), Error);
    EXPECT_EQ(detector.detect().pairs, before);
}

TEST(DeviceApi, TheLaterOfHostAndDevicePositionsWins) {
    const TetMesh a = test::random_soup(400, 2.0, 1.0, 98), b = test::random_soup(400, 2.0, 1.0, 99);
    const TetMesh near = test::moved(b, 0.4, 0.3, 0.0, 0.0), far = test::moved(b, 0.0, 50.0, 0.0, 0.0);
    const auto expected_near = collide(a, near);
    ASSERT_FALSE(expected_near.empty());
    const std::vector<float> near_xyz = as_float(near), far_xyz = as_float(far);
    Detector detector;
    detector.add_object(a);
    const ObjectId ib = detector.add_object(b);

    detector.set_positions_on_device(ib, far_xyz.data(), b.num_vertices());
    detector.set_positions(ib, near_xyz.data(), b.num_vertices());
    EXPECT_EQ(pairs_of(detector.detect(), 0, ib), expected_near);

    detector.set_positions(ib, far_xyz.data(), b.num_vertices());
    detector.set_positions_on_device(ib, near_xyz.data(), b.num_vertices());
    EXPECT_EQ(pairs_of(detector.detect(), 0, ib), expected_near);
}

TEST(DeviceApi, PositionsGivenOnTheDeviceBeforeAnObjectIsAddedAreKeptOrRejected) {
    const TetMesh a = test::random_soup(400, 2.0, 1.0, 100), b = test::random_soup(400, 2.0, 1.0, 101);
    const TetMesh near = test::moved(b, 0.4, 0.3, 0.0, 0.0);
    const auto expected_near = collide(a, near);
    const auto expected_rest = collide(a, b);
    ASSERT_NE(expected_near, expected_rest);
    std::vector<float> xyz = as_float(near);
    Detector detector;
    detector.add_object(a);
    const ObjectId ib = detector.add_object(b);
    detector.detect();

    // Staged, then the topology changes before any frame adopts them: the new pipeline gets them.
    detector.set_positions_on_device(ib, xyz.data(), b.num_vertices());
    detector.add_object(test::random_soup(10, 100.0, 0.0, 102));
    EXPECT_EQ(pairs_of(detector.detect(), 0, ib), expected_near);

    // The same with a bad value: the rebuild reports it and keeps the previous positions.
    const std::vector<float> good = xyz;
    xyz[0] = std::nanf("");
    detector.set_positions(ib, as_float(b).data(), b.num_vertices());
    detector.detect();
    detector.set_positions_on_device(ib, xyz.data(), b.num_vertices());
    detector.add_object(test::random_soup(10, 100.0, 0.0, 103));
    expect_error_naming([&] { detector.detect(); }, "object 1: vertex 0 of the positions given on the device");
    EXPECT_EQ(pairs_of(detector.detect(), 0, ib), expected_rest);
}

} // namespace
} // namespace kdet
