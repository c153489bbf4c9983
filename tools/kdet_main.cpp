#include "bench_plot.hpp"
#include "commands.hpp"
#include "prepare_command.hpp"
#include "view_command.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <new>

void kdet::cli::print_error(const char* message) { std::cerr << "kdet: error: " << message << std::endl; }

namespace {

/// True for a command given --mpi in a process that an MPI launcher started as a rank other than 0:
/// the usage errors and kdet::Errors that reach main() are the same on every rank (a bad flag, found
/// before MPI starts; the MPI commands print their agreed errors on rank 0 themselves), so only rank 0
/// prints them.
bool quiet_rank(int argc, char** argv) {
    bool mpi = false;
    for (int k = 2; k < argc; ++k) mpi = mpi || std::strcmp(argv[k], "--mpi") == 0;
    if (!mpi) return false;
    for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"}) {
        const char* value = std::getenv(name);
        if (value && *value) return std::strcmp(value, "0") != 0;
    }
    return false;
}

const char* usage = R"(usage: kdet <command> [arguments]

Finds every colliding pair of tetrahedra between tetrahedral meshes and inside one mesh.

commands:
  collide A [B] [options]   colliding pairs between two meshes, or inside one with --self
  locate MESH POINTS --out FILE [--within D]
                            the tets holding each point, with barycentric coordinates
  bench [scene] [options]   runs a scene frame by frame (default: the built-in procedural scene)
                            and writes the thesis's CSV files
  view [SCENE | A [B]]      shows a scene or meshes in a window, detecting collisions every frame;
                            --screenshot FILE draws one frame into a PNG without a window
  plot FOLDER               turns the CSV files of kdet bench into PNG figures (matplotlib)
  prepare [MODEL...] [-r N] builds the tet meshes of the thesis scenes (CGAL + TetGen) into the cache

  kdet <command> --help     options of a command
  kdet --version
)";

} // namespace

int main(int argc, char** argv) {
    using namespace kdet::cli;
    if (argc < 2) {
        std::cerr << usage;
        return exit_usage;
    }
    std::string command = argv[1];
    // `kdet help collide` as `kdet collide --help`.
    char help_flag[] = "--help";
    char* help_argv[] = {argv[0], argc > 2 ? argv[2] : nullptr, help_flag, nullptr};
    if (command == "help" && argc == 3) {
        argc = 3;
        argv = help_argv;
        command = argv[1];
    }
    try {
        if (command == "collide") return run_collide(argc, argv);
        if (command == "bench") return run_bench(argc, argv);
        if (command == "locate") return run_locate(argc, argv);
        if (command == "prepare") return run_prepare(argc, argv);
        if (command == "plot") return run_plot(argc, argv);
        if (command == "view") return run_view(argc, argv);
        if (command == "--help" || command == "-h" || command == "help") {
            std::cout << usage;
            return exit_ok;
        }
        if (command == "--version") {
            std::cout << "kdet " << kdet::version() << "\n";
            return exit_ok;
        }
        std::cerr << "kdet: unknown command '" << command << "' (commands: collide, locate, bench, view, plot, prepare; see 'kdet --help')\n";
        return exit_usage;
    } catch (const UsageError& e) {
        if (!quiet_rank(argc, argv)) std::cerr << "kdet " << e.what() << "\n";
        return exit_usage;
    } catch (const kdet::Error& e) {
        if (!quiet_rank(argc, argv)) print_error(e.what());
        return exit_failure;
    } catch (const std::bad_alloc&) {
        print_error("out of memory"); // one rank's own trouble: every rank says its own
        return exit_failure;
    } catch (const std::exception& e) {
        print_error(e.what());
        return exit_failure;
    }
}
