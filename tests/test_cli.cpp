// The kdet command as a user runs it: outputs, the pairs file, and one-line errors with exit codes.

#include "filter_support.hpp"
#include "run_command.hpp"
#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/io.hpp>
#include <kdet/locate.hpp>
#include <kdet/option_table.hpp>

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace kdet {
namespace {

#ifdef KDET_CLI_PATH

using Outcome = test::CommandOutcome; // stdout and stderr together

Outcome run_command(const std::string& command_line) { return test::run_command(command_line + " 2>&1"); }

Outcome kdet_cli(const std::string& arguments) { return run_command(std::string(KDET_CLI_PATH) + " " + arguments); }

std::filesystem::path temp_dir() {
    const auto dir = std::filesystem::temp_directory_path() / ("kdet_cli_test_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    return dir;
}

std::size_t line_count(const std::string& text) {
    return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

TEST(Cli, CollideWritesExactlyTheLibrarysPairs) {
    test::use_default_data_dir();
    const TetMesh bunny = read_tet_mesh(data_path("bunny.mesh"));
    const TetMesh shifted = test::moved(bunny, 0.2, 0.1 * test::extent_of(bunny), 0.0, 0.0);
    const auto dir = temp_dir();
    write_tetgen(shifted, (dir / "shifted").string());
    const auto expected = collide(bunny, shifted);
    ASSERT_GT(expected.size(), 100u);

    for (const char* spelling : {"shifted", "shifted.node", "shifted.ele"}) {
        const auto pairs_file = dir / "pairs.txt";
        const Outcome r = kdet_cli("collide " + data_path("bunny.mesh") + " " + (dir / spelling).string() +
                                   " --pairs " + pairs_file.string());
        ASSERT_EQ(r.exit_code, 0) << r.out;
        EXPECT_NE(r.out.find("colliding pairs   " + std::to_string(expected.size())), std::string::npos) << r.out;
        std::ifstream in(pairs_file);
        std::vector<IndexPair> written;
        std::uint32_t i, j;
        while (in >> i >> j) written.emplace_back(i, j);
        EXPECT_EQ(written, expected) << spelling;
    }
}

TEST(Cli, SelfCollisionJsonHasCountsTimesAndMemory) {
    test::use_default_data_dir();
    const Outcome r = kdet_cli("collide " + data_path("octopus-low.mesh") + " --self --json --threads 1");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_EQ(line_count(r.out), 1u) << r.out;
    for (const char* key : {"\"candidates\": ", "\"narrow_phase_candidates\": ", "\"colliding_pairs\": 0",
                            "\"exact_stage_pairs\": 0",
                            "\"times_ms\": {\"bounding_boxes\": ", "\"narrow_phase\": ", "\"total_ms\": ",
                            "\"memory_bytes\": ", "\"host_waits\": "})
        EXPECT_NE(r.out.find(key), std::string::npos) << key << " missing in " << r.out;
}

TEST(Cli, ExclusionRingsLeaveOutTheLibrarysPairsAndNeedSelf) {
    const TetMesh crumpled = test::crumpled_bar(30, 0.45, 3);
    const std::string mesh = (temp_dir() / "crumpled.mesh").string();
    write_medit(crumpled, mesh);
    Detector detector;
    detector.set_self_collision(detector.add_object(crumpled), true);
    const std::size_t all = detector.detect().pairs.size();
    detector.set_self_exclusion_rings(0, 2);
    const std::size_t expected = detector.detect().pairs.size();
    ASSERT_GT(expected, 0u);
    ASSERT_LT(expected, all);
    const Outcome r = kdet_cli("collide " + mesh + " --self --exclusion-rings 2");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_NE(r.out.find("self-collision, exclusion rings 2\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("colliding pairs   " + std::to_string(expected) + "\n"), std::string::npos) << r.out;
    const Outcome pair = kdet_cli("collide " + mesh + " " + mesh + " --exclusion-rings 1");
    EXPECT_EQ(pair.exit_code, 2);
    EXPECT_EQ(pair.out, "kdet collide: --exclusion-rings acts within one mesh: it needs --self\n");
    const Outcome range = kdet_cli("collide " + mesh + " --self --exclusion-rings 5");
    EXPECT_EQ(range.exit_code, 2);
    EXPECT_NE(range.out.find("invalid value '5' for --exclusion-rings: expected an integer in [0, 4]"), std::string::npos)
        << range.out;
}

TEST(Cli, ExactTestReportsThePairsThatReachedItsExactStage) {
    test::use_default_data_dir();
    const std::string mesh = data_path("octopus-low.mesh");
    const Outcome json = kdet_cli("collide " + mesh + " " + mesh + " --test exact --json");
    ASSERT_EQ(json.exit_code, 0) << json.out;
    const std::string key = "\"exact_stage_pairs\": ";
    const auto at = json.out.find(key);
    ASSERT_NE(at, std::string::npos) << json.out;
    EXPECT_GT(std::stoull(json.out.substr(at + key.size())), 0u) << json.out; // an exact copy touches everywhere
    const Outcome text = kdet_cli("collide " + mesh + " " + mesh + " --test exact");
    EXPECT_NE(text.out.find("exact stage       "), std::string::npos) << text.out;
}

TEST(Cli, ContactsFileHasDepthAndUnitDirectionPerPair) {
    test::use_default_data_dir();
    const TetMesh octopus = read_tet_mesh(data_path("octopus-low.mesh"));
    const auto dir = temp_dir();
    write_medit(test::moved(octopus, 0.3, 0.1 * test::extent_of(octopus), 0.0, 0.0), (dir / "moved.mesh").string());
    const auto contacts = dir / "contacts.txt";
    const Outcome r = kdet_cli("collide " + data_path("octopus-low.mesh") + " " + (dir / "moved.mesh").string() +
                               " --contacts " + contacts.string());
    ASSERT_EQ(r.exit_code, 0) << r.out;
    std::ifstream in(contacts);
    std::string line;
    std::size_t lines = 0;
    while (std::getline(in, line)) {
        std::istringstream fields(line);
        std::uint32_t i, j;
        double depth, nx, ny, nz;
        ASSERT_TRUE(fields >> i >> j >> depth >> nx >> ny >> nz) << line;
        EXPECT_GE(depth, 0.0);
        EXPECT_NEAR(nx * nx + ny * ny + nz * nz, 1.0, 1e-4) << line;
        ++lines;
    }
    EXPECT_GT(lines, 10u);
    EXPECT_NE(r.out.find("colliding pairs   " + std::to_string(lines)), std::string::npos) << r.out;
}

TEST(Cli, CheckExactReportsFalsePositivesOfTheConservativeTestOnly) {
    test::use_default_data_dir();
    const TetMesh octopus = read_tet_mesh(data_path("octopus-low.mesh"));
    const auto dir = temp_dir();
    write_medit(test::moved(octopus, 0.5, 0.05 * test::extent_of(octopus), 0.0, 0.0), (dir / "moved.mesh").string());
    const std::string meshes = data_path("octopus-low.mesh") + " " + (dir / "moved.mesh").string();
    const Outcome exact = kdet_cli("collide " + meshes + " --check-exact --json");
    if (exact.exit_code == 2 && exact.out.find("without CGAL") != std::string::npos) GTEST_SKIP() << exact.out;
    ASSERT_EQ(exact.exit_code, 0) << exact.out;
    EXPECT_NE(exact.out.find("\"false_positives\": 0, \"false_negatives\": 0"), std::string::npos) << exact.out;
    const Outcome loose = kdet_cli("collide " + meshes + " --check-exact --test sat_no_edges");
    ASSERT_EQ(loose.exit_code, 0) << loose.out;
    EXPECT_NE(loose.out.find("false negatives  0"), std::string::npos) << loose.out;
    EXPECT_EQ(loose.out.find("false positives  0"), std::string::npos) << loose.out;
}

TEST(Cli, LocateWritesTheLibrarysHitsAndNamesBadLines) {
    const TetMesh mesh = test::load_model("octopus-low.mesh");
    const auto dir = temp_dir();
    {
        std::ofstream points(dir / "points.txt");
        points.precision(17);
        points << "# x y z\n";
        for (std::size_t v = 0; v < mesh.num_vertices(); v += 7)
            points << mesh.positions[3 * v] << ' ' << mesh.positions[3 * v + 1] << ' ' << mesh.positions[3 * v + 2] + 1e-3 << "\n";
        std::ofstream(dir / "bad.txt") << "0 0 0\n1 2 x\n";
    }
    const std::vector<double> xyz = read_points((dir / "points.txt").string());
    LocateOptions within;
    within.within = 0.05;
    const LocateResult expected = locate(mesh, xyz, within);
    const auto out = dir / "hits.txt";
    const Outcome r = kdet_cli("locate " + data_path("octopus-low.mesh") + " " + (dir / "points.txt").string() + " --within 0.05 --out " +
                               out.string());
    ASSERT_EQ(r.exit_code, 0) << r.out;
    std::ifstream in(out);
    std::size_t lines = 0, point = 0;
    std::uint32_t tet = 0;
    double b[4], distance = 0;
    while (in >> point >> tet >> b[0] >> b[1] >> b[2] >> b[3] >> distance) {
        ASSERT_LT(lines, expected.hit_count);
        EXPECT_GE(lines, expected.offsets[point]);
        EXPECT_LT(lines, expected.offsets[point + 1]);
        EXPECT_EQ(tet, expected.tets[lines]);
        for (int k = 0; k < 4; ++k) EXPECT_EQ(b[k], expected.barycentrics[4 * lines + k]);
        EXPECT_EQ(distance, expected.distances[lines]);
        ++lines;
    }
    EXPECT_EQ(lines, expected.hit_count);
    EXPECT_GT(lines, 0u);
    std::size_t held = 0, near = 0;
    for (std::size_t p = 0; p < expected.point_count; ++p)
        if (expected.offsets[p + 1] > expected.offsets[p]) ++(expected.distances[expected.offsets[p]] > 0 ? near : held);
    ASSERT_GT(held, 0u);
    ASSERT_GT(near, 0u);
    EXPECT_NE(r.out.find("located " + std::to_string(held + near) + " (" + std::to_string(held) + " in a tet, " +
                         std::to_string(near) + " near one)"),
              std::string::npos)
        << r.out;

    const Outcome bad = kdet_cli("locate " + data_path("octopus-low.mesh") + " " + (dir / "bad.txt").string() + " --out " + out.string());
    EXPECT_EQ(bad.exit_code, 1);
    EXPECT_NE(bad.out.find("bad.txt:2: expected a coordinate, found 'x'"), std::string::npos) << bad.out;
    EXPECT_EQ(line_count(bad.out), 1u) << bad.out;
    for (const char* within_value : {"-1", "nan", "inf", "1x"}) {
        const Outcome refused = kdet_cli("locate " + data_path("octopus-low.mesh") + " " + (dir / "points.txt").string() +
                                         " --out " + out.string() + " --within " + within_value);
        EXPECT_EQ(refused.exit_code, 2) << within_value;
        EXPECT_NE(refused.out.find("for --within"), std::string::npos) << refused.out;
        EXPECT_EQ(line_count(refused.out), 1u) << refused.out;
    }
}

TEST(Cli, WithAMarginTheSummaryCountsThePairsWithinItAndThoseThatOverlap) {
    const TetMesh bunny = test::load_model("bunny.mesh");
    const auto dir = temp_dir();
    write_tetgen(test::moved(bunny, 0.0, 0.9 * test::extent_of(bunny), 0.0, 0.0), (dir / "beside").string()); // touching
    DetectorOptions options;
    options.margin = 0.05f * static_cast<float>(test::extent_of(bunny));
    options.distances = true;
    Detector detector(options);
    detector.add_object(bunny);
    detector.add_object(read_tet_mesh((dir / "beside").string()));
    const FrameResult& expected = detector.detect();
    const auto overlapping = static_cast<std::size_t>(std::count(expected.distances.begin(), expected.distances.end(), 0.0f));
    ASSERT_GT(overlapping, 0u);
    ASSERT_LT(overlapping, expected.pairs.size());
    const std::string margin = find_option("margin")->text(options);
    const std::string arguments = "collide " + data_path("bunny.mesh") + " " + (dir / "beside").string() + " --margin " + margin;
    const Outcome with_distances = kdet_cli(arguments + " --distances " + (dir / "distances.txt").string());
    ASSERT_EQ(with_distances.exit_code, 0) << with_distances.out;
    EXPECT_NE(with_distances.out.find("pairs in margin   " + std::to_string(expected.pairs.size()) + " (" +
                                      std::to_string(overlapping) + " overlapping, the rest apart)\n"),
              std::string::npos)
        << with_distances.out;
    const Outcome without = kdet_cli(arguments);
    EXPECT_NE(without.out.find("pairs in margin   " + std::to_string(expected.pairs.size()) + "\n"), std::string::npos) << without.out;
    EXPECT_EQ(without.out.find("colliding pairs"), std::string::npos) << without.out;
    const Outcome json = kdet_cli(arguments + " --json --distances " + (dir / "distances.txt").string());
    EXPECT_NE(json.out.find("\"margin\": " + margin + ","), std::string::npos) << json.out;
    EXPECT_NE(json.out.find("\"overlapping_pairs\": " + std::to_string(overlapping) + ","), std::string::npos) << json.out;
}

TEST(Cli, BenchWithoutPairsCountsItsTetsAndHelpListsTheTablesOptions) {
    const Outcome r = kdet_cli("bench --tets 3000 --scene-frames 3 -n 1 -c kdet_no_pairs -d " + (temp_dir() / "bench").string());
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_NE(r.out.find("most colliding tets in a frame"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("most colliding pairs"), std::string::npos) << r.out;
    const Outcome help = kdet_cli("bench --help");
    for (const OptionInfo& o : option_table())
        if (o.shown_on(front_end_bench)) {
            EXPECT_NE(help.out.find(std::string(o.bench_flag) + " "), std::string::npos) << o.name;
        }
}

TEST(Cli, BenchRunsTheBuiltInSceneWithoutData) {
    const auto out_dir = temp_dir() / "bench";
    const Outcome r = kdet_cli("bench --tets 3000 --scene-frames 9 -s yes -n 2 -d " + out_dir.string());
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_NE(r.out.find("scene procedural"), std::string::npos);
    EXPECT_NE(r.out.find("summary: median"), std::string::npos);
    EXPECT_NE(r.out.find("wrote " + out_dir.string()), std::string::npos);
    EXPECT_GE(line_count(r.out), 9u + 3u);
}

struct BadCall {
    const char* arguments;
    int exit_code;
    const char* message; ///< must appear in the single line of output
};

TEST(Cli, MistakesGiveOneLineNamingTheProblemAndANonZeroExit) {
    test::use_default_data_dir();
    const auto dir = temp_dir();
    {
        std::ofstream bad(dir / "bad.mesh");
        bad << "MeshVersionFormatted 1\nDimension 3\nVertices\n2\n0 0 0 0\n1 nope 0 0\n";
    }
    const std::string bunny = data_path("bunny.mesh");
    const std::string bad_mesh = (dir / "bad.mesh").string();
    const BadCall calls[] = {
        {"collide --frobnicate", 2, "unknown option '--frobnicate' (see 'kdet collide --help')"},
        {"collide BUNNY BUNNY --within 1", 2, "kdet collide: unknown option '--within'"},
        {"collide BUNNY BUNNY --margin 0x10", 2, "invalid value '0x10' for --margin"},
        {"collide BUNNY BUNNY --threads ' 2'", 2, "invalid value ' 2' for --threads"},
        {"locate BUNNY BUNNY --out x.txt --margin 0.1", 2, "kdet locate: unknown option '--margin'"},
        {"collide a.mesh b.mesh --method fastest", 2, "invalid value 'fastest' for --method"},
        {"collide a.mesh b.mesh --threads 0", 2, "--threads"},
        {"collide a.mesh b.mesh --threads", 2, "'--threads' needs a value"},
        {"collide a.mesh --self b.mesh", 2, "--self takes one mesh"},
        {"collide a.mesh", 2, "one mesh given"},
        {"collide", 2, "missing mesh A"},
        {"collide /nonexistent/x.mesh --self", 1, "/nonexistent/x.mesh: cannot open file"},
        {"collide BAD --self", 1, "bad.mesh:6: "},
        {"collide BUNNY BUNNY --hash md5", 2, "invalid value 'md5' for --hash"},
        {"bench -c nope", 2, "invalid value 'nope' for -c: expected kdet, kdet_no_pairs, brute_force_loop or brute_force_pairs"},
        {"bench -s maybe", 2, "invalid value 'maybe' for -s: expected yes, y, no, n or scene"},
        {"bench -r 5", 2, "invalid value '5' for -r"},
        {"bench -o sat+mtv", 2, "invalid value 'sat+mtv' for -o"},
        {"bench -g 100", 2, "invalid value '100' for -g"},
        {"bench -n 21", 2, "invalid value '21' for -n"},
        {"bench -h md5", 2, "invalid value 'md5' for -h: expected djb2, fnv-1a, simple or morton"},
        {"bench -h", 2, "option '-h' needs a value"},
        {"bench --backend gpu", 2, "invalid value 'gpu' for --backend"},
        {"bench --threads 0", 2, "invalid value '0' for --threads"},
        {"bench --bucket-capacity 5000", 2, "invalid value '5000' for --bucket-capacity"},
        {"bench --frames 5:2", 2, "kdet bench: invalid value '5:2' for --frames"},
        {"bench --tets 300 --scene-frames 9 --frames 3:9", 2,
         "kdet bench: invalid value '3:9' for --frames: scene 'procedural' has frames 0 to 8"},
        {"bench -d ''", 2, "kdet bench: invalid value '' for -d"},
        {"bench /nonexistent/x.scene", 1, "kdet: error: /nonexistent/x.scene: cannot open scene file"},
        {"bench /nonexistent/x.kdetrec", 1, "kdet: error: /nonexistent/x.kdetrec: cannot open file"},
        {"prepare dragon", 2, "kdet prepare: invalid value 'dragon' for MODEL"},
        {"bench --tets 5", 2, "--tets"},
        {"bench nosuchscene", 2, "unknown scene 'nosuchscene'"},
        {"bench nosuchscene --tets 500", 2, "--tets applies to the procedural scene only"},
        {"bench --frobnicate", 2, "unknown option '--frobnicate'"},
        {"frobnicate", 2, "unknown command 'frobnicate'"},
    };
    for (const BadCall& call : calls) {
        std::string arguments = call.arguments;
        for (auto [name, value] : {std::pair{"BAD", bad_mesh}, std::pair{"BUNNY", bunny}})
            for (auto at = arguments.find(name); at != std::string::npos; at = arguments.find(name))
                arguments.replace(at, std::string(name).size(), value);
        const Outcome r = kdet_cli(arguments);
        EXPECT_EQ(r.exit_code, call.exit_code) << arguments << " -> " << r.out;
        EXPECT_EQ(line_count(r.out), 1u) << arguments << " -> " << r.out;
        EXPECT_NE(r.out.find(call.message), std::string::npos) << arguments << " -> " << r.out;
    }
}

TEST(Cli, AFrameTheMemoryLimitCannotHoldFailsAtOnceNamingItsPairsAndBytes) {
    const auto pile = (temp_dir() / "pile").string();
    write_tetgen(test::identical_tets(200), pile); // 19,900 colliding pairs
    const Outcome refused = kdet_cli("collide " + pile + " --self --memory-limit 100000");
    EXPECT_EQ(refused.exit_code, 1) << refused.out;
    EXPECT_EQ(line_count(refused.out), 1u) << refused.out;
    // The pile's candidates are a lower bound's whole count (candidate_bound.hpp): refused before the count.
    EXPECT_EQ(refused.out.rfind("kdet: error: the frame has at least 19900 candidate pairs", 0), 0u) << refused.out;
    EXPECT_NE(refused.out.find(" bytes ("), std::string::npos) << refused.out;
    EXPECT_NE(refused.out.find("memory_limit 100000"), std::string::npos) << refused.out;
    const Outcome answered = kdet_cli("collide " + pile + " --self");
    EXPECT_EQ(answered.exit_code, 0) << answered.out;
    EXPECT_NE(answered.out.find("colliding pairs   19900"), std::string::npos) << answered.out;
}

TEST(Cli, VersionNamesTheCommitTheProgramWasBuiltFrom) {
    // The commit used to be read when CMake configured the build folder, so rebuilt programs
    // reported an older one.
    const Outcome head = run_command("git -C \"" KDET_SOURCE_DIR "\" rev-parse --short=12 HEAD");
    if (head.exit_code != 0) GTEST_SKIP() << "the sources are not a git checkout: " << head.out;
    const std::string commit = head.out.substr(0, head.out.find('\n'));
    const Outcome version = kdet_cli("--version");
    EXPECT_NE(version.out.find("(" + commit), std::string::npos) << version.out << " vs HEAD " << commit;
}

TEST(Cli, HelpAndVersion) {
    EXPECT_EQ(kdet_cli("--version").exit_code, 0);
    const Outcome help = kdet_cli("collide --help");
    EXPECT_EQ(help.exit_code, 0);
    EXPECT_NE(help.out.find("--pairs FILE"), std::string::npos);
    EXPECT_EQ(kdet_cli("bench --help").exit_code, 0);
    EXPECT_NE(kdet_cli("--help").out.find("view [SCENE | A [B]]"), std::string::npos);
}

#ifdef KDET_VIEWER_LEFT_OUT
TEST(Cli, ViewSaysItWasNotBuilt) {
    for (const char* arguments : {"view", "view --tets 1000 --screenshot x.png", "view --help"}) {
        const Outcome r = kdet_cli(arguments);
        EXPECT_EQ(r.exit_code, 1) << arguments;
        EXPECT_NE(r.out.find("built without the viewer"), std::string::npos) << r.out;
        EXPECT_EQ(line_count(r.out), 1u) << r.out;
    }
}
#else
TEST(Cli, ViewHelpNamesItsOptions) {
    const Outcome help = kdet_cli("view --help");
    EXPECT_EQ(help.exit_code, 0) << help.out;
    for (const char* option : {"--screenshot FILE", "--size WxH", "--method M", "--clip AXIS", "--profile"})
        EXPECT_NE(help.out.find(option), std::string::npos) << option;
}
#endif

#endif

} // namespace
} // namespace kdet
