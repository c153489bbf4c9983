#pragma once
/// @file commands.hpp
/// @brief The subcommands of the kdet tool and what they share.

#include "cli_args.hpp"

#include <kdet/options.hpp>

#include <string>

namespace kdet::cli {

/// @brief Exit codes: 0 success, 1 bad input or failure, 2 command-line mistake.
enum ExitCode { exit_ok = 0, exit_failure = 1, exit_usage = 2 };

int run_collide(int argc, char** argv);
int run_bench(int argc, char** argv);

/// @brief Adds --method, --test, --hash, --threads, --backend, --block-size, --bucket-capacity to a parser.
void add_detector_options(ArgParser& parser, DetectorOptions& options);

/// @brief Help lines for the options of add_detector_options.
std::string detector_options_help();

/// @brief --bucket-capacity alone (part of add_detector_options), for `kdet bench`, whose other flags are the thesis's.
void add_bucket_capacity_option(ArgParser& parser, DetectorOptions& options);

/// @brief The help line of --bucket-capacity.
extern const char* const bucket_capacity_help;

} // namespace kdet::cli
