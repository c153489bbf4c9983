#pragma once
/// @file bench_plot.hpp
/// @brief `kdet plot <folder>`: the figures of the thesis's chapter 6 from `kdet bench` CSV files.

namespace kdet::cli {

/// @brief Replaces the process with `python3 kdet_plot.py argv[2..]` (matplotlib does
/// the drawing), the script found beside the program (share/kdet/python of an install, or the source
/// tree's python/); returns only when neither exists or python3 cannot be started, with exit_failure.
int run_plot(int argc, char** argv);

} // namespace kdet::cli
