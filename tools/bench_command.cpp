#include "bench_args.hpp"
#include "bench_csv.hpp"
#include "bench_progress.hpp"
#include "bench_runner.hpp"
#include "commands.hpp"
#include "mpi_commands.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>

namespace kdet::cli {

namespace {

/// @brief Index of a column of frame_columns().
std::size_t column(const std::string& name) {
    const auto& columns = frame_columns();
    return static_cast<std::size_t>(std::find(columns.begin(), columns.end(), name) - columns.begin());
}

} // namespace

std::unique_ptr<Scene> open_bench_scene(const BenchConfig& config) {
    if (!config.procedural_flag.empty() && config.scene != "procedural")
        throw UsageError("bench: " + config.procedural_flag + " applies to the procedural scene only (scene is '" +
                         config.scene + "')" +
                         (config.procedural_flag == "--frames" ? "; --frames A:B runs frames A to B of any scene" : ""));
    std::unique_ptr<Scene> scene;
    try {
        scene = open_scene(config.scene, config.request);
    } catch (const Error& e) {
        // An unknown name is a mistake on the command line; a scene that cannot be read is bad input.
        if (!names_a_scene(config.scene)) throw UsageError(std::string("bench: ") + e.what());
        throw;
    }
    if (config.resolution_given) check_resolution_flag("bench", "-r", config.request.resolution, *scene);
    if (config.first_frame >= scene->num_frames() || config.last_frame >= scene->num_frames())
        throw UsageError("bench: invalid value '" + std::to_string(config.first_frame) + ":" + std::to_string(config.last_frame) +
                         "' for --frames: scene '" + scene->name() + "' has frames 0 to " +
                         std::to_string(scene->num_frames() - 1));
    return scene;
}

namespace {

void print_report(const BenchConfig& config, const Scene& scene, const BenchOutcome& outcome, const BenchFiles& files) {
    const std::vector<FrameRow> mean = average_runs(outcome.runs);
    const auto value = [&](const std::string& key) {
        for (const auto& [k, v] : outcome.header)
            if (k == key) return v;
        return std::string();
    };
    // The thesis's name, which the files carry, with kdet's own beside it where they differ.
    std::string method = bench_method_name(config.options.method);
    if (method != to_string(config.options.method)) method += std::string(" (") + to_string(config.options.method) + ")";
    const std::string tets = scene.num_objects() > 2 ? value("#tets") + " tets in " + value("#objects") + " objects"
                                                     : value("#tetsA") + "+" + value("#tetsB") + " tets";
    std::printf("scene %s (resolution %d): %s, frames %d-%d, %d run(s); method %s, test %s, hash %s, self %s, "
                "backend %s on %s\n",
                scene.name().c_str(), resolution_of(config, scene), tets.c_str(),
                config.first_frame, last_frame_of(config, scene), config.runs, method.c_str(),
                to_string(config.options.narrow_phase), value("hashing algorithm").c_str(), to_string(config.self),
                to_string(config.options.backend), value("device").c_str());
    // kdet_no_pairs flags tets and builds no pairs: its summary counts the tets.
    const bool builds_pairs = config.options.method != Method::kdet_no_pairs;
    const std::size_t device = column("device time"), pairs = column("collision pairs"), tets_column = column("colliding tets");
    if (!config.quiet) {
        std::printf("%6s %12s %12s %14s %14s %12s %12s\n", "frame", "device_ms", "host_ms", "candidates", "narrow",
                    "pairs", "tets");
        for (const FrameRow& row : mean) {
            std::printf("%6.0f %12.3f %12.3f %14.0f %14.0f ", row[column("frame")], row[device], row[column("host time")],
                        row[column("candidates")], row[column("unique candidates")]);
            if (builds_pairs) std::printf("%12.0f", row[pairs]);
            else std::printf("%12s", "-");
            std::printf(" %12.0f\n", row[tets_column]);
        }
    }
    std::vector<double> times;
    double most = 0;
    for (const FrameRow& row : mean) {
        times.push_back(row[device]);
        most = std::max(most, row[builds_pairs ? pairs : tets_column]);
    }
    std::sort(times.begin(), times.end());
    const char* most_of = !builds_pairs ? "colliding tets" : config.options.margin > 0.0f ? "pairs within the margin" : "colliding pairs";
    std::printf("summary: median %.3f ms, max %.3f ms per frame; most %s in a frame %.0f; peak memory %.1f MiB\n",
                times[times.size() / 2], times.back(), most_of, most, static_cast<double>(outcome.peak_memory) / (1024.0 * 1024.0));
    std::printf("wrote %s\nwrote %s\n", files.averages.c_str(), files.runs.c_str());
}

} // namespace

int run_bench(int argc, char** argv) {
    const BenchConfig config = parse_bench_args(argc, argv, 2);
    if (config.help) {
        std::cout << bench_help() << "\nknown scenes: " << join_names(scene_names()) << "\n";
        return exit_ok;
    }
    if (config.mpi) return run_bench_mpi(config);
    std::string reason;
    if (config.options.backend == Backend::cuda && !cuda_available(&reason))
        throw Error("bench: --backend cuda is not available here: " + reason);
    const std::unique_ptr<Scene> scene = open_bench_scene(config);
    ProgressBar progress(!config.quiet, config.runs, last_frame_of(config, *scene) - config.first_frame + 1);
    const BenchOutcome outcome = run_benchmark(config, *scene, [&](int run, int frame_index) {
        progress.update(run, frame_index);
        return true;
    });
    progress.finish();
    const BenchFiles files = write_bench_files(config.output_dir, outcome.stem, outcome.header, outcome.runs);
    print_report(config, *scene, outcome, files);
    return exit_ok;
}

} // namespace kdet::cli
