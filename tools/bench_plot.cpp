#include "bench_plot.hpp"

#include "commands.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#ifndef KDET_PYTHON_DIR
#define KDET_PYTHON_DIR "python"
#endif

namespace kdet::cli {

int run_plot(int argc, char** argv) {
    std::string script = std::string(KDET_PYTHON_DIR) + "/kdet_plot.py";
    std::vector<char*> args = {const_cast<char*>("python3"), script.data()};
    for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
    args.push_back(nullptr);
    execvp("python3", args.data());
    std::fprintf(stderr, "kdet plot: cannot run python3: %s\n", std::strerror(errno));
    return exit_failure;
}

} // namespace kdet::cli
