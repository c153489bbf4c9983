#pragma once
/// @file cli_args.hpp
/// @brief The command lines of kdet's subcommands on CLI11, with every mistake a one-line UsageError
/// worded as kdet words it, and the detector's flags taken from the library's option table.

#include <kdet/option_table.hpp>
#include <kdet/options.hpp>
#include <kdet/results.hpp>

#include <functional>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace kdet {
class Scene;
}

namespace kdet::cli {

/// @brief A mistake on the command line; the message names the flag and what it accepts.
class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// @brief One subcommand's flags and positional arguments (a CLI11 app), parsed from argv.
/// CLI11's own help flag is off: `-h` is `kdet bench`'s hash, and each command prints its own --help.
class CommandLine {
public:
    explicit CommandLine(std::string command);
    ~CommandLine();

    /// @brief A flag without a value, e.g. --self; a value after it (`--self=1`) is refused.
    void flag(const std::string& name, bool& seen);
    /// @brief A flag followed by a value, e.g. --threads 4 (or --threads=4); the last one given wins.
    void option(const std::string& name, const std::string& value_name, std::function<void(const std::string&)> on_value);
    /// @brief Collects up to @p max_count positional arguments; one more is an error.
    void positionals(std::size_t max_count, std::vector<std::string>& out);
    /// @brief The table's options shown on @p front_end, each under its flag for that front end.
    void detector_options(DetectorOptions& options, FrontEnd front_end);

    /// @brief Parses `argv[first..argc)`; throws UsageError, also for a value the library refuses (kdet::Error).
    void parse(int argc, char** argv, int first);

private:
    std::string command_;
    std::unique_ptr<CLI::App> app_;
    std::size_t max_positionals_ = 0;
    std::vector<std::string>* positionals_ = nullptr;
};

/// @brief The flag under which @p option appears on @p front_end (bench: its thesis flag).
std::string flag_of(const OptionInfo& option, FrontEnd front_end);

/// @brief The grid hash @p options use, or "none" for the brute-force methods, which build no grid
/// (as the thesis's files wrote it).
std::string hash_label(const DetectorOptions& options);

/// @brief Throws a UsageError "COMMAND: invalid value 'N' for FLAG: ..." when @p scene was not built at
/// @p requested, the resolution its FLAG (-r, --res) gave: a scene without one, or one that fixes its own.
void check_resolution_flag(const std::string& command, const std::string& flag, int requested, const Scene& scene);

/// @brief Of a frame's pairs within the margin, those that overlap (distance 0); needs its distances.
std::uint64_t overlapping_pairs(const FrameResult& result);

/// @brief The summary's pair and tet lines: "colliding pairs" and "colliding tets", or with a margin
/// "pairs in margin" (with @p overlapping, when known, how many of them overlap) and "tets in a pair".
/// kdet_no_pairs builds no pairs: its line is left out.
void print_pair_counts(const DetectorOptions& options, std::uint64_t pairs, std::uint64_t tets,
                       const std::uint64_t* overlapping = nullptr);

} // namespace kdet::cli
