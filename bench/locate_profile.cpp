// Point location through the C++ API on the mesh of bench/locate_vs_libigl.py, for profiling and
// for the backends side by side:
//
//     OMP_NUM_THREADS=1 perf record -g build/bench/locate_profile 55 1000000 3
//     build/bench/locate_profile 55 1000000 10 0 0 --backend both
//
// A box of cubes^3 cubes split into six tets each, inner vertices moved at random by up to a fifth of a
// cube, and uniform points in the box grown by SPREAD on every side, located with `within` = WITHIN;
// with --apart D, a second copy of the mesh D along x holds every second point (a sparse region: the
// points' grid is hashed).
// Without --backend, each run is one kdet::locate on the CPU (detector, grid and queries); its wall and
// process CPU time (every thread's: on a shared machine the wall clock also counts the wait for a core)
// and hit count are printed, with a checksum of the answers to compare builds. With --backend, each
// backend's Detector holds the mesh and runs Detector::locate on the same points RUNS times with the
// results copied to the host, then RUNS times with them kept in the backend's memory (what a
// simulator that reads them there pays); the first call of each, which grows the buffers, is
// reported apart. With `both`, the CPU's and the GPU's answers must be identical.
#include <kdet/detector.hpp>
#include <kdet/locate.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
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

std::uint64_t checksum(const kdet::LocateResult& result) {
    std::uint64_t sum = 0;
    for (std::size_t h = 0; h < result.hit_count; ++h) sum = sum * 1000003u + result.tets[h];
    for (const std::uint64_t offset : result.offsets) sum = sum * 31u + offset;
    return sum;
}

struct Timings {
    double first = 0.0, best = 0.0, median = 0.0;
};

/// The first call's time, then the best and median of the next `runs`.
template <class Call>
Timings time_calls(int runs, Call&& call) {
    Timings t;
    std::vector<double> seconds;
    for (int r = 0; r <= runs; ++r) {
        const auto start = std::chrono::steady_clock::now();
        call();
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (r == 0) t.first = s;
        else seconds.push_back(s);
    }
    std::sort(seconds.begin(), seconds.end());
    t.best = seconds.front();
    t.median = seconds[seconds.size() / 2];
    return t;
}

bool same_answers(const kdet::LocateResult& a, const kdet::LocateResult& b) {
    return a.offsets == b.offsets && a.objects == b.objects && a.tets == b.tets && a.barycentrics == b.barycentrics &&
           a.closest_points == b.closest_points && a.distances == b.distances;
}

[[noreturn]] void usage(const char* problem) {
    std::fprintf(stderr,
                 "locate_profile: %s\nusage: locate_profile [CUBES [POINTS [RUNS [WITHIN [SPREAD]]]]] [--backend cpu|cuda|both] "
                 "[--threads N] [--apart D] (counts at least 1, distances not negative)\n",
                 problem);
    std::exit(2);
}

double number(const char* text, const char* what) {
    char* end = nullptr;
    const double value = std::strtod(text, &end);
    if (end == text || *end != '\0' || !std::isfinite(value)) usage((std::string(what) + " '" + text + "' is not a number").c_str());
    return value;
}

} // namespace

int main(int argc, char** argv) {
    std::vector<const char*> positional;
    std::vector<kdet::Backend> backends;
    int threads = 0;
    double apart = 0.0;
    for (int a = 1; a < argc; ++a) {
        const std::string arg = argv[a];
        if (arg == "--backend" || arg == "--threads" || arg == "--apart") {
            if (a + 1 >= argc) usage((arg + " needs a value").c_str());
            const std::string value = argv[++a];
            if (arg == "--apart") {
                apart = number(value.c_str(), "--apart");
                if (apart < 0) usage("--apart must not be negative");
            } else if (arg == "--threads") {
                const double n = number(value.c_str(), "--threads");
                if (n < 1 || n != static_cast<int>(n)) usage("--threads must be a whole number, at least 1");
                threads = static_cast<int>(n);
            } else if (value == "both") {
                backends = {kdet::Backend::cpu, kdet::Backend::cuda};
            } else {
                kdet::Backend b{};
                if (!kdet::parse(value, b)) usage(("--backend '" + value + "' is not cpu, cuda or both").c_str());
                backends = {b};
            }
        } else if (arg.rfind("--", 0) == 0) {
            usage(("unknown flag " + arg).c_str());
        } else {
            positional.push_back(argv[a]);
        }
    }
    if (positional.size() > 5) usage("at most five numbers");
    const auto at = [&](std::size_t i, double fallback, const char* what) {
        return positional.size() > i ? number(positional[i], what) : fallback;
    };
    const double cubes = at(0, 55, "CUBES"), count = at(1, 1000000, "POINTS"), runs = at(2, 3, "RUNS");
    kdet::LocateOptions options;
    options.within = at(3, 0.0, "WITHIN");
    const double spread = at(4, 0.0, "SPREAD");
    if (cubes < 1 || count < 1 || runs < 1 || cubes != static_cast<int>(cubes) || count != static_cast<long>(count) ||
        runs != static_cast<int>(runs) || options.within < 0.0 || spread < 0.0)
        usage("counts must be whole numbers of at least 1 and distances not negative");
    std::mt19937_64 random(7);
    kdet::TetMesh mesh = jittered_box(static_cast<int>(cubes), random);
    if (apart > 0.0) {
        // A second copy `apart` along x, with every second point: a region of many empty cells.
        const auto vertices = static_cast<std::uint32_t>(mesh.num_vertices());
        const std::size_t coordinates = mesh.positions.size(), corners = mesh.tets.size();
        for (std::size_t i = 0; i < coordinates; ++i) mesh.positions.push_back(mesh.positions[i] + (i % 3 == 0 ? apart : 0.0));
        for (std::size_t i = 0; i < corners; ++i) mesh.tets.push_back(mesh.tets[i] + vertices);
    }
    std::uniform_real_distribution<float> coordinate(-static_cast<float>(spread), 1.0f + static_cast<float>(spread));
    const auto points_count = static_cast<std::size_t>(count);
    std::vector<float> points(3 * points_count);
    for (float& v : points) v = coordinate(random);
    for (std::size_t i = 3; apart > 0.0 && i < points.size(); i += 6) points[i] += static_cast<float>(apart);
    const kdet::PositionsView view{points.data(), false, points_count, 3, 1};
    kdet::DetectorOptions detector_options;
    detector_options.threads = threads;

    if (backends.empty()) {
        double best = 0.0, best_cpu = 0.0;
        for (int r = 0; r < static_cast<int>(runs); ++r) {
            const auto start = std::chrono::steady_clock::now();
            const double cpu_start = cpu_seconds();
            const kdet::LocateResult result = kdet::locate(mesh, view, options, detector_options);
            const double cpu = cpu_seconds() - cpu_start;
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            if (r == 0 || seconds < best) best = seconds;
            if (r == 0 || cpu < best_cpu) best_cpu = cpu;
            std::printf("run %d: %.3f s, cpu %.3f s, %zu hits, checksum %016llx\n", r, seconds, cpu, result.hit_count,
                        static_cast<unsigned long long>(checksum(result)));
        }
        std::printf("%zu tets, %zu points: best %.3f s, cpu %.3f s\n", mesh.num_tets(), points_count, best, best_cpu);
        return 0;
    }

    std::printf("%zu tets, %zu points, within %g, spread %g\n", mesh.num_tets(), points_count, options.within, spread);
    std::vector<kdet::LocateResult> answers;
    for (const kdet::Backend backend : backends) {
        std::string reason;
        if (backend == kdet::Backend::cuda && !kdet::cuda_available(&reason)) {
            std::fprintf(stderr, "locate_profile: the cuda backend is not available: %s\n", reason.c_str());
            return 1;
        }
        detector_options.backend = backend;
        kdet::Detector detector(detector_options);
        detector.add_object(mesh);
        kdet::LocateOptions to_host = options, on_device = options;
        on_device.results_to_host = false;
        const Timings host = time_calls(static_cast<int>(runs), [&] { detector.locate(view, kdet::all_objects, to_host); });
        answers.push_back(detector.locate(view, kdet::all_objects, to_host));
        const Timings device = time_calls(static_cast<int>(runs), [&] { detector.locate(view, kdet::all_objects, on_device); });
        const kdet::LocateResult& last = answers.back();
        std::printf("%s: results to the host: first %.4f s, best %.4f s, median %.4f s; kept in its memory: first %.4f s, "
                    "best %.4f s, median %.4f s; %zu hits, checksum %016llx\n",
                    kdet::to_string(backend), host.first, host.best, host.median, device.first, device.best, device.median,
                    last.hit_count, static_cast<unsigned long long>(checksum(last)));
    }
    if (answers.size() == 2) {
        const bool same = same_answers(answers[0], answers[1]);
        std::printf("same answers on cpu and cuda: %s\n", same ? "yes" : "no");
        if (!same) return 1;
    }
    return 0;
}
