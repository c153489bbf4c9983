// Soak test of one long-lived Detector (issue 48): many frames of the procedural scene while objects are
// switched on and off, moved far apart and back, stacked onto each other and self-collision toggled, so
// that the candidate and pair buffers grow and shrink again and again. It reports the process's
// resident memory as it goes (bounded: the last no higher than after the first cycle of phases, within
// a tolerance), and on sampled frames checks the pair set against a fresh detector's. Built under the
// `asan` preset, LeakSanitizer checks at exit that nothing leaked. scripts/soak.sh runs it.
//
// Usage: kdet_soak [--frames N] [--tets N] [--sample N] [--phase N] [--threads N]

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace {

using namespace kdet;

/// VmRSS or VmHWM of this process in KiB, from /proc/self/status.
long status_kib(const char* field) {
    std::ifstream in("/proc/self/status");
    std::string line;
    const std::string key = std::string(field) + ":";
    while (std::getline(in, line))
        if (line.rfind(key, 0) == 0) return std::atol(line.c_str() + key.size());
    return -1;
}

/// `count` copies of one small tet near the origin, each with vertices of their own and moved a little
/// (so that the float test decides them): all of them collide with each other, so switching its
/// self-collision makes the pairs jump by count * (count - 1) / 2.
TetMesh pile_of(std::uint32_t count) {
    TetMesh mesh;
    const double corners[4][3] = {{0, 0, 0}, {0.3, 0, 0}, {0, 0.3, 0}, {0, 0, 0.3}};
    for (std::uint32_t t = 0; t < count; ++t)
        for (std::uint32_t k = 0; k < 4; ++k) {
            for (int a = 0; a < 3; ++a) mesh.positions.push_back(corners[k][a] + 0.002 * t * (a + 1));
            mesh.tets.push_back(4 * t + k);
        }
    return mesh;
}

/// What one frame asks of the detector: the phase decides which objects are checked and where they are.
struct FrameSetup {
    std::vector<std::vector<float>> positions; ///< per object
    bool self[3];
    bool pair[3][3];
};

constexpr int phases = 8;
const char* const phase_names[phases] = {"as the scene moves", "torus 1 far away (1e6)", "self-collision of the tori",
                                         "tori not checked", "torus 1 on torus 0 (moved by 0.01)", "pile's self-collision",
                                         "pile in the tori, far and back", "nothing checked"};

FrameSetup setup_for(const Scene& scene, const TetMesh& pile, int frame, int phase_length) {
    FrameSetup s{};
    const int scene_frame = frame % scene.num_frames();
    const int phase = frame / phase_length % phases;
    s.positions.resize(3);
    scene.positions(0, scene_frame, s.positions[0]);
    scene.positions(1, scene_frame, s.positions[1]);
    s.positions[2].assign(pile.positions.begin(), pile.positions.end());
    for (auto& row : s.pair)
        for (bool& b : row) b = false;
    s.self[0] = s.self[1] = s.self[2] = false;
    s.pair[0][1] = s.pair[1][0] = true;
    s.pair[0][2] = s.pair[2][0] = s.pair[1][2] = s.pair[2][1] = true;
    // The pile waits far from the tori, except in phase 6, where it comes back into them every other frame.
    float pile_shift = 50.0f;
    switch (phase) {
    case 1:
        for (std::size_t v = 0; v < s.positions[1].size(); v += 3) s.positions[1][v] += 1e6f;
        break;
    case 2: s.self[0] = s.self[1] = true; break;
    case 3: s.pair[0][1] = s.pair[1][0] = false; break;
    case 4: // torus 1 onto torus 0, a little off so that the float test decides most pairs
        s.positions[1] = s.positions[0];
        for (float& x : s.positions[1]) x += 0.01f;
        break;
    case 5: s.self[2] = true; break;
    case 6: pile_shift = frame % 2 ? 0.0f : 1e6f; break;
    case 7:
        for (auto& row : s.pair)
            for (bool& b : row) b = false;
        break;
    default: break;
    }
    for (std::size_t v = 0; v < s.positions[2].size(); v += 3) s.positions[2][v] += pile_shift;
    return s;
}

void apply(Detector& detector, const FrameSetup& s) {
    for (ObjectId o = 0; o < 3; ++o) {
        detector.set_positions(o, s.positions[o].data(), s.positions[o].size() / 3);
        detector.set_self_collision(o, s.self[o]);
        for (ObjectId p = o + 1; p < 3; ++p) detector.set_pair_collision(o, p, s.pair[o][p]);
    }
}

void add_objects(Detector& detector, const Scene& scene, const TetMesh& pile) {
    detector.add_object(scene.rest_mesh(0));
    detector.add_object(scene.rest_mesh(1));
    detector.add_object(pile);
}

int run(int argc, char** argv) {
    long frames = 100000, sample = 1000;
    std::size_t tets = 200;
    DetectorOptions options;
    options.threads = 1; // a soak runs beside other work: one thread, no OpenMP team waiting on a busy core
    int phase_length = 237;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string flag = argv[i];
        const long value = std::atol(argv[i + 1]);
        if (value <= 0) throw Error("kdet_soak: " + flag + " needs a positive number");
        if (flag == "--frames") frames = value;
        else if (flag == "--tets") tets = static_cast<std::size_t>(value);
        else if (flag == "--sample") sample = value;
        else if (flag == "--phase") phase_length = static_cast<int>(value);
        else if (flag == "--threads") options.threads = static_cast<int>(value);
        else throw Error("kdet_soak: unknown flag " + flag + " (--frames, --tets, --sample, --phase, --threads)");
    }
    if (argc % 2 == 0) throw Error("kdet_soak: flags come in pairs: FLAG N");

    ProceduralSceneOptions scene_options;
    scene_options.total_tets = tets;
    scene_options.frames = 120;
    const ProceduralScene scene(scene_options);
    const TetMesh pile = pile_of(40);
    Detector detector(options);
    add_objects(detector, scene, pile);

    std::printf("frames %ld, procedural scene of %zu tets (%d frames) and a pile of %u identical tets, phases of %d frames\n",
                frames, scene.rest_mesh(0).num_tets() + scene.rest_mesh(1).num_tets(), scene.num_frames(),
                static_cast<unsigned>(pile.num_tets()), phase_length);
    for (int p = 0; p < phases; ++p) std::printf("phase %d: %s\n", p, phase_names[p]);
    std::printf("\n| frame | phase | pairs | fresh detector's pairs | same set | detector bytes | RSS KiB | peak RSS KiB |\n"
                "|---:|---:|---:|---:|---|---:|---:|---:|\n");
    const auto start = std::chrono::steady_clock::now();
    long after_first_cycle = -1, mismatches = 0, samples = 0, regrow_frames = 0;
    std::size_t max_pairs = 0, min_pairs = static_cast<std::size_t>(-1), max_bytes = 0, min_bytes = static_cast<std::size_t>(-1);
    for (long f = 0; f < frames; ++f) {
        const FrameSetup s = setup_for(scene, pile, static_cast<int>(f), phase_length);
        apply(detector, s);
        const FrameResult& r = detector.detect();
        regrow_frames += r.counts.buffer_regrows > 0;
        max_pairs = std::max(max_pairs, r.pairs.size());
        min_pairs = std::min(min_pairs, r.pairs.size());
        max_bytes = std::max(max_bytes, r.memory_bytes);
        min_bytes = std::min(min_bytes, r.memory_bytes);
        // The phases' length does not divide the samples' spacing, so the samples fall in every phase.
        if (f % sample == sample / 2 || f == frames - 1) {
            Detector fresh(options);
            add_objects(fresh, scene, pile);
            apply(fresh, s);
            const FrameResult& expected = fresh.detect();
            const bool same = expected.pairs == r.pairs;
            mismatches += !same;
            ++samples;
            std::printf("| %ld | %ld | %zu | %zu | %s | %zu | %ld | %ld |\n", f, f / phase_length % phases, r.pairs.size(),
                        expected.pairs.size(), same ? "yes" : "**NO**", r.memory_bytes, status_kib("VmRSS"),
                        status_kib("VmHWM"));
            std::fflush(stdout);
        }
        if (f + 1 == static_cast<long>(phases) * phase_length) after_first_cycle = status_kib("VmRSS");
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const long last = status_kib("VmRSS"), peak = status_kib("VmHWM");
    std::printf("\nframes: %ld in %.0f s; frames that grew a buffer: %ld; pairs per frame: %zu to %zu; detector's memory: %zu "
                "to %zu bytes\n",
                frames, seconds, regrow_frames, min_pairs, max_pairs, min_bytes, max_bytes);
    std::printf("RSS: after the first cycle of phases %ld KiB, last %ld KiB, peak %ld KiB\n", after_first_cycle, last, peak);
    std::printf("sampled frames: %ld, pair sets that differ from a fresh detector's: %ld\n", samples, mismatches);
    // Bounded: the last RSS may exceed the first cycle's by allocator noise (a tenth, and 16 MiB), no more.
    const bool bounded = after_first_cycle < 0 || last <= after_first_cycle + after_first_cycle / 10 + 16384;
    std::printf("memory bounded: %s\n", bounded ? "yes" : "NO");
    return mismatches == 0 && bounded ? 0 : 1;
}

} // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const kdet::Error& e) {
        std::cerr << e.what() << "\n";
        return 2;
    }
}
