// The pipeline over memory that the host cannot touch (device_like_exec.hpp): the paths CUDA takes,
// run on the CPU. With KDET_TEST_DEVICE_LIKE_MEMORY=1 every Detector of this test program runs so
// (ctest's device_like_memory entry); without it, the tests below compare the two layers.
#include "device_like_exec.hpp"
#include "pipeline/baselines.hpp"
#include "test_support.hpp"

#include <kdet/kdet.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace kdet {
namespace {

using device_like::DeviceLikeExec;
using device_like::GuardedArena;
using device_like::GuardedBuffer;
using test::load_model;
using test::moved;

std::unique_ptr<PipelineBase> make_device_like_pipeline(const DetectorOptions& options) {
    return make_pipeline<DeviceLikeExec>(options);
}

bool every_detector_device_like() {
    const char* value = std::getenv("KDET_TEST_DEVICE_LIKE_MEMORY");
    return value && std::string(value) == "1";
}

const bool installed = [] {
    if (every_detector_device_like()) set_cpu_pipeline_factory(&make_device_like_pipeline);
    return true;
}();

/// While it lives, Detectors built on the CPU backend run over the layer `factory` makes (nullptr:
/// CpuExec); then as the program's environment says.
class CpuPipelinesFrom {
public:
    explicit CpuPipelinesFrom(PipelineFactory factory) { set_cpu_pipeline_factory(factory); }
    ~CpuPipelinesFrom() { set_cpu_pipeline_factory(every_detector_device_like() ? &make_device_like_pipeline : nullptr); }
    CpuPipelinesFrom(const CpuPipelinesFrom&) = delete;
    CpuPipelinesFrom& operator=(const CpuPipelinesFrom&) = delete;
};

void skip_without_arena() {
    if (!GuardedArena::instance().usable()) GTEST_SKIP() << "no address space could be reserved for the guarded arena";
}

template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void expect_same_frame(const FrameResult& got, const FrameResult& expected, const std::string& what) {
    EXPECT_EQ(got.pairs, expected.pairs) << what;
    EXPECT_TRUE(same_bytes(got.contacts, expected.contacts)) << what;
    EXPECT_TRUE(same_bytes(got.distances, expected.distances)) << what;
    EXPECT_TRUE(same_bytes(got.closest_points, expected.closest_points)) << what;
    EXPECT_EQ(got.colliding, expected.colliding) << what;
    EXPECT_EQ(got.counts.candidates, expected.counts.candidates) << what;
    EXPECT_EQ(got.counts.host_waits, expected.counts.host_waits) << what;
}

void expect_same_location(const LocateResult& got, const LocateResult& expected, const std::string& what) {
    EXPECT_EQ(got.offsets, expected.offsets) << what;
    EXPECT_EQ(got.objects, expected.objects) << what;
    EXPECT_EQ(got.tets, expected.tets) << what;
    EXPECT_TRUE(same_bytes(got.barycentrics, expected.barycentrics)) << what;
    EXPECT_TRUE(same_bytes(got.closest_points, expected.closest_points)) << what;
    EXPECT_TRUE(same_bytes(got.distances, expected.distances)) << what;
}

/// A buffer of the guarded arena holding i * step + first at i, written by a kernel of `exec`.
GuardedBuffer<std::uint32_t> written_by_a_kernel(const DeviceLikeExec& exec, std::size_t n, std::uint32_t step,
                                                 std::uint32_t first) {
    GuardedBuffer<std::uint32_t> buffer;
    buffer.resize_discard(n);
    std::uint32_t* data = buffer.data();
    exec.for_each(n, [=](std::uint64_t i) { data[i] = static_cast<std::uint32_t>(i) * step + first; });
    return buffer;
}

TEST(DeviceLikeMemory, HostCodeTouchingABufferOutsideALayerCallDies) {
    skip_without_arena();
    const DeviceLikeExec exec{DetectorOptions{}};
    GuardedBuffer<std::uint32_t> buffer = written_by_a_kernel(exec, 1000, 3, 0);
    std::uint32_t* data = buffer.data();
    std::vector<std::uint32_t> host(1000);
    exec.download(host.data(), data, host.size());
    EXPECT_EQ(host[999], 2997u);
    ::testing::FLAGS_gtest_death_test_style = "threadsafe"; // the layer's threads are running
    EXPECT_DEATH({ data[7] = 1; }, "host code touched device-like memory");
    EXPECT_DEATH({ std::printf("%u\n", static_cast<unsigned>(data[3])); }, "host code touched device-like memory");
}

TEST(DeviceLikeMemory, AFreshBufferHoldsAPatternNotZeros) {
    skip_without_arena();
    const DeviceLikeExec exec{DetectorOptions{}};
    for (int round = 0; round < 2; ++round) { // the second reuses the pages the first gave back
        GuardedBuffer<std::uint32_t> buffer;
        buffer.resize_discard(5000);
        std::vector<std::uint32_t> host(buffer.size());
        exec.download(host.data(), buffer.data(), host.size());
        EXPECT_EQ(std::count(host.begin(), host.end(), 0xA5A5A5A5u), 5000) << round;
        exec.for_each(host.size(), [data = buffer.data()](std::uint64_t i) { data[i] = 0; });
    }
}

TEST(DeviceLikeMemory, ALandedDownloadIsReadBeforeTheNextDownload) {
    skip_without_arena();
    const DeviceLikeExec exec{DetectorOptions{}};
    GuardedBuffer<std::uint32_t> buffer = written_by_a_kernel(exec, 4, 1, 1);
    const std::uint32_t* data = buffer.data();
    const std::size_t view = exec.download_view_later(data, 4);
    exec.finish_downloads();
    EXPECT_EQ(exec.template landed<std::uint32_t>(view)[3], 4u);
    std::uint32_t one = 0;
    exec.download(&one, data, 1); // as on the GPU, which stages it where the view landed
    EXPECT_EQ(one, 1u);
    EXPECT_EQ(exec.template landed<std::uint32_t>(view)[3], 0xA5A5A5A5u);
}

/// Two octopuses whose tentacles overlap, and options that report their pairs within a margin of
/// about a tenth of an edge with distances and contacts.
struct OverlappingOctopuses {
    TetMesh first = load_model("octopus-low.mesh");
    TetMesh second = moved(first, 0.1, 0.6, 0.01, 0.0);
    DetectorOptions options = [] {
        DetectorOptions o;
        o.margin = 0.01f;
        o.distances = true;
        o.contacts = true;
        return o;
    }();
};

/// Frames of two octopuses with what this round added switched on one after the other: pairs
/// within a margin with their distances and contacts, filters, a static object, new tets, exclusion
/// rings; then point location with and without `within`. Each as the CPU's own layer answers it.
std::vector<std::pair<std::string, FrameResult>> frames_of_every_feature(std::vector<LocateResult>& locations) {
    const OverlappingOctopuses scene;
    const TetMesh &octopus = scene.first, &other = scene.second;
    DetectorOptions options = scene.options;
    Detector detector(options);
    const ObjectId a = detector.add_object(octopus), b = detector.add_object(other);
    detector.set_self_collision(a, true);
    detector.set_self_collision(b, true);
    std::vector<std::pair<std::string, FrameResult>> frames;
    frames.emplace_back("margin, distances, contacts", detector.detect());
    const TetMesh shifted = moved(other, 0.02, 0.03, 0.0, 0.0);
    detector.set_positions(b, shifted.positions.data(), shifted.num_vertices());
    frames.emplace_back("moved", detector.detect());
    detector.set_collision_filter(a, 1, 1);
    detector.set_collision_filter(b, 2, 3);
    frames.emplace_back("filters", detector.detect());
    detector.set_collision_filter(a, 1, ~0u);
    detector.set_static(a, true);
    frames.emplace_back("static", detector.detect());
    detector.set_self_exclusion_rings(b, 2);
    frames.emplace_back("rings", detector.detect());
    detector.exclude_rest_contacts(a, b);
    frames.emplace_back("rest contacts excluded", detector.detect());
    const std::vector<std::uint32_t> half(other.tets.begin(), other.tets.begin() + 4 * (other.num_tets() / 2));
    detector.set_tets(b, half.data(), half.size() / 4);
    frames.emplace_back("half the tets", detector.detect());
    detector.detect_async();
    frames.emplace_back("async", detector.finish());

    std::vector<double> points;
    for (std::size_t v = 0; v < octopus.num_vertices(); ++v) // each vertex nudged, some out of every tet
        for (std::size_t k = 0; k < 3; ++k)
            points.push_back(octopus.positions[3 * v + k] + 0.02 * static_cast<double>((v + k) % 5) - 0.04);
    const PositionsView view{points.data(), true, points.size() / 3};
    locations.push_back(detector.locate(view, all_objects));
    LocateOptions within;
    within.within = 0.05;
    locations.push_back(detector.locate(view, a, within));
    locations.push_back(locate(octopus, points, within));
    return frames;
}

TEST(DeviceLikeMemory, EveryFeatureAnswersAsOnTheHostsMemory) {
    skip_without_arena();
    std::vector<LocateResult> expected_locations;
    std::vector<std::pair<std::string, FrameResult>> expected;
    {
        const CpuPipelinesFrom host_memory(nullptr);
        expected = frames_of_every_feature(expected_locations);
    }
    std::vector<LocateResult> locations;
    std::vector<std::pair<std::string, FrameResult>> got;
    {
        const CpuPipelinesFrom device_like(&make_device_like_pipeline);
        got = frames_of_every_feature(locations);
    }
    ASSERT_EQ(got.size(), expected.size());
    for (std::size_t f = 0; f < got.size(); ++f) expect_same_frame(got[f].second, expected[f].second, got[f].first);
    EXPECT_GT(expected.front().second.pairs.size(), 1000u);
    EXPECT_EQ(expected.front().second.distances.size(), expected.front().second.pairs.size());
    ASSERT_EQ(locations.size(), expected_locations.size());
    for (std::size_t l = 0; l < locations.size(); ++l)
        expect_same_location(locations[l], expected_locations[l], "location " + std::to_string(l));
    EXPECT_GT(expected_locations[1].hit_count, 300u);
    EXPECT_LT(expected[2].second.pairs.size(), expected[1].second.pairs.size()); // the filters left self-collision only
}

TEST(DeviceLikeMemory, ResultsLeftInTheBackendsMemoryEqualTheHostResults) {
    skip_without_arena();
    const OverlappingOctopuses scene;
    const TetMesh &octopus = scene.first, &other = scene.second;
    DetectorOptions options = scene.options;
    std::vector<double> points(octopus.positions.begin(), octopus.positions.end());
    for (std::size_t k = 0; k < points.size(); ++k) points[k] += 0.01 * static_cast<double>(k % 7) - 0.03;
    const PositionsView view{points.data(), true, points.size() / 3};
    LocateOptions within;
    within.within = 0.05;
    Detector host(options);
    options.results_to_host = false;
    const CpuPipelinesFrom device_like(&make_device_like_pipeline);
    Detector device(options);
    for (Detector* d : {&host, &device}) {
        d->set_self_collision(d->add_object(octopus), true);
        d->add_object(other);
    }
    const FrameResult& expected = host.detect();
    ASSERT_GT(expected.pairs.size(), 500u);
    EXPECT_TRUE(device.detect().pairs.empty());
    const LocateResult& expected_hits = host.locate(view, all_objects, within);
    ASSERT_GT(expected_hits.hit_count, 300u);
    within.results_to_host = false;
    EXPECT_TRUE(device.locate(view, all_objects, within).tets.empty());

    const GuardedArena::Opened readable; // as a CUDA user's copy to the host would
    const DeviceResults dr = device.device_results();
    ASSERT_EQ(dr.pair_count, expected.pairs.size());
    for (std::size_t k = 0; k < dr.pair_count; ++k) {
        const TetPair& p = expected.pairs[k];
        ASSERT_EQ(dr.pair_keys[k], std::uint64_t{host.first_tet(p.object_a) + p.tet_a} << 32 |
                                       (host.first_tet(p.object_b) + p.tet_b));
        ASSERT_EQ(std::memcmp(&dr.contacts[k], &expected.contacts[k], sizeof(Contact)), 0) << k;
        ASSERT_EQ(std::memcmp(&dr.distances[k], &expected.distances[k], sizeof(float)), 0) << k;
        ASSERT_EQ(std::memcmp(&dr.closest_points[k], &expected.closest_points[k], sizeof(ClosestPoints)), 0) << k;
    }
    const DeviceLocateResults dl = device.device_locate_results();
    ASSERT_EQ(dl.point_count, expected_hits.point_count);
    ASSERT_EQ(dl.hit_count, expected_hits.hit_count);
    EXPECT_TRUE(std::equal(dl.offsets, dl.offsets + dl.point_count + 1, expected_hits.offsets.begin()));
    EXPECT_TRUE(std::equal(dl.tets, dl.tets + dl.hit_count, expected_hits.tets.begin()));
    EXPECT_TRUE(std::equal(dl.objects, dl.objects + dl.hit_count, expected_hits.objects.begin()));
    EXPECT_EQ(std::memcmp(dl.barycentrics, expected_hits.barycentrics.data(), 4 * dl.hit_count * sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(dl.distances, expected_hits.distances.data(), dl.hit_count * sizeof(double)), 0);
}

} // namespace
} // namespace kdet
