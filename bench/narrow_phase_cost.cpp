/// Cost of the `exact` narrow-phase test against `sat` on the thesis scenes, side by side in one run
/// (docs/narrow-phase.md):
///  1. per pair: the candidate pairs of every `pair_step`-th frame (the pairs the narrow phase sees:
///     tets whose boxes overlap, adjacent tets of one object excluded; checked against the detector's
///     count of candidates found, before the face-plane pre-test), timed in a tight loop with each
///     test in turn, thread CPU time, several rounds with the order alternating;
///  2. per frame: two detectors, one per test, on the same frames in turn (half as many rounds); the
///     mean detect() time.
/// Self-collision off and on, as in the thesis matrix (pass_through_armadillos without).
///
/// usage: narrow_phase_cost [resolution=2] [pair frame step=8] [rounds=7] [threads=1] [frame step=4]
///                          [--pairs-only]

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "geometry/tet_intersect.hpp"

namespace {

using namespace kdet;

double thread_ns() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return 1e9 * static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec);
}

struct PairPoints {
    vec3 a[4], b[4];
};

struct Tet {
    Aabb box;
    std::uint32_t object, index;
};

/// @brief Every pair of tets of the frame whose boxes overlap, between the two objects and, with self,
/// inside each object without a shared vertex: what the kdet method hands to the narrow phase.
std::vector<PairPoints> candidate_pairs(const Scene& scene, int frame, bool self) {
    std::vector<std::vector<float>> xyz(scene.num_objects());
    std::vector<Tet> tets;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        scene.positions(o, frame, xyz[o]);
        const TetMesh& mesh = scene.rest_mesh(o);
        for (std::uint32_t t = 0; t < mesh.num_tets(); ++t) {
            vec3 v[4];
            for (int k = 0; k < 4; ++k) {
                const float* p = &xyz[o][3 * std::size_t{mesh.tets[4 * std::size_t{t} + k]}];
                v[k] = vec3{p[0], p[1], p[2]};
            }
            tets.push_back(Tet{tet_box(v), static_cast<std::uint32_t>(o), t});
        }
    }
    std::sort(tets.begin(), tets.end(), [](const Tet& x, const Tet& y) { return x.box.lo.x < y.box.lo.x; });
    const auto load = [&](const Tet& t, vec3 out[4]) {
        const TetMesh& mesh = scene.rest_mesh(t.object);
        for (int k = 0; k < 4; ++k) {
            const float* p = &xyz[t.object][3 * std::size_t{mesh.tets[4 * std::size_t{t.index} + k]}];
            out[k] = vec3{p[0], p[1], p[2]};
        }
    };
    const auto adjacent = [&](const Tet& x, const Tet& y) {
        const TetMesh& mesh = scene.rest_mesh(x.object);
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j)
                if (mesh.tets[4 * std::size_t{x.index} + i] == mesh.tets[4 * std::size_t{y.index} + j]) return true;
        return false;
    };
    std::vector<PairPoints> pairs;
    for (std::size_t i = 0; i < tets.size(); ++i)
        for (std::size_t j = i + 1; j < tets.size() && tets[j].box.lo.x <= tets[i].box.hi.x; ++j) {
            const Tet *x = &tets[i], *y = &tets[j];
            if (!boxes_overlap(x->box, y->box)) continue;
            if (x->object == y->object ? (!self || adjacent(*x, *y)) : !scene.checks_pair(x->object, y->object)) continue;
            if (x->object > y->object || (x->object == y->object && x->index > y->index)) std::swap(x, y);
            PairPoints p;
            load(*x, p.a);
            load(*y, p.b);
            pairs.push_back(p);
        }
    return pairs;
}

Detector make_detector(const Scene& scene, bool self, DetectorOptions options) {
    Detector detector(options);
    add_scene_objects(detector, scene, self);
    return detector;
}

void set_frame(const Scene& scene, int frame, Detector& detector) {
    std::vector<float> xyz;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        scene.positions(o, frame, xyz);
        detector.set_positions(static_cast<ObjectId>(o), xyz.data(), xyz.size() / 3);
    }
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

/// Out of line so that callgrind attributes each test's loop to its own function.
template <class Test>
[[gnu::noinline]] double ns_per_pair(Test test, const std::vector<PairPoints>& pairs, long long& hits) {
    const double start = thread_ns();
    long long found = 0;
    for (const PairPoints& p : pairs) found += test(p.a, p.b);
    const double elapsed = thread_ns() - start;
    hits = found;
    return elapsed / static_cast<double>(pairs.size());
}

/// @brief Part 1 for one scene and self setting; prints one table row. Out of line so that callgrind
/// can dump its counts once per case (--dump-after='*per_pair*').
[[gnu::noinline]] void per_pair(const std::string& name, const Scene& scene, bool self, int step, int rounds) {
    constexpr std::size_t k_max_pairs = 1500000; // 144 MB of points; later frames are thinned to fit
    std::vector<PairPoints> pairs;
    DetectorOptions sat_options;
    sat_options.threads = 1;
    Detector detector = make_detector(scene, self, sat_options);
    std::size_t frames = 0, candidates = 0;
    for (int f = 0; f < scene.num_frames(); f += step) {
        std::vector<PairPoints> frame_pairs = candidate_pairs(scene, f, self);
        set_frame(scene, f, detector);
        const std::uint64_t found = detector.detect().counts.candidates;
        if (found != frame_pairs.size()) {
            std::printf("frame %d: %zu box-overlap pairs but %llu candidates found\n", f, frame_pairs.size(),
                        static_cast<unsigned long long>(found));
            std::exit(1);
        }
        ++frames;
        candidates += frame_pairs.size();
        const std::size_t stride = std::max<std::size_t>(
            1, frame_pairs.size() * static_cast<std::size_t>((scene.num_frames() + step - 1) / step) / k_max_pairs);
        for (std::size_t k = 0; k < frame_pairs.size(); k += stride) pairs.push_back(frame_pairs[k]);
    }
    long long exact_stage = 0, sat_hits = 0, exact_hits = 0;
    for (const PairPoints& p : pairs) {
        bool stage = false;
        tets_intersect_exact(p.a, p.b, stage);
        exact_stage += stage;
    }
    const auto sat_test = [](const vec3 a[4], const vec3 b[4]) { return tets_intersect_sat(a, b); };
    const auto exact = [](const vec3 a[4], const vec3 b[4]) { return tets_intersect_exact(a, b); };
    std::vector<double> sat_ns, exact_ns;
    for (int r = 0; r < rounds; ++r) {
        if (r % 2 == 0) {
            sat_ns.push_back(ns_per_pair(sat_test, pairs, sat_hits));
            exact_ns.push_back(ns_per_pair(exact, pairs, exact_hits));
        } else {
            exact_ns.push_back(ns_per_pair(exact, pairs, exact_hits));
            sat_ns.push_back(ns_per_pair(sat_test, pairs, sat_hits));
        }
    }
    const double sat = median(sat_ns), ex = median(exact_ns);
    std::printf("| %s | %s | %zu | %zu | %zu | %lld | %lld | %lld | %.1f | %.1f | %.3f | %.3f |\n", name.c_str(),
                self ? "yes" : "no", frames, candidates, pairs.size(), sat_hits, exact_hits, exact_stage, sat, ex,
                ex / sat, *std::min_element(exact_ns.begin(), exact_ns.end()) / *std::min_element(sat_ns.begin(), sat_ns.end()));
    std::fflush(stdout);
}

/// @brief Part 2 for one scene, self setting and method; prints one table row.
void per_frame(const std::string& name, const Scene& scene, bool self, Method method, int step, int rounds, int threads) {
    DetectorOptions options;
    options.method = method;
    options.threads = threads;
    options.narrow_phase = NarrowPhase::sat;
    Detector sat = make_detector(scene, self, options);
    options.narrow_phase = NarrowPhase::exact;
    Detector exact = make_detector(scene, self, options);
    double sat_ms = 0, exact_ms = 0, sat_narrow = 0, exact_narrow = 0;
    std::uint64_t exact_stage = 0, frames = 0, sat_pairs = 0, exact_pairs = 0;
    for (int f = 0; f < scene.num_frames(); f += step) {
        set_frame(scene, f, sat);
        set_frame(scene, f, exact);
        sat.detect(); // warm both
        exact.detect();
        for (int r = 0; r < rounds; ++r) {
            for (int turn = 0; turn < 2; ++turn) {
                const bool sat_turn = (turn == 0) == (r % 2 == 0);
                const FrameResult& result = (sat_turn ? sat : exact).detect();
                (sat_turn ? sat_ms : exact_ms) += result.times.total;
                (sat_turn ? sat_narrow : exact_narrow) += result.times.narrow_phase + result.times.find_candidates * (method == Method::kdet_no_pairs);
                if (r == 0) {
                    (sat_turn ? sat_pairs : exact_pairs) += method == Method::kdet_no_pairs ? result.counts.colliding_tets : result.counts.colliding_pairs;
                    if (!sat_turn) exact_stage += result.counts.exact_stage_pairs;
                }
            }
        }
        ++frames;
    }
    const double runs = static_cast<double>(frames) * rounds;
    std::printf("| %s | %s | %s | %llu | %.3f | %.3f | %.3f | %.3f | %.3f | %llu | %llu | %llu |\n", name.c_str(),
                to_string(method), self ? "yes" : "no", static_cast<unsigned long long>(frames), sat_ms / runs,
                exact_ms / runs, exact_ms / sat_ms, sat_narrow / runs, exact_narrow / runs,
                static_cast<unsigned long long>(sat_pairs), static_cast<unsigned long long>(exact_pairs),
                static_cast<unsigned long long>(exact_stage));
    std::fflush(stdout);
}

} // namespace

int main(int argc, char** argv) {
    bool pairs_only = false;
    std::vector<int> numbers;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--pairs-only") == 0) pairs_only = true;
        else numbers.push_back(std::atoi(argv[i]));
    }
    const auto number = [&](std::size_t i, int fallback) { return i < numbers.size() ? numbers[i] : fallback; };
    const int resolution = number(0, 2), pair_step = number(1, 8), rounds = number(2, 7), threads = number(3, 1),
              frame_step = number(4, 4);
    const char* scenes[] = {"armadillos", "buddha_and_armadillo", "bunny_and_planck", "pass_through_armadillos"};
    std::vector<std::pair<std::string, std::unique_ptr<Scene>>> opened;
    for (const char* name : scenes) {
        SceneRequest request;
        request.resolution = resolution;
        try {
            opened.emplace_back(name, open_scene(name, request));
        } catch (const Error& e) {
            std::printf("%s: skipped: %s\n", name, e.what());
        }
    }
    const auto self_settings = [](const std::string& name) {
        return name == "pass_through_armadillos" ? std::vector<bool>{false} : std::vector<bool>{false, true};
    };
    std::printf("resolution %d, compiler %s\n\nPer pair (one thread, thread CPU time, median of %d rounds; last "
                "column: ratio of the fastest rounds):\n\n| scene | self | frames | candidates | timed pairs | sat hits "
                "| exact hits | exact stage | sat ns | exact ns | exact / sat | best / best |\n|---|---|---:|---:|---:|---:|"
                "---:|---:|---:|---:|---:|---:|\n",
                resolution, __VERSION__, rounds);
    for (const auto& [name, scene] : opened)
        for (bool self : self_settings(name)) per_pair(name, *scene, self, pair_step, rounds);
    if (pairs_only) return 0;
    const int frame_rounds = std::max(1, rounds / 2);
    std::printf("\nPer frame (%d thread(s), every %d-th frame, %d rounds, detect() wall time in ms; narrow: the "
                "narrow-phase stage, for kdet_no_pairs the candidate stage that tests inline):\n\n| scene | method | "
                "self | frames | sat ms | exact ms | exact / sat | sat narrow ms | exact narrow ms | sat pairs | exact "
                "pairs | exact stage |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
                threads, frame_step, frame_rounds);
    for (const auto& [name, scene] : opened)
        for (bool self : self_settings(name))
            for (Method method : {Method::kdet, Method::kdet_no_pairs})
                per_frame(name, *scene, self, method, frame_step, frame_rounds, threads);
    return 0;
}
