/// A frame's cost with static objects (Detector::set_static): one moving body of about 20k tets (a
/// torus lying flat, half sunk into a floor, turning as it slides along it) on a static floor of about
/// 1M tets, against the same body on a static floor patch of about 20k tets that holds its whole path
/// (the same tets where the body goes, so the same pairs); and, for reference, the 1M-tet floor left
/// moving (no set_static), which every frame boxes, sizes and grids where the body is.
/// Prints per case the median and mean detect() time over the frames after the first (which places
/// the static floor), the first frame's time, and the pairs.
///
/// usage: static_environment [frames=24] [cpu|cuda] [floor cells per side=204] [body tets=20000]

#include <kdet/detector.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using namespace kdet;

struct Outcome {
    double first_ms = 0, median_ms = 0, mean_ms = 0;
    std::size_t pairs = 0; ///< summed over the frames after the first
};

/// The body's positions at `frame` of `frames`: turned about z by a degree a frame, its centre moved
/// along x across [x0, x1] at y = y0 and height z0.
void body_at(const TetMesh& body, int frame, int frames, double x0, double x1, double y0, double z0, std::vector<float>& out) {
    const double angle = 0.0175 * frame, x = x0 + (x1 - x0) * frame / std::max(1, frames - 1);
    out.resize(3 * body.num_vertices());
    for (std::size_t v = 0; v < body.num_vertices(); ++v) {
        const double px = body.positions[3 * v], py = body.positions[3 * v + 1], pz = body.positions[3 * v + 2];
        out[3 * v] = static_cast<float>(x + std::cos(angle) * px - std::sin(angle) * py);
        out[3 * v + 1] = static_cast<float>(y0 + std::sin(angle) * px + std::cos(angle) * py);
        out[3 * v + 2] = static_cast<float>(z0 + pz);
    }
}

/// Where the body's centre goes: along x from x0 to x1, at y0 and height z0.
struct Path {
    double x0, x1, y0, z0;
};

Outcome run(const TetMesh& block, bool block_static, const TetMesh& body, const Path& path, int frames, Backend backend) {
    DetectorOptions options;
    options.backend = backend;
    Detector detector(options);
    const ObjectId b = detector.add_object(block);
    detector.set_static(b, block_static);
    const ObjectId m = detector.add_object(body);
    std::vector<float> xyz;
    std::vector<double> times;
    Outcome out;
    for (int f = 0; f < frames; ++f) {
        body_at(body, f, frames, path.x0, path.x1, path.y0, path.z0, xyz);
        const auto start = std::chrono::steady_clock::now();
        detector.set_positions(m, xyz.data(), body.num_vertices());
        const FrameResult& r = detector.detect();
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (f == 0) {
            out.first_ms = ms;
            continue;
        }
        times.push_back(ms);
        out.pairs += r.pairs.size();
    }
    std::vector<double> sorted = times;
    std::sort(sorted.begin(), sorted.end());
    out.median_ms = sorted.empty() ? 0 : sorted[sorted.size() / 2];
    for (double t : times) out.mean_ms += t / static_cast<double>(times.size());
    return out;
}

} // namespace

int main(int argc, char** argv) {
    const int frames = argc > 1 ? std::atoi(argv[1]) : 24;
    const Backend backend = argc > 2 && std::string(argv[2]) == "cuda" ? Backend::cuda : Backend::cpu;
    const int cells = argc > 3 ? std::atoi(argv[3]) : 204;
    const std::size_t body_tets = argc > 4 ? static_cast<std::size_t>(std::atoll(argv[4])) : 20000;
    if (frames < 2 || cells < 30) {
        std::fprintf(stderr, "usage: static_environment [frames>=2] [cpu|cuda] [cells>=30] [body tets]\n");
        return 2;
    }
    // Floors 4 cells thick of cubes of side 1 (6 tets each): the large one `cells` per side, the patch
    // as many tets as the body.
    const int thickness = 4, patch = std::max(
        12, static_cast<int>(std::lround(std::sqrt(static_cast<double>(body_tets) / (6.0 * thickness)))));
    const TetMesh environment = make_box_mesh(cells, cells, thickness, 1.0);
    const TetMesh piece = make_box_mesh(patch, patch, thickness, 1.0);
    // A torus lying flat, its outer radius (3.5 times the tube's) a fifth of the patch, sliding across
    // the patch's middle.
    const double minor = patch / 5.0 / 3.5;
    const TetMesh body = make_torus_mesh(2.5 * minor, minor, body_tets);
    const double reach = 3.5 * minor;
    const Path path{reach + 1.0, patch - reach - 1.0, 0.5 * patch, thickness + 0.3 * minor};
    std::printf("| case | static tets | moving tets | first frame ms | median ms | mean ms | pairs per frame |\n");
    std::printf("| --- | --- | --- | --- | --- | --- | --- |\n");
    const auto print = [&](const char* name, const TetMesh& block, bool is_static) {
        const Outcome o = run(block, is_static, body, path, frames, backend);
        std::printf("| %s | %zu | %zu | %.2f | %.2f | %.2f | %.0f |\n", name, is_static ? block.num_tets() : 0,
                    body.num_tets() + (is_static ? 0 : block.num_tets()), o.first_ms, o.median_ms, o.mean_ms,
                    static_cast<double>(o.pairs) / (frames - 1));
        std::fflush(stdout);
        return o;
    };
    const Outcome big = print("body on the large static floor", environment, true);
    const Outcome small = print("body on the small static floor", piece, true);
    print("body on the large floor, not static", environment, false);
    std::printf("\nmedian frame, large static floor / small static floor: %.2f\n", big.median_ms / small.median_ms);
    return 0;
}
