#pragma once
/// @file mpi_commands.hpp
/// @brief `kdet collide ... --mpi` and `kdet bench ... --mpi`: run by the ranks of mpirun (kdet::mpi).

#include "bench_args.hpp"

#include <kdet/io.hpp>
#ifdef KDET_HAS_MPI
#include <kdet/mpi.hpp>
#endif
#include <kdet/options.hpp>

#include <memory>
#include <string>
#include <vector>

namespace kdet::cli {

struct MpiCollide {
    std::vector<std::string> meshes;
    bool self = false;
    std::string pairs_path;
    std::string partition; ///< slabs (also when empty) or random
    ReadOptions read_options;
    DetectorOptions options;
};

/// @brief Rank 0 reads and splits the meshes, every rank detects, rank 0 writes and prints. Without
/// MPI support in this build: a kdet::Error saying so.
int run_collide_mpi(const MpiCollide& request);

/// @brief Every rank opens the scene and takes its part (split at the first frame), then runs the
/// frames with kdet::mpi::Detector; rank 0 prints and writes per frame what the ranks exchanged.
int run_bench_mpi(const BenchConfig& config);

/// @brief The scene `kdet bench` was asked for, with its flags checked (bench_command.cpp).
std::unique_ptr<Scene> open_bench_scene(const BenchConfig& config);

#ifdef KDET_HAS_MPI
/// @brief slabs (also for "") or random, else a UsageError naming @p command's --partition.
mpi::Partition partition_of(const std::string& command, const std::string& name);

/// @brief MPI for the length of a command (initialised here unless it already was); finalised also
/// when the command throws.
struct MpiSession {
    MpiSession();
    ~MpiSession();
    MpiSession(const MpiSession&) = delete;
    MpiSession& operator=(const MpiSession&) = delete;
    bool owned = false;
};
#endif

} // namespace kdet::cli
