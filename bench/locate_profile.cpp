// Point location through the C++ API on the mesh of bench/locate_vs_libigl.py, for profiling:
//
//     OMP_NUM_THREADS=1 perf record -g build/bench/locate_profile 55 1000000 3
//
// A box of cubes^3 cubes split into six tets each, inner vertices moved at random by up to a fifth of a
// cube, and uniform points in the box grown by SPREAD on every side, located with `within` = WITHIN.
// Each run is one kdet::locate (detector, grid and queries); its wall and process CPU time (every
// thread's: on a shared machine the wall clock also counts the wait for a core) and hit count are
// printed, with a checksum of the answers to compare builds.
#include <kdet/locate.hpp>

#include <chrono>
#include <ctime>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

namespace {

kdet::TetMesh jittered_box(int cubes, std::mt19937_64& random) {
    std::uniform_real_distribution<double> jitter(-0.2, 0.2);
    kdet::TetMesh mesh;
    const int side = cubes + 1;
    const auto vertex = [&](int x, int y, int z) { return static_cast<std::uint32_t>((x * side + y) * side + z); };
    for (int x = 0; x <= cubes; ++x)
        for (int y = 0; y <= cubes; ++y)
            for (int z = 0; z <= cubes; ++z) {
                const int at[3] = {x, y, z};
                const bool inner = x > 0 && y > 0 && z > 0 && x < cubes && y < cubes && z < cubes;
                for (int a = 0; a < 3; ++a) mesh.positions.push_back((at[a] + (inner ? jitter(random) : 0.0)) / cubes);
            }
    // The six tets of a cube each walk from its low corner to its high one, one axis after the other.
    const int paths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int x = 0; x < cubes; ++x)
        for (int y = 0; y < cubes; ++y)
            for (int z = 0; z < cubes; ++z)
                for (const auto& path : paths) {
                    int c[3] = {x, y, z};
                    mesh.tets.push_back(vertex(c[0], c[1], c[2]));
                    for (const int axis : path) {
                        ++c[axis];
                        mesh.tets.push_back(vertex(c[0], c[1], c[2]));
                    }
                }
    return mesh;
}

double cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

} // namespace

int main(int argc, char** argv) {
    const int cubes = argc > 1 ? std::atoi(argv[1]) : 55;
    const long count = argc > 2 ? std::atol(argv[2]) : 1000000;
    const int runs = argc > 3 ? std::atoi(argv[3]) : 3;
    kdet::LocateOptions options;
    options.within = argc > 4 ? std::atof(argv[4]) : 0.0;
    const float spread = argc > 5 ? static_cast<float>(std::atof(argv[5])) : 0.0f;
    if (cubes < 1 || count < 1 || runs < 1 || !(options.within >= 0.0) || !(spread >= 0.0f)) {
        std::fprintf(stderr, "usage: locate_profile [CUBES [POINTS [RUNS [WITHIN [SPREAD]]]]] (counts at least 1, "
                             "distances not negative)\n");
        return 2;
    }
    std::mt19937_64 random(7);
    const kdet::TetMesh mesh = jittered_box(cubes, random);
    std::uniform_real_distribution<float> coordinate(-spread, 1.0f + spread);
    std::vector<float> points(3 * static_cast<std::size_t>(count));
    for (float& v : points) v = coordinate(random);
    const kdet::PositionsView view{points.data(), false, static_cast<std::size_t>(count), 3, 1};
    double best = 0.0, best_cpu = 0.0;
    for (int r = 0; r < runs; ++r) {
        const auto start = std::chrono::steady_clock::now();
        const double cpu_start = cpu_seconds();
        const kdet::LocateResult result = kdet::locate(mesh, view, options);
        const double cpu = cpu_seconds() - cpu_start;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (r == 0 || seconds < best) best = seconds;
        if (r == 0 || cpu < best_cpu) best_cpu = cpu;
        std::uint64_t checksum = 0;
        for (std::size_t h = 0; h < result.hit_count; ++h) checksum = checksum * 1000003u + result.tets[h];
        for (const std::uint64_t offset : result.offsets) checksum = checksum * 31u + offset;
        std::printf("run %d: %.3f s, cpu %.3f s, %zu hits, checksum %016llx\n", r, seconds, cpu, result.hit_count,
                    static_cast<unsigned long long>(checksum));
    }
    std::printf("%zu tets, %ld points: best %.3f s, cpu %.3f s\n", mesh.num_tets(), count, best, best_cpu);
    return 0;
}
