// `kdet bench`: its argument parser, its CSV files, and an end-to-end run checked against `kdet collide`.

#include <kdet/detector.hpp>
#include <kdet/io.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>

#ifdef KDET_CLI_CORE
#include "bench_args.hpp"
#include "bench_csv.hpp"
#include "bench_runner.hpp"

#include "prepare_support.hpp"
#include "run_command.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>

namespace kdet::cli {
namespace {

BenchConfig parse_words(std::vector<std::string> words) {
    words.insert(words.begin(), {"kdet", "bench"});
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    return parse_bench_args(static_cast<int>(argv.size()), argv.data(), 2);
}

/// @brief What the thesis's flags and --backend/--threads/--frames A:B/--quiet/--help set, as one printable line.
std::string settings(const BenchConfig& c) {
    std::ostringstream out;
    out << c.scene << " r" << c.request.resolution << " " << bench_method_name(c.options.method) << " "
        << to_string(c.options.narrow_phase) << " g" << c.options.block_size << " n" << c.runs << " self "
        << to_string(c.self) << " " << to_string(c.options.hash) << " " << c.output_dir << " " << to_string(c.options.backend)
        << " threads " << c.options.threads << " buckets " << c.options.bucket_capacity << " frames " << c.first_frame << ":" << c.last_frame << " quiet "
        << c.quiet << " help " << c.help << " procedural flag '" << c.procedural_flag << "'";
    return out.str();
}

TEST(BenchArgs, DefaultsAreTheThesiss) {
    EXPECT_EQ(settings(parse_words({})), "procedural r1 kdet sat g128 n10 self no djb2 exports/benchmark_data cpu "
                                         "threads 0 buckets 0 frames 0:-1 quiet 0 help 0 procedural flag ''");
}

TEST(BenchArgs, EveryFlagInAnyOrder) {
    const BenchConfig c = parse_words({"-r", "3", "-c", "gpu_no_loop", "-o", "sat_mtv", "-g", "64", "armadillos", "-n",
                                       "20", "-s", "y", "-h", "fnv-1a", "-d", "out/x", "--backend", "cuda", "--threads",
                                       "4", "--frames", "5:9", "--quiet", "--help", "--bucket-capacity", "32"});
    EXPECT_EQ(settings(c), "armadillos r3 gpu_no_loop sat_mtv g64 n20 self yes fnv-1a out/x cuda threads 4 buckets 32 frames 5:9 "
                           "quiet 1 help 1 procedural flag ''");
}

TEST(BenchArgs, EveryAcceptedValue) {
    for (int r = 1; r <= 4; ++r) EXPECT_EQ(parse_words({"-r", std::to_string(r)}).request.resolution, r);
    const std::pair<const char*, Method> methods[] = {{"kdet", Method::kdet},
                                                      {"kdet_no_pairs", Method::kdet_no_pairs},
                                                      {"gpu", Method::brute_force_loop},
                                                      {"gpu_no_loop", Method::brute_force_pairs}};
    for (const auto& [name, method] : methods) {
        EXPECT_EQ(parse_words({"-c", name}).options.method, method) << name;
        EXPECT_EQ(bench_method_name(method), name);
    }
    const std::pair<const char*, NarrowPhase> tests[] = {{"sat", NarrowPhase::sat},
                                                         {"sat_no_edges", NarrowPhase::sat_no_edges},
                                                         {"sat_mtv", NarrowPhase::sat_mtv},
                                                         {"gjk", NarrowPhase::gjk},
                                                         {"fast", NarrowPhase::fast},
                                                         {"exact", NarrowPhase::exact}};
    for (const auto& [name, test] : tests) EXPECT_EQ(parse_words({"-o", name}).options.narrow_phase, test) << name;
    for (int g : {16, 32, 64, 128, 256}) EXPECT_EQ(parse_words({"-g", std::to_string(g)}).options.block_size, g);
    for (int n : {1, 7, 20}) EXPECT_EQ(parse_words({"-n", std::to_string(n)}).runs, n);
    for (const char* yes : {"yes", "y"}) EXPECT_EQ(parse_words({"-s", yes}).self, SceneSelfCollision::every);
    for (const char* no : {"no", "n"}) EXPECT_EQ(parse_words({"-s", no}).self, SceneSelfCollision::none);
    EXPECT_EQ(parse_words({"-s", "scene"}).self, SceneSelfCollision::marked);
    const std::pair<const char*, HashFunction> hashes[] = {{"djb2", HashFunction::djb2},
                                                           {"fnv-1a", HashFunction::fnv1a},
                                                           {"morton", HashFunction::morton},
                                                           {"simple", HashFunction::simple}};
    for (const auto& [name, hash] : hashes) EXPECT_EQ(parse_words({"-h", name}).options.hash, hash) << name;
    EXPECT_EQ(parse_words({"--backend", "cpu"}).options.backend, Backend::cpu);
    EXPECT_EQ(parse_words({"--threads=2"}).options.threads, 2);
    const BenchConfig one_frame = parse_words({"--frames", "0:0"});
    EXPECT_EQ(one_frame.first_frame, 0);
    EXPECT_EQ(one_frame.last_frame, 0);
}

TEST(BenchArgs, TheThesissExampleCommandRunsUnchanged) {
    // Appendix A.1.3: benchmark_tet buddha_and_armadillo -r 2 -n 5 -c gpu_no_loop -o sat-mtv -d DIR
    const BenchConfig c = parse_words({"buddha_and_armadillo", "-r", "2", "-n", "5", "-c", "gpu_no_loop", "-o", "sat-mtv",
                                       "-d", "./../../exports/benchmark_data"});
    EXPECT_EQ(settings(c), "buddha_and_armadillo r2 gpu_no_loop sat_mtv g128 n5 self no djb2 ./../../exports/benchmark_data "
                           "cpu threads 0 buckets 0 frames 0:-1 quiet 0 help 0 procedural flag ''");
    EXPECT_EQ(parse_words({"-c", "Brute-Force-Pairs", "-h", "FNV_1A", "--backend", "CPU"}).options.method,
              Method::brute_force_pairs);
}

TEST(BenchArgs, HelpListsTheLibrarysNames) {
    const std::string help = bench_help();
    for (const std::string& name : option_names<NarrowPhase>()) EXPECT_NE(help.find(name), std::string::npos) << name;
    for (const std::string& name : option_names<Method>()) EXPECT_NE(help.find(name), std::string::npos) << name;
    EXPECT_NE(help.find("gpu_no_loop = brute_force_pairs"), std::string::npos) << help;
    EXPECT_NE(help.find("sat (default)"), std::string::npos) << help; // the thesis's test, not the library's
}

TEST(BenchArgs, ProceduralSceneSizeAndLength) {
    const BenchConfig c = parse_words({"--tets", "5000", "--scene-frames", "7"});
    EXPECT_EQ(c.request.procedural.total_tets, 5000u);
    EXPECT_EQ(c.request.procedural.frames, 7);
    EXPECT_EQ(c.procedural_flag, "--tets");
    // --frames N keeps its earlier meaning: the procedural scene's length, not a range.
    const BenchConfig legacy = parse_words({"--frames", "9"});
    EXPECT_EQ(legacy.request.procedural.frames, 9);
    EXPECT_EQ(legacy.last_frame, -1);
    EXPECT_EQ(legacy.procedural_flag, "--frames");
}

TEST(BenchArgs, EveryMistakeIsOneLineNamingTheFlagAndWhatItAccepts) {
    const std::pair<std::vector<std::string>, const char*> mistakes[] = {
        {{"-r", "0"}, "invalid value '0' for -r: expected an integer in [1, 4]"},
        {{"-r", "5"}, "invalid value '5' for -r: expected an integer in [1, 4]"},
        {{"-r", "two"}, "invalid value 'two' for -r"},
        {{"-c", "bvh"}, "invalid value 'bvh' for -c: expected kdet, kdet_no_pairs, brute_force_loop or brute_force_pairs"},
        {{"-o", "sat.mtv"}, "invalid value 'sat.mtv' for -o: expected sat, sat_no_edges, sat_mtv, gjk, fast or exact"},
        {{"-g", "100"}, "invalid value '100' for -g: expected 16, 32, 64, 128 or 256"},
        {{"-n", "0"}, "invalid value '0' for -n: expected an integer in [1, 20]"},
        {{"-n", "21"}, "invalid value '21' for -n: expected an integer in [1, 20]"},
        {{"-s", "maybe"}, "invalid value 'maybe' for -s: expected yes, y, no, n or scene"},
        {{"-h", "md5"}, "invalid value 'md5' for -h: expected djb2, fnv-1a, simple or morton"},
        {{"-d", ""}, "invalid value '' for -d: expected a folder"},
        {{"--backend", "gpu"}, "invalid value 'gpu' for --backend: expected cpu or cuda"},
        {{"--threads", "0"}, "invalid value '0' for --threads: expected an integer in [1, 1024]"},
        {{"--frames", "5:2"}, "invalid value '5:2' for --frames: expected A:B with 0 <= A <= B"},
        {{"--frames", "a:b"}, "invalid value 'a:b' for --frames: expected A:B"},
        {{"--frames", "0"}, "invalid value '0' for --frames: expected an integer in [1, 100000]"},
        {{"--scene-frames", "0"}, "invalid value '0' for --scene-frames: expected an integer in [1, 100000]"},
        {{"--tets", "5"}, "invalid value '5' for --tets: expected an integer in [100, 20000000]"},
        {{"--rings", "5", "-s", "yes"}, "invalid value '5' for --rings: expected an integer in [0, 4]"},
        {{"--rings", "1"}, "bench: --rings needs -s yes"},
        {{"--filters", "no"}, "invalid value 'no' for --filters: expected on or off"},
        {{"--mpi", "--rings", "1", "-s", "yes"}, "bench: --rings is not available with --mpi"},
        {{"--frobnicate"}, "bench: unknown option '--frobnicate'"},
        {{"-r"}, "bench: option '-r' needs a value <resolution>"},
        {{"-h"}, "bench: option '-h' needs a value <hash>"},
        {{"--quiet=1"}, "bench: option '--quiet' takes no value"},
        {{"armadillos", "bunny_and_planck"}, "bench: unexpected argument 'bunny_and_planck'"},
    };
    for (const auto& [words, message] : mistakes) {
        try {
            parse_words(words);
            ADD_FAILURE() << message << ": no error";
        } catch (const UsageError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(message), std::string::npos) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        }
    }
}

FrameResult sample_result() {
    FrameResult r;
    r.colliding = {{1, 0, 1, 1}, {0, 1}};
    r.counts.candidates = 40;
    r.counts.narrow_phase_candidates = 30;
    r.counts.colliding_pairs = 5;
    r.counts.colliding_tets = 4;
    r.counts.buffer_regrows = 1;
    r.counts.exact_stage_pairs = 2;
    r.times = StageTimes{0.5, 1.0, 2.0, 3.0, 4.0, 11.0};
    r.memory_bytes = 1234;
    return r;
}

double value_of(const FrameRow& row, const std::string& column) {
    const auto& columns = frame_columns();
    const auto at = std::find(columns.begin(), columns.end(), column);
    EXPECT_NE(at, columns.end()) << column;
    return row.at(static_cast<std::size_t>(at - columns.begin()));
}

TEST(BenchCsv, ColumnsStartWithTheThesissEightThenStagesAndCounts) {
    const std::vector<std::string> expected = {
        "frame", "host time", "device time", "bbox time", "collision time", "col tets A to B", "col tets B to A",
        "collision pairs", "populate time", "find candidates time", "sort unique time", "narrow phase time",
        "candidates", "unique candidates", "colliding tets", "buffer regrows", "memory bytes", "bbox overlap x",
        "exact stage pairs"};
    EXPECT_EQ(frame_columns(), expected);
}

TEST(BenchCsv, FrameRowTakesTimesCountsAndFlagsFromTheResult) {
    const FrameRow row = make_frame_row(7, 12.5, sample_result(), -0.25);
    // In frame_columns() order; collision time = populate + candidates + sort + narrow phase.
    EXPECT_EQ(row, (FrameRow{7, 12.5, 11.0, 0.5, 10.0, 3, 1, 5, 1.0, 2.0, 3.0, 4.0, 40, 30, 4, 1, 1234, -0.25, 2}));
}

TEST(BenchCsv, BoxOverlapAlongXIsNegativeForAGap) {
    const std::vector<float> a = {0, 0, 0, 2, 5, 5}, b = {1.5f, 9, 9, 4, 9, 9}, c = {3, 0, 0, 4, 0, 0};
    EXPECT_DOUBLE_EQ(box_overlap_x(a, b), 0.5);
    EXPECT_DOUBLE_EQ(box_overlap_x(b, a), 0.5);
    EXPECT_DOUBLE_EQ(box_overlap_x(a, c), -1.0);
}

TEST(BenchCsv, AveragesAreTheMeanOfTheRunsFrameByFrame) {
    const std::vector<std::vector<FrameRow>> runs = {{{0, 1.0, 10}, {1, 2.0, 20}},
                                                     {{0, 3.0, 10}, {1, 5.0, 20}},
                                                     {{0, 8.0, 10}, {1, 2.0, 20}}};
    const std::vector<FrameRow> mean = average_runs(runs);
    ASSERT_EQ(mean.size(), 2u);
    EXPECT_EQ(mean[0], (FrameRow{0, 4.0, 10}));
    EXPECT_EQ(mean[1], (FrameRow{1, 3.0, 20}));
    const std::vector<FrameRow> raw = rows_with_run(runs);
    ASSERT_EQ(raw.size(), 6u);
    EXPECT_EQ(raw[0], (FrameRow{0, 0, 1.0, 10}));
    EXPECT_EQ(raw[5], (FrameRow{2, 1, 2.0, 20}));
    EXPECT_TRUE(average_runs({}).empty());
}

TEST(BenchCsv, WriterUsesTheThesisLayout) {
    std::ostringstream out;
    write_bench_csv(out, {{"scene name", "procedural"}, {"device", "CPU, 2 cores"}}, {"frame", "host time"},
                    {{0, 1.5}, {1, 2.0}, {2, 0.1234567}});
    EXPECT_EQ(out.str(),
              "scene name, procedural\ndevice, CPU, 2 cores\nframe, host time\n0, 1.500000\n1, 2\n2, 0.123457\n");
}

// ---- the files as written, read back the way a user reads them ------------------------------------------------

struct CsvFile {
    std::map<std::string, std::string> header;
    std::vector<std::string> header_order;
    std::vector<std::string> columns;
    std::vector<std::vector<double>> rows;

    double at(std::size_t row, const std::string& column) const {
        const auto it = std::find(columns.begin(), columns.end(), column);
        EXPECT_NE(it, columns.end()) << column;
        return rows.at(row).at(static_cast<std::size_t>(it - columns.begin()));
    }
};

std::vector<std::string> split_fields(const std::string& line) {
    std::vector<std::string> fields;
    std::size_t start = 0;
    for (std::size_t comma; (comma = line.find(", ", start)) != std::string::npos; start = comma + 2)
        fields.push_back(line.substr(start, comma - start));
    fields.push_back(line.substr(start));
    return fields;
}

CsvFile read_csv(const std::filesystem::path& path) {
    std::ifstream in(path);
    EXPECT_TRUE(in) << path;
    CsvFile file;
    for (std::string line; std::getline(in, line);) {
        if (file.columns.empty() && (line.rfind("frame, ", 0) == 0 || line.rfind("run, ", 0) == 0)) {
            file.columns = split_fields(line);
        } else if (file.columns.empty()) {
            const auto comma = line.find(", ");
            file.header[line.substr(0, comma)] = line.substr(comma + 2);
            file.header_order.push_back(line.substr(0, comma));
        } else {
            std::vector<double> row;
            for (const std::string& f : split_fields(line)) row.push_back(std::stod(f));
            EXPECT_EQ(row.size(), file.columns.size()) << line;
            file.rows.push_back(row);
        }
    }
    return file;
}

std::filesystem::path temp_dir(const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / ("kdet_bench_test_" + std::to_string(getpid())) / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

void expect_averages_are_means(const CsvFile& averages, const CsvFile& raw, std::size_t runs) {
    ASSERT_EQ(raw.rows.size(), averages.rows.size() * runs);
    for (std::size_t f = 0; f < averages.rows.size(); ++f)
        for (const std::string& column : averages.columns) {
            double sum = 0;
            for (std::size_t r = 0; r < runs; ++r) {
                const std::size_t row = r * averages.rows.size() + f;
                EXPECT_EQ(raw.at(row, "run"), static_cast<double>(r));
                sum += raw.at(row, column);
            }
            // Both files round to 6 decimals.
            EXPECT_NEAR(averages.at(f, column), sum / static_cast<double>(runs), 2e-6) << column << " frame " << f;
        }
}

TEST(BenchRunner, HeaderFieldsAndFrameRange) {
    BenchConfig config;
    config.request.procedural = ProceduralSceneOptions{400, 6};
    config.runs = 2;
    config.first_frame = 1;
    config.last_frame = 3;
    config.self = SceneSelfCollision::every;
    const auto scene = open_scene("procedural", config.request);
    std::vector<std::pair<int, int>> reported;
    const BenchProgress progress = [&](int run, int frame_index) {
        reported.emplace_back(run, frame_index);
        return true;
    };
    const BenchOutcome outcome = run_benchmark(config, *scene, progress);
    const std::vector<std::pair<int, int>> every_frame = {{0, 0}, {0, 1}, {0, 2}, {1, 0}, {1, 1}, {1, 2}};
    EXPECT_EQ(reported, every_frame);
    EXPECT_FALSE(outcome.stopped);

    const std::vector<std::string> thesis_keys = {"scene name",        "resolution", "algorithm", "block size",
                                                  "overlap test",      "self collisions", "hashing algorithm",
                                                  "#frames",           "first frame", "total runs", "#tetsA",
                                                  "#tetsB",            "#verticesA", "#verticesB"};
    const std::vector<std::string> more_keys = {"#objects", "#tets", "backend", "threads", "bucket capacity", "exclusion rings",
                                                "collision filters", "margin", "device", "compiler", "compiler flags",
                                                "kdet version", "peak memory bytes", "time unit"};
    std::vector<std::string> keys;
    std::map<std::string, std::string> header;
    for (const auto& [key, value] : outcome.header) {
        keys.push_back(key);
        header[key] = value;
        EXPECT_FALSE(value.empty()) << key;
    }
    std::vector<std::string> expected = thesis_keys;
    expected.insert(expected.end(), more_keys.begin(), more_keys.end());
    EXPECT_EQ(keys, expected);
    EXPECT_EQ(header["scene name"], "procedural");
    EXPECT_EQ(header["bucket capacity"], config.options.bucket_capacity ? std::to_string(config.options.bucket_capacity) : "automatic");
    EXPECT_EQ(header["algorithm"], "kdet");
    EXPECT_EQ(header["self collisions"], "yes");
    EXPECT_EQ(header["exclusion rings"], "0");
    EXPECT_EQ(header["collision filters"], "on");
    EXPECT_EQ(header["margin"], "0");
    EXPECT_EQ(header["#frames"], "3");
    EXPECT_EQ(header["first frame"], "1");
    EXPECT_EQ(header["total runs"], "2");
    EXPECT_EQ(header["#tetsA"], std::to_string(scene->rest_mesh(0).num_tets()));
    EXPECT_EQ(header["#verticesB"], std::to_string(scene->rest_mesh(1).num_vertices()));
    EXPECT_EQ(header["peak memory bytes"], std::to_string(outcome.peak_memory));
    EXPECT_GT(outcome.peak_memory, 0u);

    ASSERT_EQ(outcome.runs.size(), 2u);
    for (const auto& run : outcome.runs) {
        ASSERT_EQ(run.size(), 3u);
        for (std::size_t f = 0; f < 3; ++f) EXPECT_EQ(value_of(run[f], "frame"), static_cast<double>(f + 1));
    }
    EXPECT_NE(outcome.stem.find("procedural_r1_kdet_sat_djb2_g128_self-yes_cpu_"), std::string::npos) << outcome.stem;
    EXPECT_NE(outcome.stem.find("tets_f1-3"), std::string::npos) << outcome.stem;
    EXPECT_EQ(outcome.stem.find("margin"), std::string::npos) << outcome.stem;

    // A margin reports more pairs: its runs are named apart and say which margin they took.
    BenchConfig within = config;
    within.options.margin = 0.05f;
    const BenchOutcome near = run_benchmark(within, *scene, progress);
    EXPECT_NE(near.stem.find("tets_f1-3_margin0.05"), std::string::npos) << near.stem;
    const std::map<std::string, std::string> near_header(near.header.begin(), near.header.end());
    EXPECT_EQ(near_header.at("margin"), "0.05");
    EXPECT_GT(value_of(near.runs[0][0], "collision pairs"), value_of(outcome.runs[0][0], "collision pairs"));

    config.options.method = Method::brute_force_loop;
    config.first_frame = 0;
    config.last_frame = -1;
    const BenchOutcome brute = run_benchmark(config, *scene, progress);
    EXPECT_EQ(brute.runs[0].size(), 6u);
    EXPECT_EQ(brute.stem.find("_f"), std::string::npos) << brute.stem;
    EXPECT_NE(brute.stem.find("_gpu_sat_none_g128_"), std::string::npos) << brute.stem;
}

TEST(BenchRunner, RingsAndFiltersFlags) {
    EXPECT_EQ(parse_words({"-s", "yes", "--rings", "2"}).rings, 2);
    EXPECT_EQ(parse_words({}).rings, 0);
    EXPECT_FALSE(parse_words({"--filters", "off"}).filters);
    EXPECT_TRUE(parse_words({"--filters", "on"}).filters);

    // heap's filters leave out the pairs of boxes side by side in a layer: off, the bench counts them.
    BenchConfig config;
    config.runs = 1;
    config.first_frame = config.last_frame = 119;
    const auto heap = open_scene("heap");
    const auto pairs = [&](const BenchOutcome& o) { return value_of(o.runs.at(0).at(0), "collision pairs"); };
    const BenchOutcome on = run_benchmark(config, *heap, [](int, int) { return true; });
    config.filters = false;
    const BenchOutcome off = run_benchmark(config, *heap, [](int, int) { return true; });
    EXPECT_GT(pairs(off), pairs(on));
    EXPECT_NE(off.stem.find("_f119-119_filters-off"), std::string::npos) << off.stem;
    EXPECT_EQ(on.stem.find("filters"), std::string::npos) << on.stem;
    // heap has more objects than the thesis's A and B: the header counts them all.
    std::map<std::string, std::string> heap_header(on.header.begin(), on.header.end());
    std::size_t heap_tets = 0;
    for (std::size_t o = 0; o < heap->num_objects(); ++o) heap_tets += heap->rest_mesh(o).num_tets();
    EXPECT_EQ(heap_header["#objects"], std::to_string(heap->num_objects()));
    EXPECT_EQ(heap_header["#tets"], std::to_string(heap_tets));
    EXPECT_NE(on.stem.find("_" + std::to_string(heap_tets) + "tets"), std::string::npos) << on.stem;

    // Rings leave out the self pairs of drape's folds that lie near each other in the mesh.
    config = BenchConfig{};
    config.runs = 1;
    config.first_frame = config.last_frame = 119;
    config.self = SceneSelfCollision::every;
    const auto drape = open_scene("drape");
    const BenchOutcome plain = run_benchmark(config, *drape, [](int, int) { return true; });
    config.rings = 2;
    const BenchOutcome ringed = run_benchmark(config, *drape, [](int, int) { return true; });
    EXPECT_LT(pairs(ringed), pairs(plain));
    EXPECT_NE(ringed.stem.find("_rings2"), std::string::npos) << ringed.stem;
    std::map<std::string, std::string> header(ringed.header.begin(), ringed.header.end());
    EXPECT_EQ(header["exclusion rings"], "2");
}

TEST(BenchRunner, ProgressCanStopIt) {
    BenchConfig config;
    config.request.procedural = ProceduralSceneOptions{400, 4};
    config.runs = 3;
    const auto scene = open_scene("procedural", config.request);
    int frames_allowed = 6;
    const BenchOutcome outcome = run_benchmark(config, *scene, [&](int, int) { return frames_allowed-- > 0; });
    EXPECT_TRUE(outcome.stopped);
    ASSERT_EQ(outcome.runs.size(), 2u);
    EXPECT_EQ(outcome.runs[0].size(), 4u);
    EXPECT_EQ(outcome.runs[1].size(), 2u);
}

TEST(BenchRunner, FilesHoldAveragesAndRuns) {
    BenchConfig config;
    config.request.procedural = ProceduralSceneOptions{600, 5};
    config.runs = 3;
    const auto scene = open_scene("procedural", config.request);
    const BenchOutcome outcome = run_benchmark(config, *scene, [](int, int) { return true; });
    const auto dir = temp_dir("files") / "nested";
    const BenchFiles files = write_bench_files(dir.string(), outcome.stem, outcome.header, outcome.runs);
    EXPECT_EQ(files.averages, (dir / (outcome.stem + ".csv")).string());
    EXPECT_EQ(files.runs, (dir / (outcome.stem + "_runs.csv")).string());
    const CsvFile averages = read_csv(files.averages), raw = read_csv(files.runs);
    EXPECT_EQ(averages.columns, frame_columns());
    EXPECT_EQ(raw.columns.front(), "run");
    EXPECT_EQ(averages.header_order, raw.header_order);
    EXPECT_EQ(averages.rows.size(), 5u);
    expect_averages_are_means(averages, raw, 3);
}

#ifdef KDET_CLI_PATH

/// @brief Runs the kdet command; stdout only (stderr goes to `stderr_file` when given).
std::pair<int, std::string> kdet_command(const std::string& arguments, const std::string& stderr_file = "/dev/null") {
    const std::string command = std::string(KDET_CLI_PATH) + " " + arguments + " 2>" + stderr_file;
    const test::CommandOutcome r = test::run_command(command);
    return {r.exit_code, r.out};
}

std::uint64_t colliding_pairs_of(const std::string& json) {
    const std::string key = "\"colliding_pairs\": ";
    const auto at = json.find(key);
    EXPECT_NE(at, std::string::npos) << json;
    return at == std::string::npos ? 0 : std::stoull(json.substr(at + key.size()));
}

CsvFile only_csv(const std::filesystem::path& dir, bool raw) {
    std::vector<std::filesystem::path> found;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        const bool is_raw = name.size() > 9 && name.compare(name.size() - 9, 9, "_runs.csv") == 0;
        if (is_raw == raw) found.push_back(entry.path());
    }
    EXPECT_EQ(found.size(), 1u) << dir;
    return found.empty() ? CsvFile{} : read_csv(found[0]);
}

TEST(BenchEndToEnd, CsvPairCountsEqualKdetCollideOnTheSameFrame) {
    const auto dir = temp_dir("end_to_end");
    const std::string scene_flags = "--tets 3000 --scene-frames 9";
    SceneRequest request;
    request.procedural = ProceduralSceneOptions{3000, 9};
    const auto scene = open_scene("procedural", request);

    // The frame of deepest interpenetration, as two TetGen meshes.
    const int frame = 4;
    std::string stems[2];
    for (std::size_t o = 0; o < 2; ++o) {
        TetMesh mesh = scene->rest_mesh(o);
        scene->positions(o, frame, mesh.positions);
        stems[o] = (dir / ("object" + std::to_string(o))).string();
        write_tetgen(mesh, stems[o]);
    }
    const auto pairs_file = dir / "pairs.txt";
    const auto [collide_code, between_json] =
        kdet_command("collide " + stems[0] + " " + stems[1] + " --json --pairs " + pairs_file.string());
    ASSERT_EQ(collide_code, 0) << between_json;
    const std::uint64_t between = colliding_pairs_of(between_json);
    ASSERT_GT(between, 0u);
    std::set<std::uint32_t> tets_a, tets_b;
    {
        std::ifstream in(pairs_file);
        for (std::uint32_t i, j; in >> i >> j;) {
            tets_a.insert(i);
            tets_b.insert(j);
        }
    }
    const std::uint64_t inside_a = colliding_pairs_of(kdet_command("collide " + stems[0] + " --self --json").second);
    const std::uint64_t inside_b = colliding_pairs_of(kdet_command("collide " + stems[1] + " --self --json").second);

    for (const bool self : {false, true}) {
        const auto out_dir = dir / (self ? "self" : "no_self");
        const auto stderr_file = dir / "stderr.txt";
        const auto [code, out] = kdet_command("bench procedural " + scene_flags + " -n 2 -s " + (self ? "yes" : "no") +
                                                  " -d " + out_dir.string(),
                                              stderr_file.string());
        ASSERT_EQ(code, 0) << out;
        EXPECT_NE(out.find("wrote " + out_dir.string()), std::string::npos) << out;
        // Not a terminal: no progress bar in the captured stderr.
        std::ifstream err(stderr_file);
        EXPECT_EQ(std::string(std::istreambuf_iterator<char>(err), {}), "");

        const CsvFile averages = only_csv(out_dir, false), raw = only_csv(out_dir, true);
        ASSERT_EQ(averages.rows.size(), 9u);
        expect_averages_are_means(averages, raw, 2);
        EXPECT_EQ(averages.at(frame, "frame"), frame);
        const double expected = static_cast<double>(self ? between + inside_a + inside_b : between);
        EXPECT_EQ(averages.at(frame, "collision pairs"), expected) << "self " << self;
        if (!self) {
            EXPECT_EQ(averages.at(frame, "col tets A to B"), static_cast<double>(tets_a.size()));
            EXPECT_EQ(averages.at(frame, "col tets B to A"), static_cast<double>(tets_b.size()));
        }
        EXPECT_EQ(averages.header.at("#tetsA"), std::to_string(scene->rest_mesh(0).num_tets()));
        EXPECT_EQ(averages.header.at("total runs"), "2");
    }
}

TEST(BenchEndToEnd, CudaBackendGivesTheCpuCountsOrAClearError) {
    const auto dir = temp_dir("cuda");
    const std::string flags = " --tets 2000 --scene-frames 5 -n 1 --quiet -s yes -d ";
    std::string reason;
    if (!cuda_available(&reason)) {
        const auto [code, out] = kdet_command("bench --backend cuda" + flags + dir.string(), "&1");
        EXPECT_EQ(code, 1) << out;
        EXPECT_NE(out.find("bench: --backend cuda is not available here: " + reason), std::string::npos) << out;
        EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
        return;
    }
    for (const char* backend : {"cpu", "cuda"})
        ASSERT_EQ(kdet_command(std::string("bench --backend ") + backend + flags + (dir / backend).string()).first, 0);
    const CsvFile cpu = only_csv(dir / "cpu", false), cuda = only_csv(dir / "cuda", false);
    ASSERT_EQ(cpu.rows.size(), cuda.rows.size());
    for (std::size_t f = 0; f < cpu.rows.size(); ++f)
        for (const char* column : {"collision pairs", "col tets A to B", "col tets B to A"})
            EXPECT_EQ(cpu.at(f, column), cuda.at(f, column)) << column << " frame " << f;
}

TEST(BenchCommand, AResolutionTheSceneDoesNotHaveIsRefusedAndTheFilesNameTheOneItHas) {
    // pass_through_armadillos is at resolution 2 whatever -r says: -r 4 was run at 2 and named r4.
    const auto dir = temp_dir("fixed-resolution");
    const std::string flags = " --frames 0:0 -n 1 --quiet -d " + dir.string();
    // A scene of no resolution: -r would only rename its files.
    const auto [none, none_message] = kdet_command("bench tearing -r 2" + flags, "&1");
    EXPECT_EQ(none, 2) << none_message;
    EXPECT_EQ(none_message,
              "kdet bench: invalid value '2' for -r: scene 'tearing' has no resolution (its meshes are not built at one)\n");
    using test::run_prepare;
    KDET_PREPARE_OR_SKIP("armadillo -r 2");
    const auto [refused, message] = kdet_command("bench pass_through_armadillos -r 4" + flags, "&1");
    EXPECT_EQ(refused, 2) << message;
    EXPECT_EQ(message, "kdet bench: invalid value '4' for -r: scene 'pass_through_armadillos' is built at resolution 2 only\n");
    ASSERT_EQ(kdet_command("bench pass_through_armadillos" + flags).first, 0);
    std::size_t named = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        const std::string file = entry.path().filename().string();
        EXPECT_EQ(file.rfind("pass_through_armadillos_r2_", 0), 0u) << file;
        ++named;
    }
    EXPECT_EQ(named, 2u);
    EXPECT_EQ(only_csv(dir, false).header["resolution"], "2");
    std::filesystem::remove_all(dir);
}

#endif

} // namespace
} // namespace kdet::cli
#endif
