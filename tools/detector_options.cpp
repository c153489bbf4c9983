// The detector flags that every subcommand shares (collide, view).

#include "commands.hpp"

#include <string>

namespace kdet::cli {

void add_detector_options(ArgParser& parser, DetectorOptions& options) {
    parser.option("--method", "method", [&](const std::string& v) {
        if (!parse(v, options.method))
            throw UsageError("invalid value '" + v + "' for --method: expected " +
                             join_choices({"kdet", "kdet_no_pairs", "brute_force_loop", "brute_force_pairs"}));
    });
    parser.option("--test", "test", [&](const std::string& v) {
        if (!parse(v, options.narrow_phase))
            throw UsageError("invalid value '" + v + "' for --test: expected " +
                             join_choices({"sat", "sat_no_edges", "sat_mtv", "gjk", "fast"}));
    });
    parser.option("--hash", "hash", [&](const std::string& v) {
        if (!parse(v, options.hash))
            throw UsageError("invalid value '" + v + "' for --hash: expected " +
                             join_choices({"djb2", "fnv-1a", "simple", "morton"}));
    });
    parser.option("--backend", "backend", [&](const std::string& v) {
        if (!parse(v, options.backend))
            throw UsageError("invalid value '" + v + "' for --backend: expected " + join_choices({"cpu", "cuda"}));
    });
    parser.option("--threads", "N",
                  [&](const std::string& v) { options.threads = static_cast<int>(parse_integer("--threads", v, 1, 1024)); });
    parser.option("--bucket-capacity", "N", [&](const std::string& v) {
        options.bucket_capacity = static_cast<std::uint32_t>(parse_integer("--bucket-capacity", v, 1, 4096));
    });
    parser.option("--block-size", "N", [&](const std::string& v) {
        options.block_size = static_cast<int>(parse_integer("--block-size", v, 1, 1024));
    });
}

const char* detector_options_help() {
    return R"(  --method M           kdet (default), kdet_no_pairs, brute_force_loop, brute_force_pairs
  --test T             narrow phase: sat (default), sat_no_edges, sat_mtv, gjk, fast
  --hash H             grid hash: djb2 (default), fnv-1a, simple, morton
  --backend B          cpu (default) or cuda
  --threads N          CPU threads (default: all)
  --block-size N       CUDA threads per block (default 128)
  --bucket-capacity N  tet ids per grid bucket before an overflow bucket is chained (default 32)
)";
}

} // namespace kdet::cli
