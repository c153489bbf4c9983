// The consumer's distributed run (tests/consumer/run.sh, under mpirun): rank 0 reads the meshes the
// consumer wrote, splits them into slabs over the ranks, and writes the pairs all ranks found.
#include <kdet/kdet.hpp>
#include <kdet/mpi.hpp>

#include <cstdio>
#include <fstream>
#include <string>

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    int rank = 0, size = 1, status = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    try {
        if (argc != 2) throw kdet::Error("usage: consumer_mpi OUT_DIR  (reads a.mesh, b.mesh, writes pairs_mpi.txt)");
        const std::string out = argv[1];
        kdet::TetMesh a, b;
        std::vector<std::vector<int>> owners;
        if (rank == 0) {
            a = kdet::read_tet_mesh(out + "/a.mesh");
            b = kdet::read_tet_mesh(out + "/b.mesh");
            owners = kdet::mpi::partition_tets({&a, &b}, size, kdet::mpi::Partition::slabs);
        }
        kdet::mpi::Detector detector(MPI_COMM_WORLD);
        detector.add_object(kdet::mpi::scatter_mesh(MPI_COMM_WORLD, &a, rank == 0 ? &owners[0] : nullptr));
        detector.add_object(kdet::mpi::scatter_mesh(MPI_COMM_WORLD, &b, rank == 0 ? &owners[1] : nullptr));
        detector.detect();
        const std::vector<kdet::TetPair> pairs = detector.gather_pairs(0);
        if (rank == 0) {
            std::ofstream file(out + "/pairs_mpi.txt");
            for (const kdet::TetPair& p : pairs) file << p.tet_a << ' ' << p.tet_b << '\n';
            std::printf("kdet::mpi on %d ranks: %zu pairs\n", size, pairs.size());
            status = file ? 0 : 1;
        }
    } catch (const kdet::Error& error) {
        std::fprintf(stderr, "consumer_mpi: %s\n", error.what());
        status = 1;
    }
    MPI_Finalize();
    return status;
}
