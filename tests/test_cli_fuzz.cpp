// Property tests of the command lines' values: every value flag of `kdet bench` (its own, --partition,
// and the option table's) reads random text or refuses it with one line naming the flag; `kdet
// collide`'s --partition, --exclusion-rings and --memory-limit refuse malformed values with one line
// and exit 2, as the program runs; collide's --margin and locate's --within read random text or refuse
// it so, and an empty FILE (--pairs, --distances, --out) is refused rather than silently not written.

#include "random_text.hpp"
#include "run_command.hpp"

#include <kdet/option_table.hpp>

#include <gtest/gtest.h>

#ifdef KDET_CLI_CORE
#include "bench_args.hpp"
#include "cli_args.hpp"
#endif

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace kdet {
namespace {

#ifdef KDET_CLI_CORE

TEST(CliFuzz, EveryBenchValueFlagReadsRandomTextOrRefusesItInOneLineNamingIt) {
    std::vector<std::string> flags = {"--partition", "-r", "-n", "-s", "-d", "--frames", "--scene-frames", "--tets"};
    for (const OptionInfo& option : option_table())
        if (option.shown_on(front_end_bench)) flags.push_back(cli::flag_of(option, front_end_bench));
    std::mt19937 rng(48);
    std::size_t accepted = 0, refused = 0;
    for (const std::string& flag : flags)
        for (int draw = 0; draw < 500; ++draw) {
            // --mpi: --partition needs it; its value is checked when the command line is read.
            std::vector<std::string> words = {"kdet", "bench", "--mpi", flag + "=" + test::random_text(rng)};
            std::vector<char*> argv;
            for (std::string& w : words) argv.push_back(w.data());
            try {
                cli::parse_bench_args(static_cast<int>(argv.size()), argv.data(), 2);
                ++accepted;
            } catch (const cli::UsageError& error) {
                ++refused;
                const std::string message = error.what();
                EXPECT_EQ(message.find('\n'), std::string::npos) << words[3] << " -> " << message;
                EXPECT_NE(message.find(flag), std::string::npos) << words[3] << " -> " << message;
            }
        }
    // Both answers occur, so both branches are exercised.
    EXPECT_GT(accepted, 0u);
    EXPECT_GT(refused, 0u);
}

#endif

#ifdef KDET_CLI_PATH

using Outcome = test::CommandOutcome; // stdout and stderr together

/// Runs kdet with @p words, each given to the shell in single quotes (so any byte but NUL passes).
Outcome run_kdet(const std::vector<std::string>& words) {
    std::string command = KDET_CLI_PATH;
    for (const std::string& w : words) {
        command += " '";
        for (const char c : w) command += c == '\'' ? std::string("'\\''") : std::string(1, c);
        command += "'";
    }
    return test::run_command(command + " 2>&1");
}

TEST(CliFuzz, CollideRefusesMalformedValuesOfItsNewFlagsInOneLineWithExit2) {
    const std::vector<std::string> malformed = {"",     "-1",   "x",   "1.5", "nan",     "1e3", "99999999999999999999",
                                                "1\n2", "\xff", "1 ",  "slabs\n", "0x10"};
    // Each flag with what it needs beside it, so that only its value can be wrong.
    const std::vector<std::vector<std::string>> contexts = {
        {"--mpi", "--partition"}, {"--self", "--exclusion-rings"}, {"--self", "--memory-limit"}};
    for (const auto& context : contexts) {
        const std::string& flag = context.back();
        for (const std::string& value : malformed) {
            std::vector<std::string> words = {"collide", "/nonexistent/a.mesh"};
            words.insert(words.end(), context.begin(), context.end() - 1);
            words.push_back(flag + "=" + value);
            const Outcome r = run_kdet(words);
            EXPECT_EQ(r.exit_code, 2) << words.back() << " -> " << r.out;
            EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << words.back() << " -> " << r.out;
            EXPECT_NE(r.out.find(flag), std::string::npos) << words.back() << " -> " << r.out;
        }
    }
}

/// Whether `r` is a refusal of `flag`: one line naming it, exit 2.
void expect_refusal(const Outcome& r, const std::string& flag, const std::string& value) {
    EXPECT_EQ(r.exit_code, 2) << flag << "=" << value << " -> " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << flag << "=" << value << " -> " << r.out;
    EXPECT_NE(r.out.find(flag), std::string::npos) << flag << "=" << value << " -> " << r.out;
}

TEST(CliFuzz, MarginAndWithinReadRandomTextOrRefuseItInOneLineNamingTheFlag) {
    // Each command reads a missing file once its flags are read: an accepted value gets that file's
    // error (exit 1), a refused one a usage error naming the flag (exit 2).
    const std::vector<std::vector<std::string>> commands = {
        {"collide", "/nonexistent/a.mesh", "--self", "--margin"},
        {"locate", "/nonexistent/a.mesh", "/nonexistent/p.xyz", "--out", "/dev/null", "--within"}};
    std::vector<std::string> values = {"",        "-1",     "nan",       "inf",   "1e39",         "3.5e38", "-1e-45", "1 ",
                                       "1e-45",   "1e-400", "0x1p-149",  "-0",    "3.4028235e38", "1\n2",   "\xff",   "0.5m"};
    std::mt19937 rng(4848);
    for (int draw = 0; draw < 40; ++draw) {
        std::string text = test::random_text(rng);
        text.erase(std::remove(text.begin(), text.end(), '\0'), text.end()); // no NUL passes a command line
        values.push_back(text);
    }
    for (const auto& command : commands) {
        const std::string& flag = command.back();
        std::size_t accepted = 0, refused = 0;
        for (const std::string& value : values) {
            std::vector<std::string> words(command.begin(), command.end() - 1);
            words.push_back(flag + "=" + value);
            const Outcome r = run_kdet(words);
            if (r.out.find("/nonexistent/a.mesh") != std::string::npos && r.out.find(flag) == std::string::npos) {
                EXPECT_EQ(r.exit_code, 1) << words.back() << " -> " << r.out;
                ++accepted;
            } else {
                expect_refusal(r, flag, value);
                ++refused;
            }
        }
        EXPECT_GT(accepted, 0u) << flag;
        EXPECT_GT(refused, 0u) << flag;
    }
}

TEST(CliFuzz, AnEmptyOutputFileIsRefusedNotSilentlySkipped) {
    for (const auto& [words, flag] : std::vector<std::pair<std::vector<std::string>, std::string>>{
             {{"collide", "/nonexistent/a.mesh", "--self", "--pairs", ""}, "--pairs"},
             {{"collide", "/nonexistent/a.mesh", "--self", "--margin", "0.1", "--distances", ""}, "--distances"},
             {{"collide", "/nonexistent/a.mesh", "--self", "--contacts", ""}, "--contacts"},
             {{"locate", "/nonexistent/a.mesh", "/nonexistent/p.xyz", "--out", ""}, "--out"}})
        expect_refusal(run_kdet(words), flag, "");
}

#endif

} // namespace
} // namespace kdet
