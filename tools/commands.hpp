#pragma once
/// @file commands.hpp
/// @brief The subcommands of the kdet tool and what they share.

#include "cli_args.hpp"

#include <kdet/options.hpp>

#include <string>

namespace kdet::cli {

/// @brief Exit codes: 0 success, 1 bad input or failure, 2 command-line mistake.
enum ExitCode { exit_ok = 0, exit_failure = 1, exit_usage = 2 };

/// @brief Writes "kdet: error: MESSAGE" on stderr and flushes it: how every command reports a failure.
void print_error(const char* message);

int run_collide(int argc, char** argv);
int run_bench(int argc, char** argv);
int run_locate(int argc, char** argv);

/// @brief The help line of one option of the table as @p front_end shows it (flag, placeholder, text).
std::string option_help_line(const OptionInfo& option, FrontEnd front_end, const DetectorOptions& defaults);

/// @brief Help lines of the table's options shown on @p front_end, @p defaults' choices marked.
std::string detector_options_help(FrontEnd front_end, const DetectorOptions& defaults = {});

} // namespace kdet::cli
