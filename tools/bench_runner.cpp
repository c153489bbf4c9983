#include "bench_runner.hpp"

#include <kdet/detector.hpp>
#include <kdet/option_table.hpp>

#include <omp.h>

#include <algorithm>
#include <chrono>

#ifndef KDET_BENCH_CXX_FLAGS
#define KDET_BENCH_CXX_FLAGS "unknown"
#endif

namespace kdet::cli {

namespace {

std::string compiler() {
#if defined(__clang__)
    return "clang " __clang_version__;
#elif defined(__GNUC__)
    return "gcc " __VERSION__;
#else
    return "unknown";
#endif
}

std::size_t tets_of(const Scene& scene, std::size_t object) {
    return object < scene.num_objects() ? scene.rest_mesh(object).num_tets() : 0;
}

std::size_t vertices_of(const Scene& scene, std::size_t object) {
    return object < scene.num_objects() ? scene.rest_mesh(object).num_vertices() : 0;
}

std::size_t all_tets(const Scene& scene) {
    std::size_t tets = 0;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) tets += tets_of(scene, o);
    return tets;
}

std::string margin_text(const DetectorOptions& options) { return find_option("margin")->text(options); }

std::vector<HeaderField> header_of(const BenchConfig& config, const Scene& scene, const Detector& detector,
                                   int last_frame, std::size_t peak_memory) {
    const DetectorOptions& o = config.options;
    const int threads = o.threads > 0 ? o.threads : omp_get_max_threads();
    return {{"scene name", scene.name()},
            {"resolution", std::to_string(resolution_of(config, scene))},
            {"algorithm", bench_method_name(o.method)},
            {"block size", std::to_string(o.block_size)},
            {"overlap test", to_string(o.narrow_phase)},
            {"self collisions", to_string(config.self)},
            {"hashing algorithm", hash_label(o)},
            {"#frames", std::to_string(last_frame - config.first_frame + 1)},
            {"first frame", std::to_string(config.first_frame)},
            {"total runs", std::to_string(config.runs)},
            {"#tetsA", std::to_string(tets_of(scene, 0))},
            {"#tetsB", std::to_string(tets_of(scene, 1))},
            {"#verticesA", std::to_string(vertices_of(scene, 0))},
            {"#verticesB", std::to_string(vertices_of(scene, 1))},
            // The thesis's A and B are its scenes' two objects; scenes of more objects need the totals.
            {"#objects", std::to_string(scene.num_objects())},
            {"#tets", std::to_string(all_tets(scene))},
            {"backend", to_string(o.backend)},
            {"threads", std::to_string(threads)},
            {"bucket capacity", o.bucket_capacity ? std::to_string(o.bucket_capacity) : "automatic"},
            {"exclusion rings", std::to_string(config.rings)},
            {"collision filters", config.filters ? "on" : "off"},
            {"margin", margin_text(o)},
            {"device", detector.device_name()},
            {"compiler", compiler()},
            {"compiler flags", KDET_BENCH_CXX_FLAGS},
            {"kdet version", version()},
            {"peak memory bytes", std::to_string(peak_memory)},
            {"time unit", "ms"}};
}

} // namespace

std::string stem_of(const BenchConfig& config, const Scene& scene, int last_frame) {
    const std::size_t tets = all_tets(scene);
    std::string stem = scene.name() + "_r" + std::to_string(resolution_of(config, scene)) + "_" +
                       bench_method_name(config.options.method) + "_" + to_string(config.options.narrow_phase) + "_" +
                       hash_label(config.options) + "_g" + std::to_string(config.options.block_size) + "_self-" +
                       to_string(config.self) + "_" + to_string(config.options.backend) + "_" +
                       std::to_string(tets) + "tets";
    if (config.first_frame != 0 || last_frame != scene.num_frames() - 1)
        stem += "_f" + std::to_string(config.first_frame) + "-" + std::to_string(last_frame);
    if (config.rings > 0) stem += "_rings" + std::to_string(config.rings);
    if (!config.filters) stem += "_filters-off";
    if (config.options.margin > 0) stem += "_margin" + margin_text(config.options);
    return stem;
}

int resolution_of(const BenchConfig& config, const Scene& scene) {
    return scene.resolution() != 0 ? scene.resolution() : config.request.resolution;
}

int last_frame_of(const BenchConfig& config, const Scene& scene) {
    return config.last_frame < 0 ? scene.num_frames() - 1 : config.last_frame;
}

BenchOutcome run_benchmark(const BenchConfig& config, const Scene& scene, const BenchProgress& progress) {
    Detector detector(config.options);
    add_scene_objects(detector, scene, config.self);
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        const auto id = static_cast<ObjectId>(o);
        if (config.rings > 0) detector.set_self_exclusion_rings(id, config.rings);
        if (!config.filters) detector.set_collision_filter(id, CollisionFilter{}.group, CollisionFilter{}.mask);
    }

    const int last = last_frame_of(config, scene);
    BenchOutcome outcome;
    std::vector<std::vector<float>> xyz(scene.num_objects());
    std::vector<std::vector<std::uint32_t>> tets(scene.num_objects());
    for (std::size_t o = 0; o < scene.num_objects(); ++o) tets[o] = scene.rest_mesh(o).tets;
    for (int run = 0; run < config.runs && !outcome.stopped; ++run) {
        std::vector<FrameRow>& rows = outcome.runs.emplace_back();
        for (int frame = config.first_frame; frame <= last; ++frame) {
            if (!progress(run, frame - config.first_frame)) {
                outcome.stopped = true;
                break;
            }
            set_scene_tets(detector, scene, frame, tets);
            for (std::size_t o = 0; o < scene.num_objects(); ++o) {
                // A static object stays where its first frame put it.
                if (scene.is_static(o) && (run > 0 || frame > config.first_frame)) continue;
                scene.positions(o, frame, xyz[o]);
                detector.set_positions(static_cast<ObjectId>(o), xyz[o].data(), xyz[o].size() / 3);
            }
            const auto start = std::chrono::steady_clock::now();
            const FrameResult& result = detector.detect();
            const double host_ms =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            const double overlap = xyz.size() >= 2 ? box_overlap_x(xyz[0], xyz[1]) : 0.0;
            rows.push_back(make_frame_row(frame, host_ms, result, overlap));
            outcome.peak_memory = std::max(outcome.peak_memory, result.memory_bytes);
        }
    }
    outcome.header = header_of(config, scene, detector, last, outcome.peak_memory);
    outcome.stem = stem_of(config, scene, last);
    return outcome;
}

} // namespace kdet::cli
