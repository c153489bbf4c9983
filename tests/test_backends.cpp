// The CUDA backend must return exactly the CPU backend's answer for every method, test, hash and
// scene. Without a GPU these tests report themselves skipped, with the reason.

#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/locate.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>

#if defined(KDET_HAS_CUDA)
#include <cuda_runtime.h>
#endif

namespace kdet {
namespace {

/// Contacts come from the same float code on both backends (no FMA contraction on either), so they
/// must agree to the bit.
void expect_same_contacts(const std::vector<Contact>& cuda, const std::vector<Contact>& cpu, const std::string& where) {
    ASSERT_EQ(cuda.size(), cpu.size()) << where;
    std::size_t differing = 0;
    for (std::size_t k = 0; k < cpu.size(); ++k) differing += std::memcmp(&cuda[k], &cpu[k], sizeof(Contact)) != 0;
    EXPECT_EQ(differing, 0u) << where << ": contacts that differ from the CPU's";
}

FrameResult detect_on(Backend backend, const std::vector<TetMesh>& meshes, bool self, DetectorOptions options) {
    options.backend = backend;
    Detector detector(options);
    for (const TetMesh& m : meshes) detector.set_self_collision(detector.add_object(m), self);
    return detector.detect();
}

void expect_backends_agree(const std::vector<TetMesh>& meshes, bool self, const DetectorOptions& options) {
    const FrameResult cpu = detect_on(Backend::cpu, meshes, self, options);
    const FrameResult cuda = detect_on(Backend::cuda, meshes, self, options);
    EXPECT_EQ(cuda.pairs, cpu.pairs) << to_string(options.method) << " " << to_string(options.narrow_phase) << " "
                                     << to_string(options.hash);
    EXPECT_EQ(cuda.colliding, cpu.colliding);
    expect_same_contacts(cuda.contacts, cpu.contacts, to_string(options.method));
    if (options.method == Method::kdet) {
        EXPECT_EQ(cuda.counts.narrow_phase_candidates, cpu.counts.narrow_phase_candidates);
    }
    if (options.method != Method::kdet_no_pairs) { // kdet_no_pairs skips pairs in a racy order
        EXPECT_EQ(cuda.counts.exact_stage_pairs, cpu.counts.exact_stage_pairs);
    }
}

class CudaBackend : public ::testing::Test {
protected:
    void SetUp() override {
        std::string reason;
        if (!cuda_available(&reason)) GTEST_SKIP() << "CUDA backend not tested: " << reason;
    }
};

TEST_F(CudaBackend, EveryMethodTestAndHashMatchesTheCpuOnSoups) {
    const TetMesh a = test::random_soup(2000, 6.0, 3.0, 81), b = test::random_soup(2000, 6.0, 3.0, 82);
    for (Method method : {Method::kdet, Method::kdet_no_pairs, Method::brute_force_loop, Method::brute_force_pairs})
        for (NarrowPhase test : {NarrowPhase::sat, NarrowPhase::sat_no_edges, NarrowPhase::sat_mtv, NarrowPhase::gjk,
                                 NarrowPhase::fast, NarrowPhase::exact}) {
            DetectorOptions o;
            o.method = method;
            o.narrow_phase = test;
            expect_backends_agree({a, b}, true, o);
        }
    for (HashFunction hash : {HashFunction::djb2, HashFunction::fnv1a, HashFunction::simple, HashFunction::morton})
        for (int block : {16, 32, 64, 128, 256, 512, 1024}) {
            DetectorOptions o;
            o.hash = hash;
            o.block_size = block;
            expect_backends_agree({a, b}, true, o);
        }
}

TEST_F(CudaBackend, RealMeshesAndTinyBuffersMatchTheCpu) {
    for (const char* model : {"bunny.mesh", "hand.mesh", "octopus-low.mesh"}) {
        const TetMesh mesh = test::load_model(model);
        const double e = test::extent_of(mesh);
        DetectorOptions o;
        expect_backends_agree({mesh, test::moved(mesh, 0.3, 0.1 * e, 0.05 * e, 0.0)}, true, o);
        o.initial_candidate_capacity = 1;
        o.bucket_capacity = 2;
        o.contacts = true;
        expect_backends_agree({mesh, test::moved(mesh, 0.3, 0.1 * e, 0.05 * e, 0.0)}, true, o);
    }
}

/// A mesh against an exact copy of itself touches everywhere: most pairs take the exact test's exact
/// stage, which then runs on the GPU.
TEST_F(CudaBackend, ExactStageMatchesTheCpuOnTouchingCopies) {
    const TetMesh mesh = test::load_model("octopus-low.mesh");
    for (Method method : {Method::kdet, Method::kdet_no_pairs, Method::brute_force_loop, Method::brute_force_pairs}) {
        DetectorOptions o;
        o.method = method;
        o.narrow_phase = NarrowPhase::exact;
        expect_backends_agree({mesh, mesh}, true, o);
    }
}

TEST_F(CudaBackend, ProceduralSceneFramesMatchTheCpu) {
    ProceduralSceneOptions scene_options;
    scene_options.total_tets = 50000;
    scene_options.frames = 7;
    const ProceduralScene scene(scene_options);
    DetectorOptions cpu_options, cuda_options;
    cuda_options.backend = Backend::cuda;
    Detector cpu(cpu_options), cuda(cuda_options);
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        cpu.set_self_collision(cpu.add_object(scene.rest_mesh(o)), true);
        cuda.set_self_collision(cuda.add_object(scene.rest_mesh(o)), true);
    }
    std::vector<float> xyz;
    for (int f = 0; f < scene.num_frames(); ++f) {
        for (std::size_t o = 0; o < scene.num_objects(); ++o) {
            scene.positions(o, f, xyz);
            cpu.set_positions(static_cast<ObjectId>(o), xyz.data(), xyz.size() / 3);
            cuda.set_positions(static_cast<ObjectId>(o), xyz.data(), xyz.size() / 3);
        }
        EXPECT_EQ(cuda.detect().pairs, cpu.detect().pairs) << "frame " << f;
    }
}

/// Every frame of the thesis scenes at resolution 1, every object against itself too, with contacts:
/// pairs, flags and contacts as the CPU's. Uses the meshes that `kdet prepare` left in the cache.
TEST_F(CudaBackend, ThesisSceneFramesMatchTheCpu) {
    test::use_default_data_dir();
    for (const char* name : {"armadillos", "buddha_and_armadillo", "bunny_and_planck", "pass_through_armadillos"}) {
        std::unique_ptr<Scene> scene;
        try {
            scene = open_scene(name);
        } catch (const Error& e) {
            GTEST_SKIP() << e.what();
        }
        DetectorOptions cpu_options, cuda_options;
        cpu_options.contacts = cuda_options.contacts = true;
        cuda_options.backend = Backend::cuda;
        Detector cpu(cpu_options), cuda(cuda_options);
        for (std::size_t o = 0; o < scene->num_objects(); ++o) {
            cpu.set_self_collision(cpu.add_object(scene->rest_mesh(o)), true);
            cuda.set_self_collision(cuda.add_object(scene->rest_mesh(o)), true);
        }
        std::vector<float> xyz;
        std::size_t frames_with_pairs = 0;
        for (int f = 0; f < scene->num_frames(); ++f) {
            for (std::size_t o = 0; o < scene->num_objects(); ++o) {
                scene->positions(o, f, xyz);
                cpu.set_positions(static_cast<ObjectId>(o), xyz.data(), xyz.size() / 3);
                cuda.set_positions(static_cast<ObjectId>(o), xyz.data(), xyz.size() / 3);
            }
            const FrameResult& expected = cpu.detect();
            const FrameResult& got = cuda.detect();
            const std::string where = std::string(name) + " frame " + std::to_string(f);
            EXPECT_EQ(got.pairs, expected.pairs) << where;
            EXPECT_EQ(got.colliding, expected.colliding) << where;
            expect_same_contacts(got.contacts, expected.contacts, where);
            frames_with_pairs += !expected.pairs.empty();
        }
        EXPECT_GT(frames_with_pairs, 0u) << name;
    }
}

#if defined(KDET_HAS_CUDA)
TEST_F(CudaBackend, PageableHostMemoryGivenAsTheDevicesIsRefusedWhereTheGpuCannotReadIt) {
    const TetMesh a = test::random_soup(2000, 3.0, 1.0, 101), b = test::moved(a, 0.3, 0.2, 0.0, 0.0);
    DetectorOptions o;
    o.backend = Backend::cuda;
    Detector detector(o);
    detector.add_object(a);
    const ObjectId ib = detector.add_object(b);
    const std::vector<float> xyz(b.positions.begin(), b.positions.end()); // pageable: std::vector's
    const std::vector<double> points(a.positions.begin(), a.positions.begin() + 30);
    const PositionsView host_points{points.data(), true, 10};
    const FrameResult expected = detector.detect();
    ASSERT_FALSE(expected.pairs.empty());
    const LocateResult expected_hits = detector.locate(host_points, all_objects);
    int device = 0, pageable_access = 0;
    ASSERT_EQ(cudaGetDevice(&device), cudaSuccess);
    ASSERT_EQ(cudaDeviceGetAttribute(&pageable_access, cudaDevAttrPageableMemoryAccess, device), cudaSuccess);
    if (pageable_access) { // HMM or ATS: the GPU reads it, and it is used as any device memory
        detector.set_positions_on_device(ib, xyz.data(), b.num_vertices());
        EXPECT_EQ(detector.detect().pairs, expected.pairs);
        EXPECT_EQ(detector.locate_on_device(host_points, all_objects, {}).tets, expected_hits.tets);
        return;
    }
    const std::string positions_error = test::error_message([&] { detector.set_positions_on_device(ib, xyz.data(), b.num_vertices()); });
    EXPECT_NE(positions_error.find("set_positions_on_device: the positions lie in pageable host memory"), std::string::npos)
        << positions_error;
    const std::string points_error = test::error_message([&] { detector.locate_on_device(host_points, all_objects, {}); });
    EXPECT_NE(points_error.find("locate_on_device: the points lie in pageable host memory"), std::string::npos)
        << points_error;
    EXPECT_EQ(detector.detect().pairs, expected.pairs); // the detector carries on as before
}

TEST_F(CudaBackend, DevicePositionsAndDeviceResultsNeverPassThroughTheHost) {
    const TetMesh a = test::random_soup(3000, 5.0, 2.0, 97), b = test::random_soup(3000, 5.0, 2.0, 98);
    DetectorOptions o;
    o.backend = Backend::cuda;
    o.results_to_host = false;
    Detector detector(o);
    const ObjectId ia = detector.add_object(a), ib = detector.add_object(b);
    detector.set_self_collision(ia, true);
    detector.detect(); // uploads the topology
    const std::vector<float> xyz(b.positions.begin(), b.positions.end());
    float* device_xyz = nullptr;
    ASSERT_EQ(cudaMalloc(reinterpret_cast<void**>(&device_xyz), xyz.size() * sizeof(float)), cudaSuccess);
    ASSERT_EQ(cudaMemcpy(device_xyz, xyz.data(), xyz.size() * sizeof(float), cudaMemcpyHostToDevice), cudaSuccess);
    detector.set_positions_on_device(ib, device_xyz, b.num_vertices());
    cudaFree(device_xyz);
    detector.detect();
    const DeviceResults dr = detector.device_results();
    std::vector<std::uint64_t> keys(dr.pair_count);
    ASSERT_EQ(cudaMemcpy(keys.data(), dr.pair_keys, keys.size() * sizeof(std::uint64_t), cudaMemcpyDeviceToHost),
              cudaSuccess);
    Detector cpu_self;
    cpu_self.set_self_collision(cpu_self.add_object(a), true);
    cpu_self.add_object(b);
    const FrameResult& expected = cpu_self.detect();
    ASSERT_EQ(keys.size(), expected.pairs.size());
    for (std::size_t k = 0; k < keys.size(); ++k) {
        const TetPair& p = expected.pairs[k];
        EXPECT_EQ(keys[k], (std::uint64_t{detector.first_tet(p.object_a) + p.tet_a} << 32) |
                               (detector.first_tet(p.object_b) + p.tet_b));
    }
}
#endif

#if defined(KDET_HAS_CUDA)
TEST_F(CudaBackend, AFrameOnTheCallersStreamReadsPositionsWrittenBeforeItOnThatStream) {
    const TetMesh a = test::random_soup(4000, 5.0, 2.0, 31), b = test::random_soup(4000, 5.0, 2.0, 32);
    const TetMesh b_moved = test::moved(b, 0.5, -0.3, 0.2, 0.0);
    cudaStream_t stream = nullptr;
    ASSERT_EQ(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking), cudaSuccess);
    DetectorOptions o;
    o.backend = Backend::cuda;
    o.cuda_stream = stream;
    o.contacts = true;
    Detector detector(o);
    const ObjectId ia = detector.add_object(a), ib = detector.add_object(b);
    detector.set_self_collision(ia, true);
    detector.detect();

    // The caller's simulation writes the new positions on its stream and hands them over at once.
    const std::vector<float> xyz(b_moved.positions.begin(), b_moved.positions.end());
    float* pinned = nullptr;
    float* device_xyz = nullptr;
    ASSERT_EQ(cudaMallocHost(reinterpret_cast<void**>(&pinned), xyz.size() * sizeof(float)), cudaSuccess);
    ASSERT_EQ(cudaMalloc(reinterpret_cast<void**>(&device_xyz), xyz.size() * sizeof(float)), cudaSuccess);
    std::copy(xyz.begin(), xyz.end(), pinned);
    ASSERT_EQ(cudaMemsetAsync(device_xyz, 0xff, xyz.size() * sizeof(float), stream), cudaSuccess); // NaN first
    ASSERT_EQ(cudaMemcpyAsync(device_xyz, pinned, xyz.size() * sizeof(float), cudaMemcpyHostToDevice, stream),
              cudaSuccess);
    detector.set_positions_on_device(ib, device_xyz, b.num_vertices());
    const FrameResult& got = detector.detect();

    DetectorOptions cpu_options;
    cpu_options.contacts = true;
    Detector cpu(cpu_options);
    cpu.set_self_collision(cpu.add_object(a), true);
    cpu.add_object(b_moved);
    const FrameResult& expected = cpu.detect();
    ASSERT_GT(expected.pairs.size(), 10u);
    EXPECT_EQ(got.pairs, expected.pairs);
    EXPECT_EQ(got.colliding, expected.colliding);
    expect_same_contacts(got.contacts, expected.contacts, "caller's stream");

    // The same frame enqueued without a wait: finish() waits once and gives the same answer.
    detector.set_positions_on_device(ib, device_xyz, b.num_vertices());
    detector.detect_async();
    const FrameResult& finished = detector.finish();
    EXPECT_EQ(finished.counts.host_waits, 1u);
    EXPECT_EQ(finished.pairs, expected.pairs);
    EXPECT_EQ(finished.colliding, expected.colliding);
    cudaFree(device_xyz);
    cudaFreeHost(pinned);
    cudaStreamDestroy(stream);
}
#endif

TEST(CudaAvailability, AnUnavailableBackendIsAClearErrorNotASilentFallback) {
    std::string reason;
    if (cuda_available(&reason)) GTEST_SKIP() << "a CUDA device is present; the error path is not reachable here";
    EXPECT_FALSE(reason.empty());
    DetectorOptions o;
    o.backend = Backend::cuda;
    try {
        Detector detector(o);
        FAIL() << "expected kdet::Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("cuda"), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace kdet
