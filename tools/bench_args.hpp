#pragma once
/// @file bench_args.hpp
/// @brief The command line of `kdet bench`: the thesis's flags (appendix A.1.3) and a few more.

#include "cli_args.hpp"

#include <kdet/options.hpp>
#include <kdet/scenes.hpp>

#include <string>
#include <vector>

namespace kdet::cli {

/// @brief The detector options `kdet bench` starts from: the library's, except the test, which is the
/// thesis's default (sat) so that its files compare with the thesis's.
DetectorOptions bench_default_options();

/// @brief Everything `kdet bench` was asked to do.
struct BenchConfig {
    std::string scene = "procedural";
    SceneRequest request;                       ///< -r, and --tets / --scene-frames for "procedural"
    DetectorOptions options = bench_default_options(); ///< -c, -o, -h, -g, --backend, --threads
    int runs = 10;                              ///< -n
    SceneSelfCollision self = SceneSelfCollision::none; ///< -s yes|no|scene
    int rings = 0;                              ///< --rings: self-exclusion rings of every object, with -s
    bool filters = true;                        ///< --filters: the scene's collision filters
    std::string output_dir = "exports/benchmark_data"; ///< -d
    int first_frame = 0;                        ///< --frames A:B (0-based, inclusive)
    int last_frame = -1;                        ///< -1: up to the scene's last frame
    std::string procedural_flag;                ///< first procedural-only flag given, for the error
    bool resolution_given = false;              ///< -r was given (a scene that fixes its own refuses another)
    bool quiet = false;
    bool help = false;
    bool mpi = false;                           ///< --mpi: run on the ranks of mpirun (kdet::mpi)
    std::string partition;                      ///< --partition, with --mpi
};

/// @brief Parses `argv[first..argc)`; throws UsageError naming the flag and its accepted values.
/// The scene name is not checked here (open_scene does that).
BenchConfig parse_bench_args(int argc, char** argv, int first);

/// @brief The thesis's name for a method (`-c`): kdet, kdet_no_pairs, gpu, gpu_no_loop.
std::string bench_method_name(Method method);

/// @brief The CUDA block sizes `-g` accepts, as in the thesis.
const std::vector<std::string>& bench_block_sizes();

/// @brief The text of `kdet bench --help`.
std::string bench_help();

} // namespace kdet::cli
