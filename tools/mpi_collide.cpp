/// @file mpi_collide.cpp
/// @brief `kdet collide ... --mpi`: rank 0 reads the meshes and splits them over the ranks, all ranks
/// run kdet::mpi::Detector, rank 0 writes the pairs and prints what each rank exchanged.

#include "mpi_commands.hpp"

#include "commands.hpp"

#include <kdet/error.hpp>

#ifdef KDET_HAS_MPI
#include <kdet/mpi.hpp>
#include <kdet/option_table.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#endif

namespace kdet::cli {

#ifndef KDET_HAS_MPI

namespace {
[[noreturn]] void without_mpi(const std::string& command) {
    throw Error(command + " --mpi: this kdet was built without MPI (install an MPI, e.g. Debian's libopenmpi-dev, "
                "and build again)");
}
} // namespace

int run_collide_mpi(const MpiCollide&) { without_mpi("collide"); }
int run_bench_mpi(const BenchConfig&) { without_mpi("bench"); }

#else

MpiSession::MpiSession() {
    int ready = 0;
    MPI_Initialized(&ready);
    if (!ready) MPI_Init(nullptr, nullptr);
    owned = !ready;
}
MpiSession::~MpiSession() {
    if (owned) MPI_Finalize();
}

mpi::Partition partition_of(const std::string& command, const std::string& name) {
    if (name.empty() || name == "slabs") return mpi::Partition::slabs;
    if (name == "random") return mpi::Partition::random;
    throw UsageError(command + ": invalid value '" + name + "' for --partition: expected slabs or random");
}

namespace {

int run(const MpiCollide& request, int rank, int size) {
    const mpi::Partition kind = partition_of("collide", request.partition);
    const MPI_Comm comm = MPI_COMM_WORLD;
    const std::size_t n_objects = request.self ? 1 : 2;
    std::vector<TetMesh> meshes(n_objects);
    std::vector<std::vector<int>> owners;
    std::string bad;
    if (rank == 0) {
        try {
            for (std::size_t o = 0; o < n_objects; ++o) meshes[o] = read_tet_mesh(request.meshes[o], request.read_options);
            std::vector<const TetMesh*> all;
            for (const TetMesh& m : meshes) all.push_back(&m);
            owners = mpi::partition_tets(all, size, kind);
        } catch (const Error& e) {
            bad = e.what();
        }
    }
    mpi::agree_on_error(comm, bad);
    mpi::Detector detector(comm, request.options);
    for (std::size_t o = 0; o < n_objects; ++o)
        detector.add_object(mpi::scatter_mesh(comm, &meshes[o], rank == 0 ? &owners[o] : nullptr));
    if (request.self) detector.set_self_collision(0, true);
    const mpi::FrameResult& result = detector.detect();

    // Sums and extremes over the ranks, for the one report rank 0 prints.
    std::uint64_t colliding = 0;
    for (const auto& flags : result.colliding) colliding += static_cast<std::uint64_t>(std::count(flags.begin(), flags.end(), 1));
    const mpi::ExchangeStats& x = result.exchange;
    unsigned long long sums[4] = {colliding, x.tets_sent, x.bytes_sent, x.owned_tets}, total[4];
    MPI_Reduce(sums, total, 4, MPI_UNSIGNED_LONG_LONG, MPI_SUM, 0, comm);
    double highs[4] = {static_cast<double>(x.local_tets), -static_cast<double>(x.local_tets), x.exchange_ms, x.total_ms}, high[4];
    MPI_Reduce(highs, high, 4, MPI_DOUBLE, MPI_MAX, 0, comm);
    const std::vector<TetPair> pairs = detector.gather_pairs(0);
    if (rank != 0) return exit_ok;

    if (!request.pairs_path.empty()) {
        std::ofstream out(request.pairs_path);
        if (!out) throw Error(request.pairs_path + ": cannot open file for writing");
        for (const TetPair& p : pairs) out << p.tet_a << ' ' << p.tet_b << '\n';
        out.flush();
        if (!out) throw Error(request.pairs_path + ": write failed");
    }
    std::printf("meshes            %s (%zu tets)", request.meshes[0].c_str(), meshes[0].num_tets());
    if (!request.self) std::printf(" x %s (%zu tets)", request.meshes[1].c_str(), meshes[1].num_tets());
    std::printf("%s\n", request.self ? ", self-collision" : "");
    const DetectorOptions& options = request.options;
    std::printf("method            %s, test %s, hash %s, backend %s\n", to_string(options.method),
                to_string(options.narrow_phase), hash_label(options).c_str(), to_string(options.backend));
    std::printf("ranks             %d, partition %s\n", size, kind == mpi::Partition::slabs ? "slabs" : "random");
    if (options.margin > 0.0f) std::printf("margin            %s\n", find_option("margin")->text(options).c_str());
    print_pair_counts(options, pairs.size(), total[0]);
    const double mean = static_cast<double>(total[3]) / size;
    std::printf("exchange          %llu tets sent (%.3f per tet), %llu bytes; tets per rank with those received: "
                "%.0f to %.0f (%.2f of the mean owned)\n",
                total[1], total[3] ? static_cast<double>(total[1]) / static_cast<double>(total[3]) : 0.0, total[2], -high[1],
                high[0], mean > 0 ? high[0] / mean : 0.0);
    std::printf("total             %.3f ms (slowest rank; exchange %.3f ms)\n", high[3], high[2]);
    return exit_ok;
}

} // namespace

int run_collide_mpi(const MpiCollide& request) {
    MpiSession session;
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    try {
        return run(request, rank, size);
    } catch (const Error& e) {
        // Every rank has the same message: rank 0 prints it here, before MPI is finalised, since once a
        // rank has exited with an error mpirun may stop the others before they print anything.
        if (rank == 0) print_error(e.what());
        return exit_failure;
    }
}

#endif

} // namespace kdet::cli
