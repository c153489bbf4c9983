/// @file prepare_unavailable.cpp
/// @brief `kdet prepare` in a build without CGAL.

#include "prepare_command.hpp"

#include <kdet/prepare.hpp>

#include <iostream>

namespace kdet::cli {

int run_prepare(int, char**) {
    std::cerr << "kdet prepare: this kdet was built without CGAL, which the alpha wrapping needs; install "
                 "libcgal-dev (scripts/install-deps.sh) and rebuild (cache: "
              << cache_dir() << ")\n";
    return 1;
}

} // namespace kdet::cli
