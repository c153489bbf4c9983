#pragma once
/// @file bench_args.hpp
/// @brief The command line of `kdet bench`: the thesis's flags (appendix A.1.3) and a few more.

#include "cli_args.hpp"

#include <kdet/options.hpp>
#include <kdet/scenes.hpp>

#include <string>

namespace kdet::cli {

/// @brief Everything `kdet bench` was asked to do.
struct BenchConfig {
    std::string scene = "procedural";
    SceneRequest request;                       ///< -r, and --tets / --scene-frames for "procedural"
    DetectorOptions options;                    ///< -c, -o (default sat, as in the thesis), -h, -g, --backend, --threads
    int runs = 10;                              ///< -n
    bool self = false;                          ///< -s
    std::string output_dir = "exports/benchmark_data"; ///< -d
    int first_frame = 0;                        ///< --frames A:B (0-based, inclusive)
    int last_frame = -1;                        ///< -1: up to the scene's last frame
    std::string procedural_flag;                ///< first procedural-only flag given, for the error
    bool quiet = false;
    bool help = false;
};

/// @brief Parses `argv[first..argc)`; throws UsageError naming the flag and its accepted values.
/// The scene name is not checked here (open_scene does that).
BenchConfig parse_bench_args(int argc, char** argv, int first);

/// @brief The thesis's name for a method (`-c`): kdet, kdet_no_pairs, gpu, gpu_no_loop.
const char* bench_method_name(Method method);

/// @brief The text of `kdet bench --help`.
const char* bench_help();

} // namespace kdet::cli
