#pragma once
/// @file mpi_collide.hpp
/// @brief `kdet collide ... --mpi`: the same question answered by the ranks of mpirun (kdet::mpi).

#include <kdet/io.hpp>
#include <kdet/options.hpp>

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

} // namespace kdet::cli
