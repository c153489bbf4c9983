/// kdet's CPU backend against the cuBQL peer on the CPU, both on the same threads: per frame, the
/// tets' boxes, cuBQL's host builder (cuBQL::cpuBuilder, a recursive spatial-median builder that runs
/// on one thread; the objects' BVHs are built side by side) builds one BVH per object, and one cuBQL
/// fixedBoxQuery per tet (OpenMP over the tets) feeds kdet's exact test, kdet's default narrow phase
/// (cubql_peer.hpp, the same code the GPU peer runs), so both give the same pair set, which every
/// frame checks. The previous frame's BVHs are freed at the start of the next, inside its timing.
///
/// Per frame, outside any timing: the scene's positions, concatenated, which the peer reads where they
/// lie and kdet gets with Detector::set_positions. Timed with a steady clock: kdet's detect() (sorted
/// pairs) and the peer's frame (its keys in any order). One untimed pass warms both up; every pass
/// compares the pair sets of every frame.
///
/// usage: kdet_cpu_vs_cubql [--scenes a,b,...] [-r N] [--frames A:B] [--runs N] [--tets N,...] [--csv FILE]
///                          [--threads N]
///   --scenes, -r, --frames, --runs: as kdet_gpu_vs_cubql (the same default scenes)
///   --tets N   tets of the procedural scene, one case each (default 100000,1000000)
///   --csv FILE scene,self,frames,kdet_ms,cubql_ms,ratio,same_pairs, one row per case
///   --threads  threads of both sides (default 2)
/// Exit status: 0, 1 on a mismatching frame or an error, 2 for a bad command line.
///
/// cuBQL is NVIDIA's (Apache-2.0), read from ../shared/third_party/cuBQL, never part of kdet.

#include <cuBQL/bvh.h>
#include <cuBQL/builder/cpu.h>

#include "cubql_peer.hpp"
#include "scene_frames.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <omp.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

namespace {

using namespace kdet;
using namespace kdet::bench;

class CubqlCpuPeer {
public:
    CubqlCpuPeer(const SceneLayout& layout, int threads)
        : layout_(layout), threads_(threads), bvhs_(layout.objects), boxes_(layout.tets.size()),
          found_(static_cast<std::size_t>(threads)) {}
    CubqlCpuPeer(const CubqlCpuPeer&) = delete;
    CubqlCpuPeer& operator=(const CubqlCpuPeer&) = delete;
    ~CubqlCpuPeer() { free_bvhs(); }

    /// One frame; the pair keys, in any order.
    const std::vector<std::uint64_t>& detect(const std::vector<float>& xyz) {
        free_bvhs();
        const vec3* positions = reinterpret_cast<const vec3*>(xyz.data());
        const auto count = static_cast<std::int64_t>(layout_.tets.size());
#pragma omp parallel for num_threads(threads_) schedule(static)
        for (std::int64_t t = 0; t < count; ++t) boxes_[t] = cubql_box(positions, layout_.tets[t]);
        const auto objects = static_cast<std::int64_t>(bvhs_.size());
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 1)
        for (std::int64_t o = 0; o < objects; ++o) {
            const std::uint32_t begin = layout_.tet_begin[o], end = layout_.tet_begin[o + 1];
            if (end > begin) cuBQL::cpuBuilder(bvhs_[o], boxes_.data() + begin, end - begin, cuBQL::BuildConfig());
        }
        const CubqlView view{positions,          layout_.tets.data(), layout_.tet_object.data(), layout_.tet_begin.data(),
                             layout_.checked.data(), bvhs_.data(),     boxes_.data(),             static_cast<std::uint32_t>(objects)};
#pragma omp parallel num_threads(threads_)
        {
            std::vector<std::uint64_t>& mine = found_[static_cast<std::size_t>(omp_get_thread_num())];
            mine.clear();
            // Queries differ widely in cost (a tet deep inside the other object meets many candidates).
#pragma omp for schedule(dynamic, 256)
            for (std::int64_t t = 0; t < count; ++t)
                query_tet(view, static_cast<std::uint32_t>(t),
                          [&](std::uint32_t lo, std::uint32_t hi) { mine.push_back(pair_key(lo, hi)); });
        }
        keys_.clear();
        for (const std::vector<std::uint64_t>& keys : found_) keys_.insert(keys_.end(), keys.begin(), keys.end());
        return keys_;
    }

    /// Throws kdet::Error if a BVH of the last frame is deeper than cuBQL's traversal stack allows.
    void check() const {
        for (const cuBQL::bvh3f& bvh : bvhs_) {
            if (!bvh.nodes) continue;
            const int depth = bvh_depth(bvh.nodes);
            if (depth > 64) throw Error("a cuBQL BVH is " + std::to_string(depth) + " levels deep, over its traversal's stack of 64");
        }
    }

private:
    void free_bvhs() {
        for (cuBQL::bvh3f& bvh : bvhs_) cuBQL::cpu::freeBVH(bvh);
    }

    const SceneLayout& layout_;
    int threads_;
    std::vector<cuBQL::bvh3f> bvhs_; ///< [object]
    std::vector<cuBQL::box3f> boxes_;
    std::vector<std::vector<std::uint64_t>> found_; ///< [thread]
    std::vector<std::uint64_t> keys_;
};

double elapsed_ms(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

CaseResult run_cpu_case(const PeerConfig& config, const Scene& scene, CaseResult result) {
    DetectorOptions options;
    options.threads = config.threads;
    Detector detector(options);
    add_scene_objects(detector, scene, result.self);
    const SceneLayout layout(scene, result.self);
    layout.check_numbering(detector);
    CubqlCpuPeer peer(layout, config.threads);
    std::vector<float> xyz;
    return run_frames(config, scene, result, [&](int frame, bool first_pass) {
        layout.positions(scene, frame, xyz);
        for (std::size_t o = 0; o < layout.objects; ++o)
            detector.set_positions(static_cast<ObjectId>(o), xyz.data() + 3 * std::size_t{layout.vertex_begin[o]},
                                   layout.vertex_begin[o + 1] - layout.vertex_begin[o]);
        FrameOutcome outcome;
        auto start = std::chrono::steady_clock::now();
        const FrameResult& kdet = detector.detect();
        outcome.kdet_ms = elapsed_ms(start);
        start = std::chrono::steady_clock::now();
        const std::vector<std::uint64_t>& keys = peer.detect(xyz);
        outcome.peer_ms = elapsed_ms(start);
        if (first_pass) peer.check();
        outcome.peer_keys = keys;
        for (const TetPair& p : kdet.pairs)
            outcome.kdet_keys.push_back(pair_key(layout.tet_begin[p.object_a] + p.tet_a, layout.tet_begin[p.object_b] + p.tet_b));
        return outcome;
    });
}

} // namespace

int main(int argc, char** argv) {
    const char* program = "kdet_cpu_vs_cubql";
    PeerConfig defaults;
    defaults.scenes.push_back("procedural");
    defaults.without_self = {"pass_through_armadillos"};
    defaults.procedural_tets = {100000, 1000000};
    const PeerConfig config = parse_peer_args(argc, argv, program, defaults, true);
    try {
        std::printf("cpu: %s, %d logical processors; %d threads for each side; kdet %s\n", cpu_name().c_str(),
                    omp_get_num_procs(), config.threads, version().c_str());
        std::printf("%d timed runs after one untimed; medians over frames x runs\n\n", config.runs);
        const std::vector<CaseResult> results = run_cases(
            config, "cubql", [&](const Scene& scene, CaseResult c) { return run_cpu_case(config, scene, c); });
        std::printf("%s", results_table(results, "cubql").c_str());
        if (!config.csv.empty() && !write_text(config.csv, ratio_csv(results, "cubql"), program)) return 1;
        return mismatches(results, program) ? 1 : 0;
    } catch (const std::exception& error) { // kdet::Error, and cuBQL's errors
        std::fprintf(stderr, "%s: %s\n", program, error.what());
        return 1;
    }
}
