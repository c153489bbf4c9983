#pragma once
/// @file scene_frames.hpp
/// @brief What the frame-by-frame peers (gpu_vs_sweep.cu, gpu_vs_cubql.cu, cpu_vs_cubql.cpp) share: a
/// scene's tets in kdet's global numbering with the object pairs it checks, their command line, the
/// cases they run, the loop that times kdet and a peer on the same frames and compares their pair sets
/// on every frame, and the table of the results.

#include "pipeline/scene_view.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace kdet::bench {

KDET_HD inline void load_tet_vertices(const vec3* positions, const TetIndices& tet, vec3 out[4]) {
    for (int k = 0; k < 4; ++k) out[k] = positions[tet.v[k]];
}

/// A pair as kdet's device results key it: the lower global tet id in the high half.
KDET_HD inline unsigned long long pair_key(std::uint32_t lo, std::uint32_t hi) {
    return (static_cast<unsigned long long>(lo) << 32) | hi;
}

/// A scene's tets as kdet numbers them (object by object, first_tet(o) + t), with global vertex ids
/// into the concatenated positions of all objects, and the object pairs kdet checks.
struct SceneLayout {
    std::size_t objects = 0;
    std::vector<std::uint32_t> vertex_begin, tet_begin; ///< [object + 1]
    std::vector<TetIndices> tets;
    std::vector<std::uint32_t> tet_object;
    /// [a * objects + b]: whether pairs between a and b (a == b: inside a) are reported, as
    /// add_scene_objects switches them for kdet.
    std::vector<std::uint8_t> checked;

    SceneLayout(const Scene& scene, bool self)
        : objects(scene.num_objects()), vertex_begin(objects + 1, 0), tet_begin(objects + 1, 0),
          checked(objects * objects, 0) {
        for (std::size_t o = 0; o < objects; ++o) {
            const TetMesh& mesh = scene.rest_mesh(o);
            vertex_begin[o + 1] = vertex_begin[o] + static_cast<std::uint32_t>(mesh.num_vertices());
            tet_begin[o + 1] = tet_begin[o] + static_cast<std::uint32_t>(mesh.num_tets());
            for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
                TetIndices tet;
                for (int k = 0; k < 4; ++k) tet.v[k] = vertex_begin[o] + mesh.tets[4 * t + k];
                tets.push_back(tet);
                tet_object.push_back(static_cast<std::uint32_t>(o));
            }
            checked[o * objects + o] = self;
            for (std::size_t p = o + 1; p < objects; ++p)
                checked[o * objects + p] = checked[p * objects + o] = scene.checks_pair(o, p);
        }
    }

    std::size_t vertex_count() const { return vertex_begin.back(); }

    /// The pair keys compare with kdet's only while kdet numbers the tets as this layout does.
    void check_numbering(const Detector& detector) const {
        for (std::size_t o = 0; o < objects; ++o)
            if (detector.first_tet(static_cast<ObjectId>(o)) != tet_begin[o]) throw Error("unexpected tet numbering");
    }

    /// Every object's positions at `frame`, concatenated (x y z per global vertex).
    void positions(const Scene& scene, int frame, std::vector<float>& xyz) const {
        xyz.resize(3 * vertex_count());
        std::vector<float> object_xyz;
        for (std::size_t o = 0; o < objects; ++o) {
            scene.positions(o, frame, object_xyz);
            std::copy(object_xyz.begin(), object_xyz.end(), xyz.begin() + 3 * std::ptrdiff_t{vertex_begin[o]});
        }
    }
};

/// The command line of the frame-by-frame peers; each program sets its own defaults.
struct PeerConfig {
    std::vector<std::string> scenes{"armadillos", "buddha_and_armadillo", "bunny_and_planck", "pass_through_armadillos"};
    /// Scenes that run without self-collision only (as in the thesis); the others run without and with.
    std::vector<std::string> without_self;
    int resolution = 4;
    int first_frame = -1, last_frame = -1; ///< -1: each scene's default (frame_range)
    int runs = 3;
    std::vector<std::size_t> procedural_tets{100000};
    std::string csv;
    int threads = 2; ///< CPU threads of both sides (CPU programs only)
};

/// The frames a case runs: --frames clamped to the scene, else 60-99 (around contact) in the thesis
/// scenes and the eleven frames around the deepest in the procedural scene.
inline std::pair<int, int> frame_range(const PeerConfig& config, const Scene& scene) {
    const bool procedural = scene.name() == "procedural";
    const int middle = scene.num_frames() / 2;
    const bool given = config.first_frame >= 0;
    const int first = given ? config.first_frame : (procedural ? std::max(0, middle - 5) : 60);
    const int wanted_last = given ? config.last_frame : (procedural ? middle + 5 : 99);
    const int last = std::min(wanted_last, scene.num_frames() - 1);
    if (first > last)
        throw Error("frames " + std::to_string(first) + ":" + std::to_string(wanted_last) + " outside scene '" +
                    scene.name() + "' (" + std::to_string(scene.num_frames()) + " frames)");
    return {first, last};
}

[[noreturn]] inline void peer_usage(const char* program, bool threads, const std::string& problem) {
    if (!problem.empty()) std::fprintf(stderr, "%s: %s\n", program, problem.c_str());
    std::fprintf(problem.empty() ? stdout : stderr,
                 "usage: %s [--scenes a,b,...] [-r N] [--frames A:B] [--runs N] [--tets N,...] [--csv FILE]%s\n", program,
                 threads ? " [--threads N]" : "");
    std::exit(problem.empty() ? 0 : 2);
}

inline long parse_peer_number(const char* program, bool threads, const std::string& text, const char* flag, long lo,
                              long hi) {
    char* end = nullptr;
    const long value = std::strtol(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || value < lo || value > hi)
        peer_usage(program, threads,
                   std::string(flag) + " '" + text + "': expected a number in [" + std::to_string(lo) + ", " +
                       std::to_string(hi) + "]");
    return value;
}

inline std::vector<std::string> split_list(const std::string& text) {
    std::vector<std::string> items;
    for (std::size_t begin = 0; begin <= text.size();) {
        const std::size_t end = std::min(text.find(',', begin), text.size());
        if (end > begin) items.push_back(text.substr(begin, end - begin));
        begin = end + 1;
    }
    return items;
}

/// Reads the flags into `config` (which holds the program's defaults); `threads`: --threads is taken.
/// A bad command line prints the usage and exits with 2.
inline PeerConfig parse_peer_args(int argc, char** argv, const char* program, PeerConfig config, bool threads = false) {
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "-h" || flag == "--help") peer_usage(program, threads, "");
        if (i + 1 >= argc) peer_usage(program, threads, "unknown flag or missing value: " + flag);
        const std::string value = argv[++i];
        const auto number = [&](long lo, long hi) { return parse_peer_number(program, threads, value, flag.c_str(), lo, hi); };
        if (flag == "--scenes") {
            config.scenes = split_list(value);
            if (config.scenes.empty()) peer_usage(program, threads, "--scenes: no scene given");
        } else if (flag == "-r") {
            config.resolution = static_cast<int>(number(1, 4));
        } else if (flag == "--frames") {
            const std::size_t colon = value.find(':');
            if (colon == std::string::npos) peer_usage(program, threads, "--frames: expected A:B");
            config.first_frame = static_cast<int>(parse_peer_number(program, threads, value.substr(0, colon), "--frames", 0, 1000000));
            config.last_frame = static_cast<int>(parse_peer_number(program, threads, value.substr(colon + 1), "--frames", 0, 1000000));
            if (config.first_frame > config.last_frame) peer_usage(program, threads, "--frames: A must not exceed B");
        } else if (flag == "--runs") {
            config.runs = static_cast<int>(number(1, 1000));
        } else if (flag == "--tets") {
            config.procedural_tets.clear();
            for (const std::string& item : split_list(value))
                config.procedural_tets.push_back(
                    static_cast<std::size_t>(parse_peer_number(program, threads, item, "--tets", 100, 20000000)));
            if (config.procedural_tets.empty()) peer_usage(program, threads, "--tets: no count given");
        } else if (flag == "--csv") {
            config.csv = value;
        } else if (flag == "--threads" && threads) {
            config.threads = static_cast<int>(number(1, 1024));
        } else {
            peer_usage(program, threads, "unknown flag: " + flag);
        }
    }
    return config;
}

struct CaseResult {
    std::string scene;      ///< as open_scene names it
    std::string label;      ///< scene and size: "armadillos-r4", "procedural-1M"
    std::string resolution; ///< "-" for the procedural scene
    bool self = false;
    std::size_t tets = 0;
    int frames = 0;
    double kdet_ms = 0, peer_ms = 0, pairs = 0; ///< medians over frames (times: over frames x timed runs)
    std::size_t mismatching_frames = 0;
};

/// One frame of both sides: their times and pair keys (any order).
struct FrameOutcome {
    double kdet_ms = 0, peer_ms = 0;
    std::vector<std::uint64_t> kdet_keys, peer_keys;
};

inline double median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// Prints how two sorted key sets differ; returns whether they do.
inline bool keys_differ(const std::vector<std::uint64_t>& kdet, const std::vector<std::uint64_t>& peer,
                        const std::string& what) {
    if (kdet == peer) return false;
    std::vector<std::uint64_t> only_kdet, only_peer;
    std::set_difference(kdet.begin(), kdet.end(), peer.begin(), peer.end(), std::back_inserter(only_kdet));
    std::set_difference(peer.begin(), peer.end(), kdet.begin(), kdet.end(), std::back_inserter(only_peer));
    std::fprintf(stderr, "MISMATCH %s: kdet %zu pairs, peer %zu; only kdet %zu, only peer %zu", what.c_str(),
                 kdet.size(), peer.size(), only_kdet.size(), only_peer.size());
    const auto show = [](const char* side, const std::vector<std::uint64_t>& keys) {
        if (!keys.empty())
            std::fprintf(stderr, " (first only %s: %u %u)", side, static_cast<unsigned>(keys[0] >> 32),
                         static_cast<unsigned>(keys[0] & 0xffffffffu));
    };
    show("kdet", only_kdet);
    show("peer", only_peer);
    std::fprintf(stderr, "\n");
    return true;
}

/// Runs `frame(f, first_pass)` (a FrameOutcome) over the case's frames: one untimed pass that warms
/// both sides up (buffers grow to what the frames need), then config.runs timed ones; every pass
/// compares the two pair sets of every frame. `result` comes with its scene, label, resolution, self
/// and tets set.
template <class Frame>
CaseResult run_frames(const PeerConfig& config, const Scene& scene, CaseResult result, Frame&& frame) {
    const auto [first, last] = frame_range(config, scene);
    result.frames = last - first + 1;
    std::vector<double> kdet_ms, peer_ms, pairs;
    std::set<int> mismatching;
    for (int pass = 0; pass <= config.runs; ++pass) {
        for (int f = first; f <= last; ++f) {
            FrameOutcome outcome = frame(f, pass == 0);
            std::sort(outcome.kdet_keys.begin(), outcome.kdet_keys.end());
            std::sort(outcome.peer_keys.begin(), outcome.peer_keys.end());
            const std::string what = result.label + (result.self ? " self" : "") + " frame " + std::to_string(f) +
                                     " pass " + std::to_string(pass);
            if (keys_differ(outcome.kdet_keys, outcome.peer_keys, what)) mismatching.insert(f);
            if (pass == 0) {
                pairs.push_back(static_cast<double>(outcome.kdet_keys.size()));
            } else {
                kdet_ms.push_back(outcome.kdet_ms);
                peer_ms.push_back(outcome.peer_ms);
            }
        }
    }
    result.kdet_ms = median(kdet_ms);
    result.peer_ms = median(peer_ms);
    result.pairs = median(pairs);
    result.mismatching_frames = mismatching.size();
    return result;
}

/// A tet count as a label: 1M, 250k, 1500.
inline std::string count_label(std::size_t n) {
    if (n % 1000000 == 0) return std::to_string(n / 1000000) + "M";
    if (n % 1000 == 0) return std::to_string(n / 1000) + "k";
    return std::to_string(n);
}

/// Calls `each(scene, c)` for every case of the configuration: each scene (the procedural one at each
/// --tets), without and with self-collision (without only for the scenes in config.without_self), `c`
/// with its scene, label, resolution, self and tets set. Throws kdet::Error for a scene that cannot be
/// opened.
inline void for_each_case(const PeerConfig& config, const std::function<void(const Scene&, const CaseResult&)>& each) {
    for (const std::string& name : config.scenes) {
        const bool procedural = name == "procedural";
        for (const std::size_t tets : procedural ? config.procedural_tets : std::vector<std::size_t>{0}) {
            SceneRequest request;
            request.resolution = config.resolution;
            if (procedural) request.procedural.total_tets = tets;
            const std::unique_ptr<Scene> scene = open_scene(name, request);
            // pass_through_armadillos fixes its meshes at resolution 2; the procedural scene has none.
            const std::string resolution =
                procedural ? "-" : (name == "pass_through_armadillos" ? "2" : std::to_string(config.resolution));
            const bool self_too = std::find(config.without_self.begin(), config.without_self.end(), name) ==
                                  config.without_self.end();
            for (const bool self : {false, true}) {
                if (self && !self_too) continue;
                CaseResult c;
                c.scene = name;
                c.label = name + (procedural ? "-" + count_label(tets) : "-r" + resolution);
                c.resolution = resolution;
                c.self = self;
                for (std::size_t o = 0; o < scene->num_objects(); ++o) c.tets += scene->rest_mesh(o).num_tets();
                each(*scene, c);
            }
        }
    }
}

/// Every case of the configuration (for_each_case): `run_case(scene, result)` returns the case's
/// result (see run_frames). Progress goes to stderr.
inline std::vector<CaseResult> run_cases(const PeerConfig& config, const char* peer,
                                         const std::function<CaseResult(const Scene&, CaseResult)>& run_case) {
    std::vector<CaseResult> results;
    for_each_case(config, [&](const Scene& scene, const CaseResult& c) {
        results.push_back(run_case(scene, c));
        const CaseResult& r = results.back();
        std::fprintf(stderr, "%s self %s: kdet %.3f ms, %s %.3f ms%s\n", r.label.c_str(), r.self ? "yes" : "no", r.kdet_ms,
                     peer, r.peer_ms, r.mismatching_frames ? ", MISMATCHING FRAMES" : "");
    });
    return results;
}

/// The markdown table of the results; `peer` names the peer's columns.
inline std::string results_table(const std::vector<CaseResult>& results, const std::string& peer) {
    std::string out = "| scene | r | self | tets | frames | kdet ms | " + peer + " ms | " + peer +
                      " / kdet | pairs | mismatching frames |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
    char line[512];
    for (const CaseResult& r : results) {
        std::snprintf(line, sizeof line, "| %s | %s | %s | %zu | %d | %.3f | %.3f | %.2f | %.0f | %zu |\n", r.scene.c_str(),
                      r.resolution.c_str(), r.self ? "yes" : "no", r.tets, r.frames, r.kdet_ms, r.peer_ms,
                      r.kdet_ms > 0 ? r.peer_ms / r.kdet_ms : 0.0, r.pairs, r.mismatching_frames);
        out += line;
    }
    return out;
}

/// The CSV of the comparison: scene,self,frames,kdet_ms,<peer>_ms,ratio,same_pairs (ratio: the
/// peer's time over kdet's; same_pairs: no frame of the case differed).
inline std::string ratio_csv(const std::vector<CaseResult>& results, const std::string& peer) {
    std::string out = "scene,self,frames,kdet_ms," + peer + "_ms,ratio,same_pairs\n";
    char line[512];
    for (const CaseResult& r : results) {
        std::snprintf(line, sizeof line, "%s,%s,%d,%.4f,%.4f,%.3f,%s\n", r.label.c_str(), r.self ? "yes" : "no", r.frames,
                      r.kdet_ms, r.peer_ms, r.kdet_ms > 0 ? r.peer_ms / r.kdet_ms : 0.0,
                      r.mismatching_frames ? "false" : "true");
        out += line;
    }
    return out;
}

/// The processor's name from /proc/cpuinfo ("unknown" without it).
inline std::string cpu_name() {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);)
        if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) return line.substr(line.find(':') + 2);
    return "unknown";
}

/// Writes `text` to `path`; false (with a message naming the program) when it cannot.
inline bool write_text(const std::string& path, const std::string& text, const char* program) {
    std::ofstream out(path);
    out << text;
    out.close();
    if (!out) std::fprintf(stderr, "%s: cannot write %s\n", program, path.c_str());
    return static_cast<bool>(out);
}

/// The number of frames, over all cases, where kdet and the peer differ; says so on stderr.
inline std::size_t mismatches(const std::vector<CaseResult>& results, const char* program) {
    std::size_t n = 0;
    for (const CaseResult& r : results) n += r.mismatching_frames;
    if (n) std::fprintf(stderr, "%s: %zu frames where kdet and the peer differ\n", program, n);
    return n;
}

} // namespace kdet::bench
