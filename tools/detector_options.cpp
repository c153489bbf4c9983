// The detector flags that every subcommand shares (collide, view).

#include "commands.hpp"

#include <string>

namespace kdet::cli {

const char* const bucket_capacity_help =
    "  --bucket-capacity N  tet ids per grid bucket before an overflow bucket is chained, 1-4096\n"
    "                       (default 0: chosen from the scene, 4-32)\n";

void add_bucket_capacity_option(ArgParser& parser, DetectorOptions& options) {
    parser.option("--bucket-capacity", "N", [&](const std::string& v) {
        options.bucket_capacity = static_cast<std::uint32_t>(parse_integer("--bucket-capacity", v, 0, max_bucket_capacity));
    });
}

void add_detector_options(ArgParser& parser, DetectorOptions& options) {
    parser.option("--method", "method", [&](const std::string& v) { options.method = parse_option<Method>("--method", v); });
    parser.option("--test", "test", [&](const std::string& v) { options.narrow_phase = parse_option<NarrowPhase>("--test", v); });
    parser.option("--hash", "hash", [&](const std::string& v) { options.hash = parse_option<HashFunction>("--hash", v); });
    parser.option("--backend", "backend", [&](const std::string& v) { options.backend = parse_option<Backend>("--backend", v); });
    parser.option("--threads", "N",
                  [&](const std::string& v) { options.threads = static_cast<int>(parse_integer("--threads", v, 1, 1024)); });
    add_bucket_capacity_option(parser, options);
    parser.option("--block-size", "N", [&](const std::string& v) {
        options.block_size = static_cast<int>(parse_integer("--block-size", v, 1, 1024));
    });
}

std::string detector_options_help() {
    const DetectorOptions defaults;
    return "  --method M           " + option_help(defaults.method) +
           "\n  --test T             narrow phase: " + option_help(defaults.narrow_phase) +
           "\n  --hash H             grid hash: " + option_help(defaults.hash) +
           "\n  --backend B          " + option_help(defaults.backend) +
           R"(
  --threads N          CPU threads (default: all)
  --block-size N       CUDA threads per block (default 128)
)" + std::string(bucket_capacity_help);
}

} // namespace kdet::cli
