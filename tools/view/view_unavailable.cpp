/// @file view_unavailable.cpp
/// @brief `kdet view` in a build without the viewer's libraries.

#include "view_command.hpp"

#include <iostream>

namespace kdet::cli {

int run_view(int, char**) {
    std::cerr << "kdet view: this kdet was built without the viewer, which needs GLFW 3, Dear ImGui, libepoxy and "
                 "libpng; install them (scripts/install-deps.sh) and rebuild\n";
    return 1;
}

} // namespace kdet::cli
