#include "commands.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <vector>

namespace kdet::cli {

namespace {

const char* bench_help = R"(usage: kdet bench [procedural] [options]

Runs the built-in procedural scene (two deforming tori that approach, interpenetrate and separate)
and prints per-frame detection times and pair counts. Needs no data files.

options:
  --tets N             total tetrahedra of the scene (default 100000, up to 20000000)
  --frames N           frames to run (default 120)
  -n N                 runs of the whole scene; times are averaged per frame (default 1, at most 20)
  -c M                 method: kdet, kdet_no_pairs, gpu (brute force, loop), gpu_no_loop (brute force, pairs)
  -o T                 narrow phase: sat, sat_no_edges, sat_mtv, gjk, fast
  -h H                 grid hash: djb2, fnv-1a, morton, simple (as in the thesis; --help prints this)
  -g N                 CUDA block size: 16, 32, 64, 128 or 256
  -s yes|y|no|n        self-collisions of both objects (default no)
  --quiet              print only the summary
)";

} // namespace

int run_bench(int argc, char** argv) {
    DetectorOptions options;
    SceneRequest request;
    ProceduralSceneOptions& scene_options = request.procedural;
    int runs = 1;
    bool self = false, quiet = false, help = false;
    std::vector<std::string> scene_arguments;

    ArgParser parser("bench");
    parser.positionals(1, scene_arguments);
    parser.flag("--help", [&] { help = true; });
    parser.flag("--quiet", [&] { quiet = true; });
    parser.option("--tets", "N", [&](const std::string& v) {
        scene_options.total_tets = static_cast<std::size_t>(parse_integer("--tets", v, 100, 20000000));
    });
    parser.option("--frames", "N",
                  [&](const std::string& v) { scene_options.frames = static_cast<int>(parse_integer("--frames", v, 1, 100000)); });
    parser.option("-n", "runs", [&](const std::string& v) { runs = static_cast<int>(parse_integer("-n", v, 1, 20)); });
    parser.option("-c", "method", [&](const std::string& v) {
        const std::string m = parse_choice("-c", v, {"kdet", "kdet_no_pairs", "gpu", "gpu_no_loop"});
        options.method = m == "gpu" ? Method::brute_force_loop
                         : m == "gpu_no_loop" ? Method::brute_force_pairs
                                              : (m == "kdet" ? Method::kdet : Method::kdet_no_pairs);
    });
    parser.option("-o", "test", [&](const std::string& v) {
        parse(parse_choice("-o", v, {"sat", "sat_no_edges", "sat_mtv", "gjk", "fast"}), options.narrow_phase);
    });
    parser.option("-h", "hash", [&](const std::string& v) {
        parse(parse_choice("-h", v, {"djb2", "fnv-1a", "morton", "simple"}), options.hash);
    });
    parser.option("-g", "block size", [&](const std::string& v) {
        options.block_size = std::stoi(parse_choice("-g", v, {"16", "32", "64", "128", "256"}));
    });
    parser.option("-s", "yes|no", [&](const std::string& v) {
        self = parse_choice("-s", v, {"yes", "y", "no", "n"})[0] == 'y';
    });
    add_detector_options(parser, options);
    parser.parse(argc, argv, 2);
    if (help) {
        std::cout << bench_help << detector_options_help();
        return exit_ok;
    }
    std::unique_ptr<Scene> opened;
    try {
        opened = open_scene(scene_arguments.empty() ? "procedural" : scene_arguments[0], request);
    } catch (const Error& e) {
        throw UsageError(std::string("bench: ") + e.what());
    }
    const Scene& scene = *opened;
    Detector detector(options);
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        const ObjectId id = detector.add_object(scene.rest_mesh(o));
        detector.set_self_collision(id, self);
    }
    const int frames = scene.num_frames();
    std::vector<double> frame_ms(static_cast<std::size_t>(frames), 0.0);
    std::vector<FrameCounts> counts(static_cast<std::size_t>(frames));
    std::vector<float> xyz;
    std::size_t peak_memory = 0;
    for (int run = 0; run < runs; ++run)
        for (int f = 0; f < frames; ++f) {
            for (std::size_t o = 0; o < scene.num_objects(); ++o) {
                scene.positions(o, f, xyz);
                detector.set_positions(static_cast<ObjectId>(o), xyz.data(), xyz.size() / 3);
            }
            const FrameResult& r = detector.detect();
            frame_ms[static_cast<std::size_t>(f)] += r.times.total / runs;
            counts[static_cast<std::size_t>(f)] = r.counts;
            peak_memory = std::max(peak_memory, r.memory_bytes);
        }

    std::size_t tets = 0;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) tets += scene.rest_mesh(o).num_tets();
    std::printf("scene %s: %zu objects, %zu tets, %d frames, %d run(s); method %s, test %s, hash %s, self %s, "
                "backend %s on %s\n",
                scene.name().c_str(), scene.num_objects(), tets, frames, runs, to_string(options.method), to_string(options.narrow_phase),
                to_string(options.hash), self ? "yes" : "no", to_string(options.backend), detector.device_name().c_str());
    if (!quiet) {
        std::printf("%6s %12s %14s %14s %12s %12s\n", "frame", "time_ms", "candidates", "unique", "pairs", "tets");
        for (int f = 0; f < frames; ++f) {
            const FrameCounts& c = counts[static_cast<std::size_t>(f)];
            std::printf("%6d %12.3f %14llu %14llu %12llu %12llu\n", f, frame_ms[static_cast<std::size_t>(f)],
                        static_cast<unsigned long long>(c.candidates), static_cast<unsigned long long>(c.unique_candidates),
                        static_cast<unsigned long long>(c.colliding_pairs),
                        static_cast<unsigned long long>(c.colliding_tets));
        }
    }
    std::vector<double> sorted = frame_ms;
    std::sort(sorted.begin(), sorted.end());
    unsigned long long max_pairs = 0;
    for (const FrameCounts& c : counts) max_pairs = std::max<unsigned long long>(max_pairs, c.colliding_pairs);
    std::printf("summary: median %.3f ms, max %.3f ms per frame; most colliding pairs in a frame %llu; peak memory %.1f MiB\n",
                sorted[sorted.size() / 2], sorted.back(), max_pairs, static_cast<double>(peak_memory) / (1024.0 * 1024.0));
    return exit_ok;
}

} // namespace kdet::cli
