#pragma once
/// @file gpu_peer.cuh
/// @brief What the GPU peers (gpu_vs_sweep.cu, gpu_vs_cubql.cu) share: the pair keys a peer's kernel
/// appends (growing and running again when they do not fit), kdet's CUDA side of a case, and main().
///
/// Per frame, outside any timing: the scene's positions are uploaded once into one device buffer that
/// both sides read (kdet copies them into its own buffer with set_positions_on_device, enqueued before
/// its start event). Timed with CUDA events on one stream, each including its waits for the device:
/// kdet's Detector::detect() (Backend::cuda, results left on the device, sorted) and the peer's
/// detect(positions), which returns its pair count and leaves its keys, in any order, on the device.

#include "scene_frames.hpp"

#include "exec/cuda_exec.cuh"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <cuda_runtime.h>

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace kdet::bench {

inline unsigned grid_for(std::uint32_t count, unsigned block) { return (count + block - 1) / block; }

/// Where a peer's kernel appends its pairs: every pair is counted, also those past the capacity, so
/// that the host can grow the buffer and run the kernel again.
struct KeyOutput {
    unsigned long long* keys;
    unsigned long long capacity;
    unsigned long long* found;

    __device__ void push(std::uint32_t lo, std::uint32_t hi) const {
        const unsigned long long slot = atomicAdd(found, 1ull);
        if (slot < capacity) keys[slot] = pair_key(lo, hi);
    }
};

/// A peer's pair keys, kept between frames as a simulation's would be.
class KeyBuffer {
public:
    explicit KeyBuffer(std::size_t capacity) {
        keys_.resize_discard(std::max<std::size_t>(capacity, 1024));
        found_.resize_discard(1);
        found_host_ = reinterpret_cast<unsigned long long*>(found_pinned_.reserve(sizeof(unsigned long long)));
    }

    /// Enqueues launch(KeyOutput) on the stream and reads the pair count back; if the keys did not fit,
    /// grows the buffer and launches again (never drops a pair). Returns the pair count.
    template <class Launch>
    std::size_t collect(cudaStream_t stream, Launch&& launch) {
        for (;;) {
            cuda_check(cudaMemsetAsync(found_.data(), 0, sizeof(unsigned long long), stream), "cudaMemsetAsync");
            launch(KeyOutput{keys_.data(), keys_.size(), found_.data()});
            cuda_check(cudaGetLastError(), "peer kernel");
            cuda_check(cudaMemcpyAsync(found_host_, found_.data(), sizeof(unsigned long long), cudaMemcpyDeviceToHost,
                                       stream), "cudaMemcpyAsync");
            cuda_check(cudaStreamSynchronize(stream), "cudaStreamSynchronize");
            const std::size_t found = static_cast<std::size_t>(*found_host_);
            if (found <= keys_.size()) return found;
            keys_.resize_discard(found + found / 2);
        }
    }
    const unsigned long long* keys() const { return keys_.data(); }

private:
    DeviceBuffer<unsigned long long> keys_, found_;
    PinnedBuffer found_pinned_;
    unsigned long long* found_host_ = nullptr; ///< in found_pinned_
};

inline std::vector<std::uint64_t> keys_to_host(const void* keys, std::size_t count, cudaStream_t stream) {
    std::vector<std::uint64_t> out(count);
    if (count)
        cuda_check(cudaMemcpyAsync(out.data(), keys, count * sizeof(std::uint64_t), cudaMemcpyDeviceToHost, stream),
                   "cudaMemcpyAsync");
    cuda_check(cudaStreamSynchronize(stream), "cudaStreamSynchronize");
    return out;
}

template <class Peer, class = void>
struct has_check : std::false_type {};
template <class Peer>
struct has_check<Peer, std::void_t<decltype(std::declval<Peer&>().check())>> : std::true_type {};

/// One case: kdet (CUDA backend, narrow-phase test `test`) and a `Peer` built from the layout and the
/// stream (with `std::size_t detect(const float* positions)`, `keys()` and, optionally, `check()`, which
/// throws kdet::Error if what detect() built is unfit), frame by frame.
template <class Peer>
CaseResult run_gpu_case(const PeerConfig& config, const Scene& scene, CaseResult result, NarrowPhase test,
                        cudaStream_t stream) {
    DetectorOptions options;
    options.backend = Backend::cuda;
    options.narrow_phase = test;
    options.results_to_host = false;
    options.cuda_stream = stream;
    Detector detector(options);
    add_scene_objects(detector, scene, result.self);
    const SceneLayout layout(scene, result.self);
    layout.check_numbering(detector);
    Peer peer(layout, stream);

    DeviceBuffer<float> positions;
    positions.resize_discard(3 * layout.vertex_count());
    std::vector<float> host;
    cudaEvent_t start, stop;
    cuda_check(cudaEventCreate(&start), "cudaEventCreate");
    cuda_check(cudaEventCreate(&stop), "cudaEventCreate");
    const auto timed = [&](auto&& work) {
        cuda_check(cudaEventRecord(start, stream), "cudaEventRecord");
        work();
        cuda_check(cudaEventRecord(stop, stream), "cudaEventRecord");
        cuda_check(cudaEventSynchronize(stop), "cudaEventSynchronize");
        float ms = 0.0f;
        cuda_check(cudaEventElapsedTime(&ms, start, stop), "cudaEventElapsedTime");
        return static_cast<double>(ms);
    };
    result = run_frames(config, scene, result, [&](int frame, bool first_pass) {
        layout.positions(scene, frame, host);
        cuda_check(cudaMemcpyAsync(positions.data(), host.data(), host.size() * sizeof(float), cudaMemcpyHostToDevice,
                                   stream), "cudaMemcpyAsync");
        for (std::size_t o = 0; o < layout.objects; ++o)
            detector.set_positions_on_device(static_cast<ObjectId>(o), positions.data() + 3 * layout.vertex_begin[o],
                                             layout.vertex_begin[o + 1] - layout.vertex_begin[o]);
        FrameOutcome outcome;
        outcome.kdet_ms = timed([&] { detector.detect(); });
        std::size_t peer_count = 0;
        outcome.peer_ms = timed([&] { peer_count = peer.detect(positions.data()); });
        if constexpr (has_check<Peer>::value)
            if (first_pass) peer.check(); // once per frame, untimed
        const DeviceResults kdet_results = detector.device_results();
        outcome.kdet_keys = keys_to_host(kdet_results.pair_keys, kdet_results.pair_count, stream);
        outcome.peer_keys = keys_to_host(peer.keys(), peer_count, stream);
        return outcome;
    });
    cuda_check(cudaEventDestroy(start), "cudaEventDestroy");
    cuda_check(cudaEventDestroy(stop), "cudaEventDestroy");
    return result;
}

inline std::string version_text(int version) {
    return std::to_string(version / 1000) + "." + std::to_string(version % 1000 / 10);
}

/// The kernel driver's release (e.g. 570.124.06), which the CUDA API does not report: the first
/// number with a dot on the first line of /proc/driver/nvidia/version; "unknown" without it.
inline std::string driver_release() {
    std::ifstream in("/proc/driver/nvidia/version");
    std::string line, word;
    std::getline(in, line);
    std::istringstream words(line);
    while (words >> word)
        if (std::isdigit(static_cast<unsigned char>(word[0])) && word.find('.') != std::string::npos) return word;
    return "unknown";
}

/// A GPU peer program: parses the command line over `defaults`, runs every case with kdet's test
/// `test` against `Peer`, prints the device, the progress and the table (the peer's columns named
/// `peer`), and writes csv(results) to --csv. Exit status: 0, 1 on a mismatching frame or an error,
/// 2 for a bad command line.
template <class Peer>
int gpu_peer_main(int argc, char** argv, const char* program, const PeerConfig& defaults, NarrowPhase test,
                  const char* peer, std::string (*csv)(const std::vector<CaseResult>&)) {
    const PeerConfig config = parse_peer_args(argc, argv, program, defaults);
    std::string reason;
    if (!cuda_available(&reason)) {
        std::fprintf(stderr, "%s: no usable GPU: %s\n", program, reason.c_str());
        return 1;
    }
    try {
        int device = 0, driver = 0, runtime = 0;
        cudaDeviceProp properties{};
        cuda_check(cudaGetDevice(&device), "cudaGetDevice");
        cuda_check(cudaGetDeviceProperties(&properties, device), "cudaGetDeviceProperties");
        cuda_check(cudaDriverGetVersion(&driver), "cudaDriverGetVersion");
        cuda_check(cudaRuntimeGetVersion(&runtime), "cudaRuntimeGetVersion");
        std::printf("device: %s; driver %s (CUDA %s); CUDA runtime %s; kdet %s\n", properties.name,
                    driver_release().c_str(), version_text(driver).c_str(), version_text(runtime).c_str(),
                    version().c_str());
        std::printf("%d timed runs after one untimed; medians over frames x runs\n\n", config.runs);
        cudaStream_t stream;
        cuda_check(cudaStreamCreate(&stream), "cudaStreamCreate");
        const std::vector<CaseResult> results = run_cases(config, peer, [&](const Scene& scene, CaseResult c) {
            return run_gpu_case<Peer>(config, scene, c, test, stream);
        });
        cuda_check(cudaStreamDestroy(stream), "cudaStreamDestroy");
        std::printf("%s", results_table(results, peer).c_str());
        if (!config.csv.empty() && !write_text(config.csv, csv(results), program)) return 1;
        return mismatches(results, program) ? 1 : 0;
    } catch (const std::exception& error) { // kdet::Error, and the peer library's errors
        std::fprintf(stderr, "%s: %s\n", program, error.what());
        return 1;
    }
}

} // namespace kdet::bench
