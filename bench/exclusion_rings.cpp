/// What self-exclusion rings cost (Detector::set_self_exclusion_rings): on a crumpled box (a box of
/// n x n x n cubes in six tets each, its vertices moved at random by up to 0.45 cells), per ring count
/// the time set_self_exclusion_rings takes, the bytes the detector holds for the lists afterwards
/// (memory_bytes() against a detector without rings), and the self pairs and candidates of a frame.
/// The results are in docs/filters-and-topology.md.
///
/// usage: exclusion_rings [cells per side=12] [threads=1] [cpu|cuda]

#include <kdet/detector.hpp>
#include <kdet/scenes.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

int main(int argc, char** argv) {
    using namespace kdet;
    const int cells = argc > 1 ? std::atoi(argv[1]) : 12;
    DetectorOptions options;
    options.threads = argc > 2 ? std::atoi(argv[2]) : 1;
    options.backend = argc > 3 && std::string(argv[3]) == "cuda" ? Backend::cuda : Backend::cpu;
    TetMesh mesh = make_box_mesh(cells, cells, cells, 1.0);
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> unit(-0.45, 0.45);
    for (double& x : mesh.positions) x += unit(rng);
    std::printf("%zu tets, %d thread(s)\n", mesh.num_tets(), options.threads);
    std::printf("rings  ids_bytes_per_tet  build_s  self_pairs  candidates\n");
    std::size_t plain_bytes = 0;
    for (int rings = 0; rings <= max_exclusion_rings; ++rings) {
        Detector detector(options);
        detector.set_self_collision(detector.add_object(mesh), true);
        const auto start = std::chrono::steady_clock::now();
        detector.set_self_exclusion_rings(0, rings);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const FrameResult& r = detector.detect();
        const std::size_t bytes = detector.memory_bytes();
        if (rings == 0) plain_bytes = bytes;
        std::printf("%5d  %17.1f  %7.3f  %10zu  %10llu\n", rings,
                    static_cast<double>(bytes - plain_bytes) / static_cast<double>(mesh.num_tets()), seconds, r.pairs.size(),
                    static_cast<unsigned long long>(r.counts.candidates));
    }
}
