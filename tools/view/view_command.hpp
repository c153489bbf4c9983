#pragma once
/// @file view_command.hpp
/// @brief `kdet view`: the interactive viewer, or a one-line message in a build without it.

namespace kdet::cli {

int run_view(int argc, char** argv);

} // namespace kdet::cli
