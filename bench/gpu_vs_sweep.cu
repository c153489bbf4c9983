/// kdet's CUDA backend against the peer a GPU user would otherwise write: a sort-and-sweep broad phase
/// over the tets' boxes (CUB radix sort on min x, one thread per sorted box walking forward), then
/// kdet's own `sat` on each box-overlapping pair, with kdet's rules: tets of one object that share a
/// vertex are never reported, and pairs inside an object only in self mode.
///
/// The peer's detect(): boxes kernel, radix sort, sweep kernel, reading the pair count back (and, if
/// the key buffer was too small, growing it and sweeping again). Its keys stay unsorted. How both
/// sides are timed and compared: gpu_peer.cuh.
///
/// usage: kdet_gpu_vs_sweep [--scenes a,b,...] [-r N] [--frames A:B] [--runs N] [--tets N,...] [--csv FILE]
///   --scenes   scenes for open_scene (default: armadillos,buddha_and_armadillo,bunny_and_planck,
///              pass_through_armadillos; the last always at resolution 2); "procedural" needs no data
///   -r N       resolution of the thesis scenes, 1-4 (default 4)
///   --frames   first and last frame, inclusive, clamped to the scene (default 60:99 around contact in
///              the thesis scenes, the eleven frames around the deepest in the procedural scene)
///   --runs N   timed passes over the frames (default 3)
///   --tets N   tets of the procedural scene, one case each (default 100000)
///   --csv FILE one row per case
/// Every scene runs with self-collision off and on (for every object, as `kdet bench -s yes`).
/// Exit status: 0, 1 on a mismatching frame or an error, 2 for a bad command line.

#include "gpu_peer.cuh"

#include "geometry/tet_intersect.hpp"

#include <cub/device/device_radix_sort.cuh>
#include <cuda_runtime.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

namespace {

using namespace kdet;
using namespace kdet::bench;

__global__ void boxes_kernel(const vec3* positions, const TetIndices* tets, std::uint32_t count, Aabb* boxes, float* min_x) {
    const std::uint32_t t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t >= count) return;
    vec3 v[4];
    load_tet_vertices(positions, tets[t], v);
    const Aabb box = tet_box(v);
    boxes[t] = box;
    min_x[t] = box.lo.x;
}

struct SweepArgs {
    const vec3* positions;
    const TetIndices* tets;
    const std::uint32_t* object;   ///< [tet]
    const std::uint8_t* checked;   ///< [object * object_count + object]; the diagonal is self-collision
    std::uint32_t object_count;
    const Aabb* boxes;             ///< [tet]
    const float* sorted_min_x;
    const std::uint32_t* sorted_ids;
    std::uint32_t count;
    KeyOutput out;
};

/// One thread per sorted box: every later box whose min x is within this box's x range overlaps it in x.
__global__ void sweep_kernel(SweepArgs s) {
    const std::uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= s.count) return;
    const std::uint32_t t = s.sorted_ids[i];
    const Aabb box = s.boxes[t];
    const std::uint32_t object_t = s.object[t];
    for (std::uint32_t j = i + 1; j < s.count && s.sorted_min_x[j] <= box.hi.x; ++j) {
        const std::uint32_t u = s.sorted_ids[j];
        const Aabb other = s.boxes[u];
        if (other.lo.y > box.hi.y || box.lo.y > other.hi.y || other.lo.z > box.hi.z || box.lo.z > other.hi.z) continue;
        const std::uint32_t object_u = s.object[u];
        if (!s.checked[object_t * s.object_count + object_u]) continue;
        // Lower id first, as kdet passes its tets to the test (it is not symmetric to the last bit).
        const std::uint32_t lo = t < u ? t : u, hi = t < u ? u : t;
        const TetIndices a = s.tets[lo], b = s.tets[hi];
        if (object_t == object_u && share_vertex(a, b)) continue;
        vec3 va[4], vb[4];
        load_tet_vertices(s.positions, a, va);
        load_tet_vertices(s.positions, b, vb);
        if (tets_intersect_sat(va, vb)) s.out.push(lo, hi);
    }
}

/// The peer: its buffers persist between frames, as a simulation's would.
class SweepPeer {
public:
    SweepPeer(const SceneLayout& layout, cudaStream_t stream)
        : count_(static_cast<std::uint32_t>(layout.tets.size())), object_count_(static_cast<std::uint32_t>(layout.objects)),
          stream_(stream), keys_(count_) {
        tets_.resize_discard(count_);
        object_.resize_discard(count_);
        checked_.resize_discard(layout.checked.size());
        boxes_.resize_discard(count_);
        min_x_.resize_discard(count_);
        sorted_min_x_.resize_discard(count_);
        ids_.resize_discard(count_);
        sorted_ids_.resize_discard(count_);
        std::vector<std::uint32_t> ids(count_);
        std::iota(ids.begin(), ids.end(), 0u);
        const auto upload = [](auto* device, const auto& host) {
            cuda_check(cudaMemcpy(device, host.data(), host.size() * sizeof(host[0]), cudaMemcpyHostToDevice), "cudaMemcpy");
        };
        upload(tets_.data(), layout.tets);
        upload(object_.data(), layout.tet_object);
        upload(checked_.data(), layout.checked);
        upload(ids_.data(), ids);
        std::size_t bytes = 0;
        cuda_check(cub::DeviceRadixSort::SortPairs(nullptr, bytes, min_x_.data(), sorted_min_x_.data(), ids_.data(),
                                                   sorted_ids_.data(), count_, 0, 32, stream_), "SortPairs");
        temp_.resize_discard(bytes);
        temp_bytes_ = bytes;
    }
    /// One frame on the stream; returns the pair count, the keys stay in keys().
    std::size_t detect(const float* positions) {
        if (count_ == 0) return 0;
        const vec3* xyz = reinterpret_cast<const vec3*>(positions);
        boxes_kernel<<<grid_for(count_, block), block, 0, stream_>>>(xyz, tets_.data(), count_, boxes_.data(),
                                                                    min_x_.data());
        cuda_check(cudaGetLastError(), "boxes_kernel");
        std::size_t bytes = temp_bytes_;
        cuda_check(cub::DeviceRadixSort::SortPairs(temp_.data(), bytes, min_x_.data(), sorted_min_x_.data(),
                                                   ids_.data(), sorted_ids_.data(), count_, 0, 32, stream_), "SortPairs");
        return keys_.collect(stream_, [&](KeyOutput out) {
            const SweepArgs args{xyz, tets_.data(), object_.data(), checked_.data(), object_count_, boxes_.data(),
                                 sorted_min_x_.data(), sorted_ids_.data(), count_, out};
            sweep_kernel<<<grid_for(count_, block), block, 0, stream_>>>(args);
        });
    }
    const unsigned long long* keys() const { return keys_.keys(); }

private:
    static constexpr unsigned block = 256;
    std::uint32_t count_, object_count_;
    cudaStream_t stream_;
    DeviceBuffer<TetIndices> tets_;
    DeviceBuffer<std::uint32_t> object_, ids_, sorted_ids_;
    DeviceBuffer<std::uint8_t> checked_, temp_;
    DeviceBuffer<Aabb> boxes_;
    DeviceBuffer<float> min_x_, sorted_min_x_;
    std::size_t temp_bytes_ = 0;
    KeyBuffer keys_;
};

/// The CSV as earlier runs wrote it (bench/results/gpu-*/peer-*.csv).
std::string sweep_csv(const std::vector<CaseResult>& results) {
    std::string out = "scene,resolution,self,tets,frames,kdet_median_ms,peer_median_ms,peer_over_kdet,pairs_median,"
                      "mismatching_frames\n";
    char line[512];
    for (const CaseResult& r : results) {
        std::snprintf(line, sizeof line, "%s,%s,%s,%zu,%d,%.4f,%.4f,%.3f,%.0f,%zu\n", r.scene.c_str(), r.resolution.c_str(),
                      r.self ? "yes" : "no", r.tets, r.frames, r.kdet_ms, r.peer_ms,
                      r.kdet_ms > 0 ? r.peer_ms / r.kdet_ms : 0.0, r.pairs, r.mismatching_frames);
        out += line;
    }
    return out;
}

} // namespace

int main(int argc, char** argv) {
    return gpu_peer_main<SweepPeer>(argc, argv, "kdet_gpu_vs_sweep", PeerConfig{}, NarrowPhase::sat, "peer", sweep_csv);
}
