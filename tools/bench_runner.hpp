#pragma once
/// @file bench_runner.hpp
/// @brief Runs one benchmark (a scene, a method, some runs) and describes it for the CSV files.

#include "bench_args.hpp"
#include "bench_csv.hpp"

#include <kdet/detector.hpp>
#include <kdet/scenes.hpp>

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace kdet::cli {

/// @brief What one benchmark measured.
struct BenchOutcome {
    std::vector<std::vector<FrameRow>> runs; ///< runs[r][f]: frame first_frame + f of run r
    std::vector<HeaderField> header;         ///< thesis fields first, then backend, machine and build
    std::string stem;                        ///< file name without extension, from the parameters
    std::size_t peak_memory = 0;             ///< largest FrameResult::memory_bytes of any frame
    bool stopped = false;                    ///< the progress callback asked to stop; runs are incomplete
};

/// @brief Told before each frame which run (0-based) and frame (0-based within the range) comes
/// next; returning false stops the benchmark there.
using BenchProgress = std::function<bool(int run, int frame_index)>;

/// @brief The last frame `config` selects in `scene` (its --frames B, else the scene's last frame).
int last_frame_of(const BenchConfig& config, const Scene& scene);

/// @brief The resolution its files name: the scene's own (Scene::resolution), else the requested one.
int resolution_of(const BenchConfig& config, const Scene& scene);

/// @brief The files' name without extension: the scene, resolution, method, test, hash, block size,
/// self-collision, backend and tets, then what differs from a plain run (frames, rings, filters, margin).
std::string stem_of(const BenchConfig& config, const Scene& scene, int last_frame);

/// @brief Runs frames first_frame..last_frame_of() of `scene` config.runs times with one Detector
/// (its buffers persist between runs, as in an application). Only detect() is timed; the scene's
/// positions are computed and uploaded outside the measured time.
BenchOutcome run_benchmark(const BenchConfig& config, const Scene& scene, const BenchProgress& progress);

} // namespace kdet::cli
