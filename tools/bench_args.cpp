#include "bench_args.hpp"

#include "commands.hpp"

#include <kdet/error.hpp>

#include <string>
#include <vector>

namespace kdet::cli {

namespace {

/// The table's options that bench takes under their --flag (the thesis's single-letter flags and the
/// backend are worded above).
std::string table_options_help(const DetectorOptions& defaults) {
    std::string lines;
    for (const OptionInfo& o : option_table())
        if (o.shown_on(front_end_bench) && std::string(o.bench_flag).rfind("--", 0) == 0 && std::string(o.name) != "backend")
            lines += option_help_line(o, front_end_bench, defaults);
    return lines;
}

std::string help_text() {
    const DetectorOptions defaults = bench_default_options();
    std::string thesis_names;
    for (const std::string& name : option_names<Method>()) {
        Method method{};
        parse(name, method);
        for (const std::string& alias : aliases(method)) thesis_names += (thesis_names.empty() ? "" : ", ") + alias + " = " + name;
    }
    return R"(usage: kdet bench [scene] [options]

Runs a scene frame by frame and writes per-frame times and pair counts as CSV (thesis appendix A.1.4):
  DIR/STEM.csv        per-frame averages over the runs
  DIR/STEM_runs.csv   every run of every frame
where STEM names the parameters, e.g. procedural_r1_kdet_sat_djb2_g128_self-no_cpu_100272tets.
Frames are numbered from 0. Times are in milliseconds.

scene: procedural (default; two deforming tori, no data files needed) or another scene that kdet
       opens (the known names are listed at the end).

thesis options (any order):
  -r N                 model resolution 1-4 (default 1)
  -c M                 method: )" + find_option("method")->values_help(defaults) + R"(
                       (the thesis's names: )" + thesis_names + R"()
  -o T                 overlap test: )" + find_option("test")->values_help(defaults) + R"(
  -g N                 CUDA block size: 16, 32, 64, 128 (default) or 256
  -n N                 runs 1-20 (default 10)
  -s yes|y|no|n|scene  self-collisions of every object, of none (default), or of those the scene
                       marks (a scene file's `self` lines, drape's sheet, a recording's flags)
  -h H                 grid hash: )" + find_option("hash")->values_help(defaults) + R"(  (-h is not help)
  -d DIR               output folder (default exports/benchmark_data)

more options:
  --backend B          where detection runs: )" + find_option("backend")->values_help(defaults) + R"(; cuda needs a GPU
)" + table_options_help(defaults) + R"(  --frames A:B         run frames A to B only (0-based, inclusive)
  --rings K            with -s yes or scene: also leave out tets within K mesh edges of each other in every
                       object (self-exclusion rings, 0-)" + std::to_string(max_exclusion_rings) + R"(; default 0: only tets sharing a vertex)
  --filters on|off     the scene's collision filters between objects (heap's groups; default on)
  --quiet              no per-frame table and no progress bar; only the summary
  --mpi                run on the ranks of mpirun (kdet::mpi), each on its part of the scene, and
                       write per frame the tets and bytes they exchanged (DIR/STEM_mpi-npN-P.csv)
  --partition P        with --mpi: slabs (along the longest axis at the first frame, default) or random
  --help               this text

procedural scene only:
  --tets N             total tetrahedra (default 100000, 100 to 20000000)
  --scene-frames N     length of the motion in frames (default 120)
  --frames N           the same as --scene-frames N (kept from earlier versions)
Names of methods, tests, hashes and backends ignore case, and '-' and '_' are interchangeable.
)";
}

} // namespace

DetectorOptions bench_default_options() {
    DetectorOptions options;
    options.narrow_phase = NarrowPhase::sat;
    return options;
}

std::string bench_method_name(Method method) {
    const std::vector<std::string> thesis_names = aliases(method);
    return thesis_names.empty() ? to_string(method) : thesis_names.front();
}

std::string bench_help() { return help_text(); }

const std::vector<std::string>& bench_block_sizes() {
    static const std::vector<std::string> sizes = {"16", "32", "64", "128", "256"};
    return sizes;
}

BenchConfig parse_bench_args(int argc, char** argv, int first) {
    BenchConfig config;
    std::vector<std::string> scene;
    CommandLine parser("bench");
    parser.positionals(1, scene);
    parser.flag("--help", config.help);
    parser.flag("--quiet", config.quiet);
    parser.flag("--mpi", config.mpi);
    parser.option("--partition", "slabs|random", [&](const std::string& v) {
        config.partition = parse_choice("--partition", v, {"slabs", "random"});
    });
    parser.option("-r", "resolution", [&](const std::string& v) {
        config.request.resolution = static_cast<int>(parse_integer("-r", v, 1, 4));
        config.resolution_given = true;
    });
    parser.detector_options(config.options, front_end_bench);
    // The thesis's block sizes, a few of those the library accepts.
    const OptionInfo& block_size = *find_option("block_size");
    parser.option(block_size.bench_flag, "block size", [&](const std::string& v) {
        block_size.parse(parse_choice(block_size.bench_flag, v, bench_block_sizes()), config.options, block_size.bench_flag);
    });
    parser.option("-n", "runs", [&](const std::string& v) { config.runs = static_cast<int>(parse_integer("-n", v, 1, 20)); });
    parser.option("-s", "yes|no|scene", [&](const std::string& v) {
        const std::string choice = parse_choice("-s", v, {"yes", "y", "no", "n", "scene"});
        config.self = choice == "scene" ? SceneSelfCollision::marked
                      : choice[0] == 'y' ? SceneSelfCollision::every
                                         : SceneSelfCollision::none;
    });
    parser.option("--rings", "K", [&](const std::string& v) {
        config.rings = static_cast<int>(parse_integer("--rings", v, 0, max_exclusion_rings));
    });
    parser.option("--filters", "on|off", [&](const std::string& v) { config.filters = parse_choice("--filters", v, {"on", "off"}) == "on"; });
    parser.option("-d", "folder", [&](const std::string& v) {
        if (v.empty()) throw UsageError("invalid value '' for -d: expected a folder");
        config.output_dir = v;
    });
    const auto scene_length = [&](const std::string& flag, const std::string& v) {
        config.request.procedural.frames = static_cast<int>(parse_integer(flag, v, 1, 100000));
        if (config.procedural_flag.empty()) config.procedural_flag = flag;
    };
    parser.option("--frames", "A:B", [&](const std::string& v) {
        const auto colon = v.find(':');
        if (colon == std::string::npos) return scene_length("--frames", v);
        try {
            config.first_frame = static_cast<int>(parse_integer("--frames", v.substr(0, colon), 0, 1000000));
            config.last_frame = static_cast<int>(parse_integer("--frames", v.substr(colon + 1), config.first_frame, 1000000));
        } catch (const Error&) {
            throw UsageError(invalid_value_message("--frames", v,
                                                   "A:B with 0 <= A <= B (0-based frames), or N (length of the procedural scene)"));
        }
    });
    parser.option("--scene-frames", "N", [&](const std::string& v) { scene_length("--scene-frames", v); });
    parser.option("--tets", "N", [&](const std::string& v) {
        config.request.procedural.total_tets = static_cast<std::size_t>(parse_integer("--tets", v, 100, 20000000));
        if (config.procedural_flag.empty()) config.procedural_flag = "--tets";
    });
    parser.parse(argc, argv, first);
    if (!scene.empty()) config.scene = scene[0];
    if (!config.partition.empty() && !config.mpi) throw UsageError("bench: --partition needs --mpi");
    if (config.rings > 0 && config.self == SceneSelfCollision::none)
        throw UsageError("bench: --rings needs -s yes or -s scene (rings act within an object)");
    if (config.mpi && config.rings > 0) throw UsageError("bench: --rings is not available with --mpi");
    return config;
}

} // namespace kdet::cli
