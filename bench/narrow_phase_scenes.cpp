/// How right each narrow-phase test is on real scenes, like the thesis's figure 6.8 but with the truth
/// known: for the thesis scenes (their frame with the most colliding pairs among every 8th frame; the
/// two objects against each other, and each one's self-collision) and the tetrahedral models (against
/// a moved copy, and self-collision), every test's pairs are judged by CGAL.
///
/// CGAL judges the pairs that sat_no_edges reports (a superset of the true pairs) and those each test
/// reports (kdet collide --check-exact). usage: narrow_phase_scenes [resolution]   (a markdown table)

#include "exact_check.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/prepare.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
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

std::size_t judged_by_cgal = 0; ///< pairs CGAL judged, summed over the cases

constexpr NarrowPhase k_tests[] = {NarrowPhase::exact, NarrowPhase::sat, NarrowPhase::sat_no_edges,
                                   NarrowPhase::sat_mtv, NarrowPhase::gjk, NarrowPhase::fast};

/// @brief One row for a against b, or for a's self-collision when b is null: the pairs CGAL judged, the
/// true pairs, and each test's false positives / false negatives (and the exact test's exact-stage pairs).
void report(const std::string& name, const TetMesh& a, const TetMesh* b) {
    std::string row;
    std::size_t checked = 0, truth = 0;
    std::uint64_t candidates = 0, exact_stage = 0;
    for (NarrowPhase test : k_tests) {
        DetectorOptions options;
        options.narrow_phase = test;
        Detector detector(options);
        detector.set_self_collision(detector.add_object(a), b == nullptr);
        if (b) detector.add_object(*b);
        const FrameResult& r = detector.detect();
        std::vector<IndexPair> reported;
        for (const TetPair& p : r.pairs) reported.emplace_back(p.tet_a, p.tet_b);
        const cli::ExactReport exact = cli::check_exact(a, b, reported, options);
        checked = std::max(checked, exact.pairs_checked);
        truth = exact.true_pairs;
        candidates = r.counts.narrow_phase_candidates;
        if (test == NarrowPhase::exact) exact_stage = r.counts.exact_stage_pairs;
        row += " | " + std::to_string(exact.false_positives.size()) + " / " + std::to_string(exact.false_negatives.size());
    }
    judged_by_cgal += checked;
    std::printf("| %s | %llu | %zu | %zu | %llu%s |\n", name.c_str(), static_cast<unsigned long long>(candidates), checked,
                truth, static_cast<unsigned long long>(exact_stage), row.c_str());
    std::fflush(stdout);
}

} // namespace

int main(int argc, char** argv) {
    const int resolution = argc > 1 ? std::atoi(argv[1]) : 1;
    std::printf("False positives / false negatives of each test against CGAL:\n\n| case | unique candidates | judged by "
                "CGAL | true pairs | exact stage |");
    for (NarrowPhase test : k_tests) std::printf(" %s |", to_string(test));
    std::printf("\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
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
        const std::string frame = " frame " + std::to_string(best_frame);
        const TetMesh a = posed(*scene, 0, best_frame), b = posed(*scene, 1, best_frame);
        report(std::string(name) + frame, a, &b);
        report(std::string(name) + frame + ", self A", a, nullptr);
        report(std::string(name) + frame + ", self B", b, nullptr);
    }
    for (const char* model : {"bunny.mesh", "hand.mesh", "octopus-low.mesh"}) {
        const TetMesh mesh = read_tet_mesh(data_path(model));
        const TetMesh copy = moved_copy(mesh);
        report(std::string(model) + " x moved copy", mesh, &copy);
        report(std::string(model) + " self", mesh, nullptr);
    }
    std::printf("\n%zu pairs judged by CGAL in all\n", judged_by_cgal);
}
