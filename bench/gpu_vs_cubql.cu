/// kdet's CUDA backend against what a CUDA user would write with NVIDIA's cuBQL instead of kdet's grid:
/// per frame, a kernel computes the tets' boxes, cuBQL's default GPU builder (cuBQL::gpuBuilder)
/// builds one BVH per object over them, and one kernel runs one cuBQL fixedBoxQuery per tet, each
/// candidate decided by kdet's exact test, kdet's default narrow phase (cubql_peer.hpp), so both give
/// the same pair set, which every frame checks. The previous frame's BVHs are freed at the start of
/// the next, inside its timing. How both sides are timed and compared: gpu_peer.cuh.
///
/// usage: kdet_gpu_vs_cubql [--scenes a,b,...] [-r N] [--frames A:B] [--runs N] [--tets N,...] [--csv FILE]
///   --scenes   scenes for open_scene (default: armadillos,buddha_and_armadillo,bunny_and_planck,
///              pass_through_armadillos,procedural; pass_through_armadillos always at resolution 2)
///   -r N       resolution of the thesis scenes, 1-4 (default 4)
///   --frames   first and last frame, inclusive, clamped to the scene (default 60:99 around contact in
///              the thesis scenes, the eleven frames around the deepest in the procedural scene)
///   --runs N   timed passes over the frames (default 3)
///   --tets N   tets of the procedural scene, one case each (default 1000000,4000000)
///   --csv FILE scene,self,frames,kdet_ms,cubql_ms,ratio,same_pairs, one row per case (ratio: cubql_ms /
///              kdet_ms; times are medians of device time over frames x runs)
/// Every scene runs without and with self-collision, except pass_through_armadillos, which the thesis
/// runs without only. Exit status: 0, 1 on a mismatching frame or an error, 2 for a bad command line.
///
/// cuBQL is NVIDIA's (Apache-2.0), read from ../shared/third_party/cuBQL, never part of kdet.

#define CUBQL_GPU_BUILDER_IMPLEMENTATION 1
#include <cuBQL/bvh.h>
#include <cuBQL/builder/cuda.h>

#include "cubql_peer.hpp"
#include "gpu_peer.cuh"

#include <cuda_runtime.h>

#include <cstdint>
#include <string>
#include <vector>

namespace {

using namespace kdet;
using namespace kdet::bench;

__global__ void boxes_kernel(const vec3* positions, const TetIndices* tets, std::uint32_t count, cuBQL::box3f* boxes) {
    const std::uint32_t t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t < count) boxes[t] = cubql_box(positions, tets[t]);
}

__global__ void query_kernel(CubqlView view, std::uint32_t count, KeyOutput out) {
    const std::uint32_t t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t < count) query_tet(view, t, [&](std::uint32_t lo, std::uint32_t hi) { out.push(lo, hi); });
}

class CubqlPeer {
public:
    CubqlPeer(const SceneLayout& layout, cudaStream_t stream)
        : count_(static_cast<std::uint32_t>(layout.tets.size())), tet_begin_(layout.tet_begin),
          bvhs_(layout.objects), stream_(stream), keys_(count_) {
        const auto upload = [](auto& device, const auto& host) {
            device.resize_discard(host.size());
            cuda_check(cudaMemcpy(device.data(), host.data(), host.size() * sizeof(host[0]), cudaMemcpyHostToDevice),
                       "cudaMemcpy");
        };
        upload(tets_, layout.tets);
        upload(tet_object_, layout.tet_object);
        upload(device_tet_begin_, layout.tet_begin);
        upload(checked_, layout.checked);
        boxes_.resize_discard(count_);
        device_bvhs_.resize_discard(bvhs_.size());
    }
    CubqlPeer(const CubqlPeer&) = delete;
    CubqlPeer& operator=(const CubqlPeer&) = delete;
    ~CubqlPeer() { free_bvhs(); }

    /// One frame on the stream; returns the pair count, the keys stay in keys().
    std::size_t detect(const float* positions) {
        free_bvhs();
        if (count_ == 0) return 0;
        const vec3* xyz = reinterpret_cast<const vec3*>(positions);
        boxes_kernel<<<grid_for(count_, block), block, 0, stream_>>>(xyz, tets_.data(), count_, boxes_.data());
        cuda_check(cudaGetLastError(), "boxes_kernel");
        for (std::size_t o = 0; o < bvhs_.size(); ++o)
            if (tet_begin_[o + 1] > tet_begin_[o])
                cuBQL::gpuBuilder(bvhs_[o], boxes_.data() + tet_begin_[o], tet_begin_[o + 1] - tet_begin_[o],
                                  cuBQL::BuildConfig(), stream_);
        cuda_check(cudaMemcpyAsync(device_bvhs_.data(), bvhs_.data(), bvhs_.size() * sizeof(cuBQL::bvh3f),
                                   cudaMemcpyHostToDevice, stream_), "cudaMemcpyAsync");
        const CubqlView view{xyz,          tets_.data(),        tet_object_.data(), device_tet_begin_.data(),
                             checked_.data(), device_bvhs_.data(), boxes_.data(),      static_cast<std::uint32_t>(bvhs_.size())};
        return keys_.collect(stream_, [&](KeyOutput out) {
            query_kernel<<<grid_for(count_, block), block, 0, stream_>>>(view, count_, out);
        });
    }
    const unsigned long long* keys() const { return keys_.keys(); }

    /// Throws kdet::Error if a BVH of the last frame is deeper than cuBQL's traversal stack allows.
    void check() const {
        for (const cuBQL::bvh3f& bvh : bvhs_) {
            if (!bvh.nodes) continue;
            std::vector<cuBQL::bvh3f::Node> nodes(bvh.numNodes);
            cuda_check(cudaMemcpy(nodes.data(), bvh.nodes, nodes.size() * sizeof(nodes[0]), cudaMemcpyDeviceToHost),
                       "cudaMemcpy");
            const int depth = bvh_depth(nodes.data());
            if (depth > 64) throw Error("a cuBQL BVH is " + std::to_string(depth) + " levels deep, over its traversal's stack of 64");
        }
    }

private:
    void free_bvhs() {
        for (cuBQL::bvh3f& bvh : bvhs_)
            if (bvh.nodes) cuBQL::cuda::free(bvh, stream_);
    }

    static constexpr unsigned block = 128;
    std::uint32_t count_;
    std::vector<std::uint32_t> tet_begin_;
    std::vector<cuBQL::bvh3f> bvhs_; ///< [object], device pointers; empty until the first frame
    cudaStream_t stream_;
    DeviceBuffer<TetIndices> tets_;
    DeviceBuffer<std::uint32_t> tet_object_, device_tet_begin_;
    DeviceBuffer<std::uint8_t> checked_;
    DeviceBuffer<cuBQL::box3f> boxes_;
    DeviceBuffer<cuBQL::bvh3f> device_bvhs_;
    KeyBuffer keys_;
};

std::string cubql_csv(const std::vector<CaseResult>& results) { return ratio_csv(results, "cubql"); }

} // namespace

int main(int argc, char** argv) {
    PeerConfig defaults;
    defaults.scenes.push_back("procedural");
    defaults.without_self = {"pass_through_armadillos"};
    defaults.procedural_tets = {1000000, 4000000};
    return gpu_peer_main<CubqlPeer>(argc, argv, "kdet_gpu_vs_cubql", defaults, NarrowPhase::exact, "cubql", cubql_csv);
}
