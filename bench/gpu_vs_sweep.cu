/// kdet's CUDA backend against the peer a GPU user would otherwise write: a sort-and-sweep broad phase
/// over the tets' boxes (CUB radix sort on min x, one thread per sorted box walking forward), then
/// kdet's own `sat` on each box-overlapping pair, with kdet's rules: tets of one object that share a
/// vertex are never reported, and pairs inside an object only in self mode.
///
/// Per frame, outside any timing: the scene's positions are uploaded once into one device buffer that
/// both sides read (kdet copies them into its own buffer with set_positions_on_device, enqueued before
/// its start event). Timed with CUDA events on one stream, each including its one wait for the device:
///   kdet: Detector::detect() (Backend::cuda, sat, results left on the device, sorted);
///   peer: boxes kernel, radix sort, sweep kernel, reading the pair count back (and, if the key
///         buffer was too small, growing it and sweeping again). Its keys stay unsorted.
/// A first pass over the frames warms both up untimed (buffers grow to what the frames need); every
/// pass compares the two pair sets of every frame.
///
/// usage: kdet_gpu_vs_sweep [--scenes a,b,...] [-r N] [--frames A:B] [--runs N] [--tets N] [--csv FILE]
///   --scenes   scenes for open_scene (default: armadillos,buddha_and_armadillo,bunny_and_planck,
///              pass_through_armadillos; the last always at resolution 2); "procedural" needs no data
///   -r N       resolution of the thesis scenes, 1-4 (default 4)
///   --frames   first and last frame, inclusive, clamped to the scene (default 60:99, around contact)
///   --runs N   timed passes over the frames (default 3)
///   --tets N   tets of the procedural scene (default 100000)
///   --csv FILE one row per case
/// Every scene runs with self-collision off and on (for every object, as `kdet bench -s yes`).
/// Exit status: 0, 1 on a mismatching frame or an error, 2 for a bad command line.

#include "exec/cuda_exec.cuh"
#include "geometry/tet_intersect.hpp"
#include "pipeline/scene_view.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <cub/device/device_radix_sort.cuh>
#include <cuda_runtime.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <memory>
#include <numeric>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace kdet;

__device__ void load(const vec3* positions, const TetIndices& tet, vec3 out[4]) {
    for (int k = 0; k < 4; ++k) out[k] = positions[tet.v[k]];
}

__global__ void boxes_kernel(const vec3* positions, const TetIndices* tets, std::uint32_t count, Aabb* boxes, float* min_x) {
    const std::uint32_t t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t >= count) return;
    vec3 v[4];
    load(positions, tets[t], v);
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
    unsigned long long* keys;
    unsigned long long capacity;
    unsigned long long* found;     ///< counts every pair, also those past capacity, so the host can grow
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
        load(s.positions, a, va);
        load(s.positions, b, vb);
        if (!tets_intersect_sat(va, vb)) continue;
        const unsigned long long slot = atomicAdd(s.found, 1ull);
        if (slot < s.capacity) s.keys[slot] = (static_cast<unsigned long long>(lo) << 32) | hi;
    }
}

unsigned grid_for(std::uint32_t count, unsigned block) { return (count + block - 1) / block; }

/// The peer: its buffers persist between frames, as a simulation's would.
class SweepPeer {
public:
    /// tets: per global tet (kdet's numbering), ids into the concatenated positions; object: per tet;
    /// checked: [a * object_count + b] whether pairs between a and b (a == b: inside a) are reported.
    SweepPeer(const std::vector<TetIndices>& tets, const std::vector<std::uint32_t>& object,
              const std::vector<std::uint8_t>& checked, std::uint32_t object_count, cudaStream_t stream)
        : count_(static_cast<std::uint32_t>(tets.size())), object_count_(object_count), stream_(stream) {
        tets_.resize_discard(count_);
        object_.resize_discard(count_);
        checked_.resize_discard(checked.size());
        boxes_.resize_discard(count_);
        min_x_.resize_discard(count_);
        sorted_min_x_.resize_discard(count_);
        ids_.resize_discard(count_);
        sorted_ids_.resize_discard(count_);
        keys_.resize_discard(std::max<std::size_t>(count_, 1024));
        found_.resize_discard(1);
        std::vector<std::uint32_t> ids(count_);
        std::iota(ids.begin(), ids.end(), 0u);
        const auto upload = [](auto* device, const auto& host) {
            cuda_check(cudaMemcpy(device, host.data(), host.size() * sizeof(host[0]), cudaMemcpyHostToDevice), "cudaMemcpy");
        };
        upload(tets_.data(), tets);
        upload(object_.data(), object);
        upload(checked_.data(), checked);
        upload(ids_.data(), ids);
        std::size_t bytes = 0;
        cuda_check(cub::DeviceRadixSort::SortPairs(nullptr, bytes, min_x_.data(), sorted_min_x_.data(), ids_.data(),
                                                   sorted_ids_.data(), count_, 0, 32, stream_), "SortPairs");
        temp_.resize_discard(bytes);
        temp_bytes_ = bytes;
        found_host_ = reinterpret_cast<unsigned long long*>(found_pinned_.reserve(sizeof(unsigned long long)));
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
        for (;;) {
            cuda_check(cudaMemsetAsync(found_.data(), 0, sizeof(unsigned long long), stream_), "cudaMemsetAsync");
            const SweepArgs args{xyz, tets_.data(), object_.data(), checked_.data(), object_count_, boxes_.data(),
                                 sorted_min_x_.data(), sorted_ids_.data(), count_, keys_.data(), keys_.size(),
                                 found_.data()};
            sweep_kernel<<<grid_for(count_, block), block, 0, stream_>>>(args);
            cuda_check(cudaGetLastError(), "sweep_kernel");
            cuda_check(cudaMemcpyAsync(found_host_, found_.data(), sizeof(unsigned long long), cudaMemcpyDeviceToHost,
                                       stream_), "cudaMemcpyAsync");
            cuda_check(cudaStreamSynchronize(stream_), "cudaStreamSynchronize");
            const std::size_t found = static_cast<std::size_t>(*found_host_);
            if (found <= keys_.size()) return found;
            keys_.resize_discard(found + found / 2); // never drop a pair: grow and sweep again
        }
    }
    const unsigned long long* keys() const { return keys_.data(); }

private:
    static constexpr unsigned block = 256;
    std::uint32_t count_, object_count_;
    cudaStream_t stream_;
    DeviceBuffer<TetIndices> tets_;
    DeviceBuffer<std::uint32_t> object_, ids_, sorted_ids_;
    DeviceBuffer<std::uint8_t> checked_, temp_;
    DeviceBuffer<Aabb> boxes_;
    DeviceBuffer<float> min_x_, sorted_min_x_;
    DeviceBuffer<unsigned long long> keys_, found_;
    std::size_t temp_bytes_ = 0;
    PinnedBuffer found_pinned_;
    unsigned long long* found_host_ = nullptr; ///< in found_pinned_
};

struct Config {
    std::vector<std::string> scenes{"armadillos", "buddha_and_armadillo", "bunny_and_planck", "pass_through_armadillos"};
    int resolution = 4, first_frame = 60, last_frame = 99, runs = 3;
    std::size_t procedural_tets = 100000;
    std::string csv;
};

struct CaseResult {
    std::string scene, resolution;
    bool self = false;
    std::size_t tets = 0;
    int frames = 0;
    double kdet_ms = 0, peer_ms = 0, pairs = 0;
    std::size_t mismatching_frames = 0;
};

double median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::vector<std::uint64_t> to_host(const void* keys, std::size_t count, cudaStream_t stream) {
    std::vector<std::uint64_t> out(count);
    if (count)
        cuda_check(cudaMemcpyAsync(out.data(), keys, count * sizeof(std::uint64_t), cudaMemcpyDeviceToHost, stream),
                   "cudaMemcpyAsync");
    cuda_check(cudaStreamSynchronize(stream), "cudaStreamSynchronize");
    return out;
}

/// Prints how two sorted key sets differ; returns whether they do.
bool differ(const std::vector<std::uint64_t>& kdet, const std::vector<std::uint64_t>& peer, const std::string& what) {
    if (kdet == peer) return false;
    std::vector<std::uint64_t> only_kdet, only_peer;
    std::set_difference(kdet.begin(), kdet.end(), peer.begin(), peer.end(), std::back_inserter(only_kdet));
    std::set_difference(peer.begin(), peer.end(), kdet.begin(), kdet.end(), std::back_inserter(only_peer));
    std::fprintf(stderr, "MISMATCH %s: kdet %zu pairs, peer %zu; only kdet %zu, only peer %zu", what.c_str(),
                 kdet.size(), peer.size(), only_kdet.size(), only_peer.size());
    const auto show = [](const char* side, const std::vector<std::uint64_t>& keys) {
        if (!keys.empty())
            std::fprintf(stderr, " (first only %s: %u %u)", side, static_cast<unsigned>(keys[0] >> 32),
                         static_cast<unsigned>(keys[0] & 0xffffffffu));
    };
    show("kdet", only_kdet);
    show("peer", only_peer);
    std::fprintf(stderr, "\n");
    return true;
}

CaseResult run_case(const Config& config, const Scene& scene, const std::string& resolution, bool self,
                    cudaStream_t stream) {
    const std::size_t objects = scene.num_objects();
    DetectorOptions options;
    options.backend = Backend::cuda;
    options.narrow_phase = NarrowPhase::sat; // the peer's test
    options.results_to_host = false;
    options.cuda_stream = stream;
    Detector detector(options);

    // The objects and the pairs checked as `kdet bench` sets them up, and the same pairs for the peer.
    add_scene_objects(detector, scene, self);
    std::vector<std::uint8_t> checked(objects * objects, 0);
    std::vector<std::uint32_t> vertex_begin(objects + 1, 0);
    for (std::size_t o = 0; o < objects; ++o) {
        vertex_begin[o + 1] = vertex_begin[o] + static_cast<std::uint32_t>(scene.rest_mesh(o).num_vertices());
        checked[o * objects + o] = self;
        for (std::size_t p = o + 1; p < objects; ++p) checked[o * objects + p] = checked[p * objects + o] = scene.checks_pair(o, p);
    }
    // The peer's tets in kdet's global numbering (first_tet(o) + t), so the pair keys compare directly.
    std::vector<TetIndices> tets;
    std::vector<std::uint32_t> tet_object;
    for (std::size_t o = 0; o < objects; ++o) {
        const TetMesh& mesh = scene.rest_mesh(o);
        if (detector.first_tet(static_cast<ObjectId>(o)) != tets.size()) throw Error("unexpected tet numbering");
        for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
            TetIndices tet;
            for (int k = 0; k < 4; ++k) tet.v[k] = vertex_begin[o] + mesh.tets[4 * t + k];
            tets.push_back(tet);
            tet_object.push_back(static_cast<std::uint32_t>(o));
        }
    }
    SweepPeer peer(tets, tet_object, checked, static_cast<std::uint32_t>(objects), stream);

    const int last = std::min(config.last_frame, scene.num_frames() - 1);
    if (config.first_frame > last)
        throw Error("frames " + std::to_string(config.first_frame) + ":" + std::to_string(config.last_frame) +
                    " outside scene '" + scene.name() + "' (" + std::to_string(scene.num_frames()) + " frames)");
    DeviceBuffer<float> positions;
    positions.resize_discard(3 * std::size_t{vertex_begin.back()});
    std::vector<float> host(3 * std::size_t{vertex_begin.back()}), object_xyz;
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

    CaseResult result{scene.name(), resolution, self, tets.size(), last - config.first_frame + 1};
    std::vector<double> kdet_ms, peer_ms, pairs;
    std::set<int> mismatching;
    for (int pass = 0; pass <= config.runs; ++pass) { // pass 0 warms up, untimed
        for (int frame = config.first_frame; frame <= last; ++frame) {
            for (std::size_t o = 0; o < objects; ++o) {
                scene.positions(o, frame, object_xyz);
                std::copy(object_xyz.begin(), object_xyz.end(), host.begin() + 3 * std::ptrdiff_t{vertex_begin[o]});
            }
            cuda_check(cudaMemcpyAsync(positions.data(), host.data(), host.size() * sizeof(float),
                                       cudaMemcpyHostToDevice, stream), "cudaMemcpyAsync");
            for (std::size_t o = 0; o < objects; ++o)
                detector.set_positions_on_device(static_cast<ObjectId>(o), positions.data() + 3 * vertex_begin[o],
                                                 vertex_begin[o + 1] - vertex_begin[o]);
            const double kdet_time = timed([&] { detector.detect(); });
            std::size_t peer_count = 0;
            const double peer_time = timed([&] { peer_count = peer.detect(positions.data()); });

            const DeviceResults kdet_results = detector.device_results();
            const std::vector<std::uint64_t> kdet_keys = to_host(kdet_results.pair_keys, kdet_results.pair_count, stream);
            std::vector<std::uint64_t> peer_keys = to_host(peer.keys(), peer_count, stream);
            std::sort(peer_keys.begin(), peer_keys.end());
            const std::string what = scene.name() + (self ? " self" : "") + " frame " + std::to_string(frame) +
                                     " pass " + std::to_string(pass);
            if (differ(kdet_keys, peer_keys, what)) mismatching.insert(frame);
            if (pass == 0) {
                pairs.push_back(static_cast<double>(kdet_keys.size()));
            } else {
                kdet_ms.push_back(kdet_time);
                peer_ms.push_back(peer_time);
            }
        }
    }
    cuda_check(cudaEventDestroy(start), "cudaEventDestroy");
    cuda_check(cudaEventDestroy(stop), "cudaEventDestroy");
    result.kdet_ms = median(kdet_ms);
    result.peer_ms = median(peer_ms);
    result.pairs = median(pairs);
    result.mismatching_frames = mismatching.size();
    return result;
}

[[noreturn]] void usage(const char* problem) {
    if (problem) std::fprintf(stderr, "kdet_gpu_vs_sweep: %s\n", problem);
    std::fprintf(problem ? stderr : stdout, "usage: kdet_gpu_vs_sweep [--scenes a,b,...] [-r N] [--frames A:B] [--runs N] [--tets N] "
                         "[--csv FILE]\n");
    std::exit(problem ? 2 : 0);
}

long parse_number(const std::string& text, const char* flag, long lo, long hi) {
    char* end = nullptr;
    const long value = std::strtol(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || value < lo || value > hi)
        usage((std::string(flag) + " '" + text + "': expected a number in [" + std::to_string(lo) + ", " +
               std::to_string(hi) + "]").c_str());
    return value;
}

Config parse_args(int argc, char** argv) {
    Config config;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "-h" || flag == "--help") usage(nullptr);
        if (i + 1 >= argc) usage(("unknown flag or missing value: " + flag).c_str());
        const std::string value = argv[++i];
        if (flag == "--scenes") {
            config.scenes.clear();
            for (std::size_t begin = 0; begin <= value.size();) {
                const std::size_t end = std::min(value.find(',', begin), value.size());
                if (end > begin) config.scenes.push_back(value.substr(begin, end - begin));
                begin = end + 1;
            }
            if (config.scenes.empty()) usage("--scenes: no scene given");
        } else if (flag == "-r") {
            config.resolution = static_cast<int>(parse_number(value, "-r", 1, 4));
        } else if (flag == "--frames") {
            const std::size_t colon = value.find(':');
            if (colon == std::string::npos) usage("--frames: expected A:B");
            config.first_frame = static_cast<int>(parse_number(value.substr(0, colon), "--frames", 0, 1000000));
            config.last_frame = static_cast<int>(parse_number(value.substr(colon + 1), "--frames", 0, 1000000));
            if (config.first_frame > config.last_frame) usage("--frames: A must not exceed B");
        } else if (flag == "--runs") {
            config.runs = static_cast<int>(parse_number(value, "--runs", 1, 1000));
        } else if (flag == "--tets") {
            config.procedural_tets = static_cast<std::size_t>(parse_number(value, "--tets", 100, 20000000));
        } else if (flag == "--csv") {
            config.csv = value;
        } else {
            usage(("unknown flag: " + flag).c_str());
        }
    }
    return config;
}

std::string version_text(int version) { return std::to_string(version / 1000) + "." + std::to_string(version % 1000 / 10); }

/// The kernel driver's release (e.g. 570.124.06), which the CUDA API does not report: the first
/// number with a dot on the first line of /proc/driver/nvidia/version; "unknown" without it.
std::string driver_release() {
    std::ifstream in("/proc/driver/nvidia/version");
    std::string line, word;
    std::getline(in, line);
    std::istringstream words(line);
    while (words >> word)
        if (std::isdigit(static_cast<unsigned char>(word[0])) && word.find('.') != std::string::npos) return word;
    return "unknown";
}

/// Runs every case and prints the table; the exit status. Throws kdet::Error for a failed CUDA call or
/// a scene that cannot be opened.
int compare(const Config& config) {
    int device = 0, driver = 0, runtime = 0;
    cudaDeviceProp properties{};
    cuda_check(cudaGetDevice(&device), "cudaGetDevice");
    cuda_check(cudaGetDeviceProperties(&properties, device), "cudaGetDeviceProperties");
    cuda_check(cudaDriverGetVersion(&driver), "cudaDriverGetVersion");
    cuda_check(cudaRuntimeGetVersion(&runtime), "cudaRuntimeGetVersion");
    std::printf("device: %s; driver %s (CUDA %s); CUDA runtime %s; kdet %s\n", properties.name,
                driver_release().c_str(), version_text(driver).c_str(), version_text(runtime).c_str(),
                version().c_str());
    std::printf("frames %d:%d (clamped to each scene), %d timed runs after one untimed; medians over frames x runs\n\n",
                config.first_frame, config.last_frame, config.runs);

    cudaStream_t stream;
    cuda_check(cudaStreamCreate(&stream), "cudaStreamCreate");
    std::vector<CaseResult> results;
    for (const std::string& name : config.scenes) {
        SceneRequest request;
        request.resolution = config.resolution;
        request.procedural.total_tets = config.procedural_tets;
        const std::unique_ptr<Scene> scene = open_scene(name, request);
        // pass_through_armadillos fixes its meshes at resolution 2; the procedural scene has none.
        const std::string resolution =
            name == "procedural" ? "-" : (name == "pass_through_armadillos" ? "2" : std::to_string(config.resolution));
        for (const bool self : {false, true}) {
            results.push_back(run_case(config, *scene, resolution, self, stream));
            const CaseResult& r = results.back();
            std::fprintf(stderr, "%s r%s self %s: kdet %.3f ms, peer %.3f ms\n", r.scene.c_str(),
                         r.resolution.c_str(), r.self ? "yes" : "no", r.kdet_ms, r.peer_ms);
        }
    }
    cuda_check(cudaStreamDestroy(stream), "cudaStreamDestroy");

    std::printf("| scene | r | self | tets | frames | kdet ms | peer ms | peer / kdet | pairs | mismatching frames |\n"
                "|---|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
    std::FILE* csv = nullptr;
    if (!config.csv.empty()) {
        csv = std::fopen(config.csv.c_str(), "w");
        if (!csv) {
            std::fprintf(stderr, "kdet_gpu_vs_sweep: cannot write %s\n", config.csv.c_str());
            return 1;
        }
        std::fprintf(csv, "scene,resolution,self,tets,frames,kdet_median_ms,peer_median_ms,peer_over_kdet,"
                          "pairs_median,mismatching_frames\n");
    }
    std::size_t mismatches = 0;
    for (const CaseResult& r : results) {
        const double ratio = r.kdet_ms > 0 ? r.peer_ms / r.kdet_ms : 0.0;
        std::printf("| %s | %s | %s | %zu | %d | %.3f | %.3f | %.2f | %.0f | %zu |\n", r.scene.c_str(), r.resolution.c_str(),
                    r.self ? "yes" : "no", r.tets, r.frames, r.kdet_ms, r.peer_ms, ratio, r.pairs, r.mismatching_frames);
        if (csv)
            std::fprintf(csv, "%s,%s,%s,%zu,%d,%.4f,%.4f,%.3f,%.0f,%zu\n", r.scene.c_str(), r.resolution.c_str(),
                         r.self ? "yes" : "no", r.tets, r.frames, r.kdet_ms, r.peer_ms, ratio, r.pairs,
                         r.mismatching_frames);
        mismatches += r.mismatching_frames;
    }
    if (csv && std::fclose(csv) != 0) {
        std::fprintf(stderr, "kdet_gpu_vs_sweep: cannot write %s\n", config.csv.c_str());
        return 1;
    }
    if (mismatches) std::fprintf(stderr, "kdet_gpu_vs_sweep: %zu frames where kdet and the peer differ\n", mismatches);
    return mismatches ? 1 : 0;
}

} // namespace

int main(int argc, char** argv) {
    const Config config = parse_args(argc, argv);
    std::string reason;
    if (!cuda_available(&reason)) {
        std::fprintf(stderr, "kdet_gpu_vs_sweep: no usable GPU: %s\n", reason.c_str());
        return 1;
    }
    try {
        return compare(config);
    } catch (const Error& error) {
        std::fprintf(stderr, "kdet_gpu_vs_sweep: %s\n", error.what());
        return 1;
    }
}
