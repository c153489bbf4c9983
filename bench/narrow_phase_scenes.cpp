/// How right each narrow-phase test is on real scenes, like the thesis's figure 6.8 but with the truth
/// known: for the thesis scenes (their frame with the most colliding pairs among every 8th frame) and
/// the tetrahedral models against a moved copy, every test's pairs are judged by CGAL.
///
/// usage: narrow_phase_scenes [resolution]      (prints a markdown table)

#include "exact_check.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/prepare.hpp>
#include <kdet/scenes.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using namespace kdet;

TetMesh posed(const Scene& scene, std::size_t object, int frame) {
    TetMesh mesh;
    mesh.tets = scene.rest_mesh(object).tets;
    std::vector<float> xyz;
    scene.positions(object, frame, xyz);
    mesh.positions.assign(xyz.begin(), xyz.end());
    return mesh;
}

TetMesh moved_copy(const TetMesh& mesh) {
    double lo = 1e300, hi = -1e300;
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
        lo = std::min(lo, mesh.positions[3 * v]);
        hi = std::max(hi, mesh.positions[3 * v]);
    }
    TetMesh out = mesh;
    const double angle = 0.3, shift = 0.1 * (hi - lo);
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
        const double x = mesh.positions[3 * v], y = mesh.positions[3 * v + 1];
        out.positions[3 * v] = std::cos(angle) * x - std::sin(angle) * y + shift;
        out.positions[3 * v + 1] = std::sin(angle) * x + std::cos(angle) * y;
    }
    return out;
}

void report(const std::string& name, const TetMesh& a, const TetMesh& b) {
    for (NarrowPhase test : {NarrowPhase::sat, NarrowPhase::sat_no_edges, NarrowPhase::sat_mtv, NarrowPhase::gjk,
                             NarrowPhase::fast}) {
        DetectorOptions options;
        options.narrow_phase = test;
        options.threads = 1;
        Detector detector(options);
        detector.add_object(a);
        detector.add_object(b);
        detector.detect(); // warm buffers
        const FrameResult& r = detector.detect();
        std::vector<IndexPair> reported;
        for (const TetPair& p : r.pairs) reported.emplace_back(p.tet_a, p.tet_b);
        const cli::ExactReport exact = cli::check_exact(a, &b, reported, options);
        std::printf("| %s | %zu | %s | %llu | %zu | %zu | %zu | %.1f |\n", name.c_str(), exact.true_pairs,
                    to_string(test), static_cast<unsigned long long>(r.counts.unique_candidates), reported.size(),
                    exact.false_positives.size(), exact.false_negatives.size(),
                    1e6 * r.times.narrow_phase / static_cast<double>(std::max<std::uint64_t>(1, r.counts.unique_candidates)));
    }
}

} // namespace

int main(int argc, char** argv) {
    const int resolution = argc > 1 ? std::atoi(argv[1]) : 1;
    std::printf("| case | true pairs | test | unique candidates | reported | false positives | false negatives | "
                "narrow phase ns per candidate |\n|---|---:|---|---:|---:|---:|---:|---:|\n");
    for (const char* name : {"armadillos", "buddha_and_armadillo", "bunny_and_planck", "pass_through_armadillos"}) {
        SceneRequest request;
        request.resolution = resolution;
        std::unique_ptr<Scene> scene;
        try {
            scene = open_scene(name, request);
        } catch (const Error& e) {
            std::printf("| %s | skipped: %s |\n", name, e.what());
            continue;
        }
        int best_frame = 0;
        std::uint64_t best_pairs = 0;
        for (int f = 0; f < scene->num_frames(); f += 8) {
            const auto pairs = collide(posed(*scene, 0, f), posed(*scene, 1, f)).size();
            if (pairs > best_pairs) best_pairs = pairs, best_frame = f;
        }
        report(std::string(name) + " frame " + std::to_string(best_frame), posed(*scene, 0, best_frame),
               posed(*scene, 1, best_frame));
    }
    for (const char* model : {"bunny.mesh", "hand.mesh", "octopus-low.mesh"}) {
        const TetMesh mesh = read_tet_mesh(data_path(model));
        report(std::string(model) + " x moved copy", mesh, moved_copy(mesh));
    }
}
