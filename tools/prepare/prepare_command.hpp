#pragma once
/// @file prepare_command.hpp
/// @brief `kdet prepare`: builds the tet meshes of the thesis scenes into the cache.

namespace kdet::cli {

/// @brief Runs `kdet prepare` (argv[1] is "prepare"); returns the exit code. Built without CGAL, it
/// says so and fails.
int run_prepare(int argc, char** argv);

} // namespace kdet::cli
