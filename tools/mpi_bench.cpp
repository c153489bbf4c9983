/// @file mpi_bench.cpp
/// @brief `kdet bench ... --mpi`: a scene's frames on the ranks of mpirun, each rank holding its part,
/// with what the ranks exchanged per frame (docs/distributed.md).

#include "mpi_commands.hpp"

#include "commands.hpp"

#ifdef KDET_HAS_MPI
#include "bench_runner.hpp"

#include <kdet/error.hpp>
#include <kdet/mpi.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace kdet::cli {

namespace {

/// One frame as the ranks saw it: sums, and the extremes that show the load balance.
struct MpiFrameRow {
    int frame;
    unsigned long long pairs, tets_sent, bytes_sent, max_sent_by_one, owned_min, owned_max, local_min, local_max, rebuilt;
    double exchange_ms, local_ms, total_ms; // slowest rank's, the mean over the runs
};

const char* columns = "frame,ranks,pairs,tets sent,bytes sent,most tets sent by one rank,owned tets min,owned tets max,"
                      "local tets min,local tets max,ranks rebuilt,exchange ms,local ms,total ms";

} // namespace

int run_bench_mpi(const BenchConfig& config) {
    MpiSession session;
    const MPI_Comm comm = MPI_COMM_WORLD;
    int rank = 0, size = 1;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &size);
    try {
        const mpi::Partition kind = partition_of("bench", config.partition);
        std::unique_ptr<Scene> scene;
        std::string bad;
        try {
            scene = open_bench_scene(config); // every rank: the harness plays the simulation's part
        } catch (const std::exception& e) {
            bad = std::string(e.what());
        }
        if (bad.empty() && scene->changes_tets())
            bad = "bench: scene '" + scene->name() + "' changes its tets from frame to frame, which --mpi does not follow";
        mpi::agree_on_error(comm, bad);
        const int first = config.first_frame, last = last_frame_of(config, *scene);
        // Split as a simulation would split its mesh: at the first frame's positions.
        std::vector<TetMesh> at_first(scene->num_objects());
        std::vector<const TetMesh*> meshes;
        for (std::size_t o = 0; o < scene->num_objects(); ++o) {
            at_first[o].tets = scene->rest_mesh(o).tets;
            scene->positions(o, first, at_first[o].positions);
            meshes.push_back(&at_first[o]);
        }
        const std::vector<std::vector<int>> owners = mpi::partition_tets(meshes, size, kind);
        mpi::Detector detector(comm, config.options);
        std::vector<mpi::MeshPart> parts;
        for (std::size_t o = 0; o < scene->num_objects(); ++o) {
            parts.push_back(mpi::local_part(at_first[o], owners[o], rank));
            detector.add_object(parts[o]);
        }
        // kdet::mpi has switches alone: the scene's filters and static objects become switches with the
        // answers a Detector gives (no pair of two static objects, no static object's self-collision).
        for (std::size_t a = 0; a < scene->num_objects(); ++a) {
            detector.set_self_collision(static_cast<ObjectId>(a),
                                        self_collision_of(*scene, a, config.self) && !scene->is_static(a));
            const CollisionFilter fa = scene->collision_filter(a);
            for (std::size_t b = a + 1; b < scene->num_objects(); ++b) {
                const CollisionFilter fb = scene->collision_filter(b);
                const bool filtered = config.filters && !((fa.group & fb.mask) && (fb.group & fa.mask));
                const bool both_static = scene->is_static(a) && scene->is_static(b);
                detector.set_pair_collision(static_cast<ObjectId>(a), static_cast<ObjectId>(b),
                                            scene->checks_pair(a, b) && !filtered && !both_static);
            }
        }

        std::vector<MpiFrameRow> rows;
        std::vector<double> all, held;
        for (int run = 0; run < config.runs; ++run)
            for (int f = first; f <= last; ++f) {
                for (std::size_t o = 0; o < scene->num_objects(); ++o) {
                    scene->positions(o, f, all);
                    held.resize(parts[o].positions.size());
                    for (std::size_t k = 0; k < parts[o].vertex_ids.size(); ++k)
                        std::copy_n(&all[3 * std::size_t{parts[o].vertex_ids[k]}], 3, &held[3 * k]);
                    detector.set_positions(static_cast<ObjectId>(o), held.data(), held.size() / 3);
                }
                const mpi::FrameResult& r = detector.detect();
                const mpi::ExchangeStats& x = r.exchange;
                unsigned long long sums[5] = {r.pairs.size(), x.tets_sent, x.bytes_sent, x.rebuilt ? 1ull : 0ull, 0}, sum[5];
                MPI_Reduce(sums, sum, 5, MPI_UNSIGNED_LONG_LONG, MPI_SUM, 0, comm);
                // Maxima of values and of negated values give both extremes in one reduction.
                double highs[8] = {double(x.tets_sent), double(x.owned_tets), -double(x.owned_tets), double(x.local_tets),
                                   -double(x.local_tets), x.exchange_ms, x.local_ms, x.total_ms},
                       high[8];
                MPI_Reduce(highs, high, 8, MPI_DOUBLE, MPI_MAX, 0, comm);
                if (rank != 0) continue;
                const MpiFrameRow row{f, sum[0], sum[1], sum[2], (unsigned long long)high[0], (unsigned long long)-high[2],
                                   (unsigned long long)high[1], (unsigned long long)-high[4], (unsigned long long)high[3],
                                   sum[3], high[5], high[6], high[7]};
                if (run == 0) {
                    rows.push_back(row);
                } else {
                    MpiFrameRow& mean = rows[static_cast<std::size_t>(f - first)];
                    mean.exchange_ms += row.exchange_ms;
                    mean.local_ms += row.local_ms;
                    mean.total_ms += row.total_ms;
                }
            }
        if (rank != 0) return exit_ok;
        for (MpiFrameRow& row : rows) {
            row.exchange_ms /= config.runs;
            row.local_ms /= config.runs;
            row.total_ms /= config.runs;
        }
        std::filesystem::create_directories(config.output_dir);
        const std::string stem = stem_of(config, *scene, last) + "_mpi-np" + std::to_string(size) + "-" +
                                 (kind == mpi::Partition::slabs ? "slabs" : "random");
        const std::string path = config.output_dir + "/" + stem + ".csv";
        std::ofstream csv(path);
        if (!csv) throw Error(path + ": cannot open file for writing");
        csv << columns << "\n";
        std::size_t tets = 0;
        for (const TetMesh& m : at_first) tets += m.num_tets();
        std::printf("scene %s: %zu tets on %d ranks (%s), frames %d-%d, %d run(s), self %s, backend %s\n",
                    scene->name().c_str(), tets, size, kind == mpi::Partition::slabs ? "slabs" : "random", first, last,
                    config.runs, to_string(config.self), to_string(config.options.backend));
        if (!config.quiet)
            std::printf("%6s %10s %10s %12s %17s %17s %9s %9s\n", "frame", "pairs", "tets_sent", "bytes_sent",
                        "owned_min-max", "local_min-max", "exch_ms", "total_ms");
        double sent = 0, worst_balance = 0;
        for (const MpiFrameRow& r : rows) {
            csv << r.frame << ',' << size << ',' << r.pairs << ',' << r.tets_sent << ',' << r.bytes_sent << ','
                << r.max_sent_by_one << ',' << r.owned_min << ',' << r.owned_max << ',' << r.local_min << ',' << r.local_max
                << ',' << r.rebuilt << ',' << r.exchange_ms << ',' << r.local_ms << ',' << r.total_ms << '\n';
            if (!config.quiet)
                std::printf("%6d %10llu %10llu %12llu %8llu-%-8llu %8llu-%-8llu %9.3f %9.3f\n", r.frame, r.pairs, r.tets_sent,
                            r.bytes_sent, r.owned_min, r.owned_max, r.local_min, r.local_max, r.exchange_ms, r.total_ms);
            sent += static_cast<double>(r.tets_sent);
            worst_balance = std::max(worst_balance, static_cast<double>(r.local_max) * size / static_cast<double>(tets));
        }
        std::printf("summary: %.0f tets sent per frame on average (%.4f per tet); most local tets on one rank %.2f times "
                    "the mean share\nwrote %s\n",
                    sent / static_cast<double>(rows.size()), sent / static_cast<double>(rows.size()) / static_cast<double>(tets),
                    worst_balance, path.c_str());
        return exit_ok;
    } catch (const Error& e) {
        // Every rank has the same message: rank 0 prints it here, before MPI is finalised, since once a
        // rank has exited with an error mpirun may stop the others before they print anything.
        if (rank == 0) print_error(e.what());
        return exit_failure;
    }
}

} // namespace kdet::cli
#endif
