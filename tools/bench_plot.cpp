#include "bench_plot.hpp"

#include "commands.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#ifndef KDET_PYTHON_DIR
#define KDET_PYTHON_DIR "python"
#endif

namespace kdet::cli {

namespace {

namespace fs = std::filesystem;

/// The folders that may hold kdet_plot.py, relative to the running program: share/kdet/python of an
/// installed prefix, then the source tree's python/ as seen from the build folder.
std::vector<fs::path> script_folders() {
    std::error_code error;
    const fs::path program = fs::read_symlink("/proc/self/exe", error);
    const fs::path bin = error ? fs::current_path() : program.parent_path();
    return {bin / ".." / "share" / "kdet" / "python", bin / KDET_PYTHON_DIR};
}

} // namespace

int run_plot(int argc, char** argv) {
    std::string script;
    std::string looked;
    for (const fs::path& folder : script_folders()) {
        const fs::path candidate = folder / "kdet_plot.py";
        if (fs::exists(candidate)) {
            script = candidate.lexically_normal().string();
            break;
        }
        looked += (looked.empty() ? "" : ", ") + folder.lexically_normal().string();
    }
    if (script.empty()) {
        std::fprintf(stderr, "kdet plot: kdet_plot.py not found (looked in %s)\n", looked.c_str());
        return exit_failure;
    }
    std::vector<char*> args = {const_cast<char*>("python3"), script.data()};
    for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
    args.push_back(nullptr);
    execvp("python3", args.data());
    std::fprintf(stderr, "kdet plot: cannot run python3: %s\n", std::strerror(errno));
    return exit_failure;
}

} // namespace kdet::cli
