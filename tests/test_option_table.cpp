/// @file test_option_table.cpp
/// @brief The option table walked entry by entry: every front end that shows an option accepts a
/// valid value and refuses an invalid one with the library's one message (python/tests/test_options.py
/// walks it for Python).

#include "run_command.hpp"
#include "test_support.hpp"

#include <kdet/error.hpp>
#include <kdet/option_table.hpp>

#include <gtest/gtest.h>

#ifdef KDET_CLI_CORE
#include "bench_args.hpp"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#endif

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace kdet {
namespace {

/// A value every front end that shows @p o accepts: its default, or its lowest when it is unset.
std::string valid_text(const OptionInfo& o) {
    return o.unset_by_default() ? std::to_string(o.min) : o.default_text();
}

/// A value no front end accepts.
std::string invalid_text(const OptionInfo& o) {
    switch (o.type) {
    case OptionType::choice: return "nope";
    case OptionType::boolean: return "maybe";
    case OptionType::real: return "-1";
    case OptionType::integer: break;
    }
    return o.max < std::numeric_limits<long long>::max() ? std::to_string(o.max + 1) : std::to_string(o.min - 1);
}

/// The entries @p front_end shows, at least @p at_least of them.
std::vector<const OptionInfo*> shown_on(FrontEnd front_end, std::size_t at_least) {
    std::vector<const OptionInfo*> out;
    for (const OptionInfo& o : option_table())
        if (o.shown_on(front_end)) out.push_back(&o);
    EXPECT_GE(out.size(), at_least);
    return out;
}

std::string refusal(const OptionInfo& o, const std::string& shown, const std::string& text) {
    try {
        DetectorOptions options;
        o.parse(text, options, shown);
    } catch (const Error& e) {
        return e.what();
    }
    return "accepted";
}

TEST(OptionTable, EveryEntryReadsItsOwnTextBackAndRefusesAnotherWithOneMessage) {
    ASSERT_FALSE(option_table().empty());
    for (const OptionInfo& o : option_table()) {
        SCOPED_TRACE(o.name);
        EXPECT_EQ(find_option(o.name), &o);
        EXPECT_EQ(find_option(o.field), &o);
        DetectorOptions options;
        o.parse(valid_text(o), options, o.name);
        EXPECT_EQ(o.text(options), valid_text(o));
        const std::string bad = invalid_text(o);
        EXPECT_EQ(refusal(o, o.name, bad), invalid_value_message(o.name, bad, o.expected()));
        EXPECT_EQ(invalid_value_message(o.name, bad, o.expected()).find('\n'), std::string::npos);
        if (o.type == OptionType::real) {
            EXPECT_THROW(o.set_real(options, -1.0), Error);
        } else if (o.type != OptionType::choice) {
            EXPECT_THROW(o.set_number(options, o.min - 1), Error);
            if (o.max < std::numeric_limits<long long>::max()) {
                EXPECT_THROW(o.set_number(options, o.max + 1), Error);
            }
        }
        EXPECT_TRUE(o.shown_on(front_end_python)) << "every option is a keyword of kdet.Detector";
    }
    EXPECT_EQ(find_option("narrow-phase"), find_option("test"));
    EXPECT_EQ(find_option("--block-size"), find_option("block_size"));
    EXPECT_EQ(find_option("cuda_stream"), nullptr); // a handle, given in C++ and Python only
}

TEST(OptionTable, TheTestsMessageListsEveryTest) {
    EXPECT_EQ(refusal(*find_option("test"), "--test", "x"),
              "invalid value 'x' for --test: expected sat, sat_no_edges, sat_mtv, gjk, fast or exact");
    DetectorOptions options;
    find_option("test")->parse("SAT-MTV", options, "--test");
    EXPECT_EQ(options.narrow_phase, NarrowPhase::sat_mtv);
}

#ifdef KDET_CLI_CORE

cli::BenchConfig bench_words(std::vector<std::string> words) {
    words.insert(words.begin(), {"kdet", "bench"});
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    return cli::parse_bench_args(static_cast<int>(argv.size()), argv.data(), 2);
}

std::string bench_refusal(const std::vector<std::string>& words) {
    try {
        bench_words(words);
    } catch (const cli::UsageError& e) {
        return e.what();
    }
    return "accepted";
}

TEST(OptionTable, KdetBenchAcceptsAndRefusesEveryOptionItShowsAsTheLibraryDoes) {
    for (const OptionInfo* option : shown_on(front_end_bench, 6)) {
        const OptionInfo& o = *option;
        const std::string flag = o.bench_flag;
        DetectorOptions expected = cli::bench_default_options();
        o.parse(valid_text(o), expected, flag);
        EXPECT_EQ(o.get(bench_words({flag, valid_text(o)}).options), o.get(expected)) << flag;
        const std::string bad = invalid_text(o);
        EXPECT_EQ(bench_refusal({flag, bad}), "bench: " + refusal(o, flag, bad));
    }
    // -g keeps the thesis's block sizes, a few of those the library accepts.
    EXPECT_EQ(bench_words({"-g", "64"}).options.block_size, 64);
    EXPECT_EQ(bench_refusal({"-g", "100"}), "bench: invalid value '100' for -g: expected 16, 32, 64, 128 or 256");
}

TEST(OptionTable, KdetBenchTakesTheThesissExampleCommandUnchanged) {
    // Appendix A.1.3, as printed there (with the output folder kdet writes to by default).
    const cli::BenchConfig c = bench_words({"buddha_and_armadillo", "-r", "2", "-n", "5", "-c", "gpu_no_loop", "-o",
                                            "sat-mtv", "-d", "exports/benchmark_data"});
    EXPECT_EQ(c.scene, "buddha_and_armadillo");
    EXPECT_EQ(c.request.resolution, 2);
    EXPECT_EQ(c.runs, 5);
    EXPECT_EQ(c.options.method, Method::brute_force_pairs);
    EXPECT_EQ(c.options.narrow_phase, NarrowPhase::sat_mtv);
    EXPECT_EQ(c.output_dir, "exports/benchmark_data");
    EXPECT_EQ(c.self, SceneSelfCollision::none);
}

#ifdef KDET_CLI_PATH
using CliRun = test::CommandOutcome;

CliRun kdet_cli(const std::string& arguments) {
    return test::run_command(std::string(KDET_CLI_PATH) + " " + arguments + " 2>&1");
}

TEST(OptionTable, KdetCollideAcceptsAndRefusesEveryOptionItShowsAsTheLibraryDoes) {
    test::use_default_data_dir();
    const std::string mesh = data_path("octopus-low.mesh");
    for (const OptionInfo* option : shown_on(front_end_cli, 7)) {
        const OptionInfo& o = *option;
        const std::string flag = o.flag;
        const CliRun good = kdet_cli("collide " + mesh + " --self --json " + flag + " " + valid_text(o));
        EXPECT_EQ(good.exit_code, 0) << flag << ": " << good.out;
        const std::string bad = invalid_text(o);
        const CliRun refused = kdet_cli("collide " + mesh + " --self " + flag + " " + bad);
        EXPECT_EQ(refused.exit_code, 2);
        EXPECT_EQ(refused.out, "kdet collide: " + refusal(o, flag, bad) + "\n");
    }
}

TEST(OptionTable, KdetLocateTakesTheOptionsPointLocationReadsAndRefusesTheOthers) {
    test::use_default_data_dir();
    const std::string mesh = data_path("octopus-low.mesh");
    const std::string out = (std::filesystem::temp_directory_path() / "kdet-option-table-locate.txt").string();
    const std::string call = "locate " + mesh + " " + mesh + " --out " + out + " ";
    const std::string help = kdet_cli("locate --help").out;
    for (const OptionInfo& o : option_table()) {
        const std::string flag = o.flag;
        if (!o.shown_on(front_end_locate)) {
            if (flag.empty()) continue;
            // A frame's option would change nothing here: refused, not ignored.
            const CliRun refused = kdet_cli(call + flag + " " + valid_text(o));
            EXPECT_EQ(refused.exit_code, 2) << flag << ": " << refused.out;
            EXPECT_EQ(help.find(flag + " "), std::string::npos) << flag;
            continue;
        }
        EXPECT_NE(help.find(flag + " "), std::string::npos) << flag;
        const CliRun good = kdet_cli(call + flag + " " + valid_text(o));
        EXPECT_EQ(good.exit_code, 0) << flag << ": " << good.out;
        const std::string bad = invalid_text(o);
        const CliRun refused = kdet_cli(call + flag + " " + bad);
        EXPECT_EQ(refused.exit_code, 2);
        EXPECT_EQ(refused.out, "kdet locate: " + refusal(o, flag, bad) + "\n");
    }
    shown_on(front_end_locate, 4);
}
#endif

#endif

} // namespace
} // namespace kdet
