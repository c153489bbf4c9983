/// Pairs within a margin (DetectorOptions::margin) on the thesis scenes: kdet at margin 0, at 1 % and at
/// 10 % of the scene's median edge length, and beside each the peer a CPU user would write: CGAL's
/// box_intersection_d over the tets' boxes grown by the margin (as kdet grows them), then, per box pair,
/// the same exact decision kdet makes (tets_intersect_exact, else narrow::disjoint_tets_within), on one
/// thread. Within one object, tets sharing a vertex are skipped, and only the object pairs the scene
/// checks are tested, as kdet does.
///
/// Per frame, outside any timing: the scene's positions, concatenated. Then, interleaved, for each
/// margin: kdet's detect() (one Detector per margin, kept over the frames) and the peer's frame, each
/// timed with a steady clock. One untimed pass warms kdet up (buffers grow to what the frames need);
/// every pass in which the peer runs compares the two pair sets of every frame at every margin.
///
/// usage: kdet_margin_vs_cgal [--scenes a,b,...] [-r N] [--frames A:B] [--runs N] [--csv FILE] [--threads N]
///                            [--backend cpu|cuda] [--peer-runs N]
///   --scenes   default: the four thesis scenes (pass_through_armadillos without self-collision only)
///   -r N       resolution (default 4); --frames A:B (default 60:99); --runs N timed passes (default 3)
///   --csv FILE scene,self,margin_fraction,margin,frames,pairs,kdet_ms,kdet_vs_margin0,peer_ms,ratio,same_pairs
///   --threads  kdet's threads (default 2); the peer always runs on one
///   --backend  kdet's backend (default cpu); with cuda, the margins' costs on the GPU (scripts/gpu-session.sh)
///   --peer-runs N  timed passes that run the peer too (default: all); the untimed pass always does, so
///              every frame's pairs are checked at least once (0: the peer's time is not measured)
/// Exit status: 0, 1 on a mismatching frame or an error, 2 for a bad command line.

#include "peer.hpp"
#include "scene_frames.hpp"

#include "geometry/tet_distance.hpp"
#include "pipeline/bounding_boxes.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <CGAL/box_intersection_d.h>

#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace kdet;
using namespace kdet::bench;

/// The margins, as fractions of the scene's median edge length.
constexpr std::array<double, 3> k_margin_fractions{0.0, 0.01, 0.1};

/// The peer: grown boxes through CGAL's box intersection, then the exact decision per box pair.
class MarginPeer {
public:
    explicit MarginPeer(const SceneLayout& layout) : layout_(layout), boxes_(layout.objects) {}

    /// One frame at `margin`; the pair keys, in any order.
    const std::vector<std::uint64_t>& detect(const std::vector<float>& xyz, float margin) {
        positions_ = reinterpret_cast<const vec3*>(xyz.data());
        margin_ = margin;
        keys_.clear();
        for (std::size_t o = 0; o < layout_.objects; ++o) {
            boxes_[o].clear();
            for (std::uint32_t t = layout_.tet_begin[o]; t < layout_.tet_begin[o + 1]; ++t) {
                vec3 v[4];
                load_tet_vertices(positions_, layout_.tets[t], v);
                const Aabb b = margin > 0.0f ? grown_box(tet_box(v), half_margin(margin)) : tet_box(v);
                float lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
                boxes_[o].emplace_back(lo, hi, t);
            }
        }
        const auto decide = [this](const Peer::Box& x, const Peer::Box& y) { decide_pair(x.info(), y.info()); };
        for (std::size_t o = 0; o < layout_.objects; ++o) {
            if (layout_.checked[o * layout_.objects + o])
                CGAL::box_self_intersection_d(boxes_[o].begin(), boxes_[o].end(), decide);
            for (std::size_t p = o + 1; p < layout_.objects; ++p)
                if (layout_.checked[o * layout_.objects + p])
                    CGAL::box_intersection_d(boxes_[o].begin(), boxes_[o].end(), boxes_[p].begin(), boxes_[p].end(), decide);
        }
        return keys_;
    }

private:
    void decide_pair(std::uint32_t t, std::uint32_t u) {
        if (t > u) std::swap(t, u);
        const TetIndices &a = layout_.tets[t], &b = layout_.tets[u];
        if (layout_.tet_object[t] == layout_.tet_object[u])
            for (int i = 0; i < 4; ++i)
                for (int j = 0; j < 4; ++j)
                    if (a.v[i] == b.v[j]) return;
        vec3 va[4], vb[4];
        load_tet_vertices(positions_, a, va);
        load_tet_vertices(positions_, b, vb);
        if (tets_intersect_exact(va, vb) || (margin_ > 0.0f && narrow::disjoint_tets_within(va, vb, margin_)))
            keys_.push_back(pair_key(t, u));
    }

    const SceneLayout& layout_;
    std::vector<std::vector<Peer::Box>> boxes_; ///< [object]
    const vec3* positions_ = nullptr;
    float margin_ = 0.0f;
    std::vector<std::uint64_t> keys_;
};

/// The median length of the scene's edges at rest (each edge once).
double median_edge_length(const Scene& scene) {
    std::vector<double> lengths;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        const TetMesh& mesh = scene.rest_mesh(o);
        std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
        for (std::size_t t = 0; t < mesh.num_tets(); ++t)
            for (int i = 0; i < 4; ++i)
                for (int j = i + 1; j < 4; ++j) {
                    const std::uint32_t p = mesh.tets[4 * t + i], q = mesh.tets[4 * t + j];
                    edges.emplace_back(std::min(p, q), std::max(p, q));
                }
        std::sort(edges.begin(), edges.end());
        edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
        for (const auto& [p, q] : edges) {
            const double* a = &mesh.positions[3 * std::size_t{p}];
            const double* b = &mesh.positions[3 * std::size_t{q}];
            lengths.push_back(std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2])));
        }
    }
    return median(std::move(lengths));
}

double elapsed_ms(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

/// One case at one margin: medians over frames x timed passes, and kdet's stage times.
struct MarginRow {
    CaseResult result;
    double fraction = 0, median_edge = 0;
    float margin = 0;
    StageTimes stages; ///< kdet's, each the median over frames x timed passes
    double candidates = 0;
};

/// What this program reads besides the frame-by-frame peers' flags (parse_peer_args).
struct MarginConfig {
    Backend backend = Backend::cpu;
    int peer_runs = -1; ///< -1: every timed pass
};

/// Takes --backend and --peer-runs out of argv (argc shrinks), into the returned configuration; a bad
/// value prints the usage and exits with 2.
MarginConfig take_margin_flags(int& argc, char** argv, const char* program) {
    MarginConfig config;
    int kept = 1;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if ((flag == "--backend" || flag == "--peer-runs") && i + 1 < argc) {
            const std::string value = argv[++i];
            if (flag == "--peer-runs") {
                config.peer_runs = static_cast<int>(parse_peer_number(program, true, value, "--peer-runs", 0, 1000));
            } else if (value == "cpu" || value == "cuda") {
                config.backend = value == "cpu" ? Backend::cpu : Backend::cuda;
            } else {
                peer_usage(program, true, "--backend '" + value + "': expected cpu or cuda");
            }
        } else {
            argv[kept++] = argv[i];
        }
    }
    argc = kept;
    return config;
}

/// kdet and the peer at every margin, interleaved frame by frame (see the file's comment).
std::vector<MarginRow> run_margin_case(const PeerConfig& config, const MarginConfig& margin_config, const Scene& scene,
                                       const CaseResult& c) {
    const double edge = median_edge_length(scene);
    const SceneLayout layout(scene, c.self);
    const auto [first, last] = frame_range(config, scene);
    std::vector<MarginRow> rows;
    std::vector<std::unique_ptr<Detector>> detectors;
    for (const double fraction : k_margin_fractions) {
        MarginRow row;
        row.result = c;
        row.result.frames = last - first + 1;
        row.fraction = fraction;
        row.median_edge = edge;
        row.margin = static_cast<float>(fraction * edge);
        rows.push_back(row);
        DetectorOptions options;
        options.backend = margin_config.backend;
        options.threads = config.threads;
        options.margin = row.margin;
        detectors.push_back(std::make_unique<Detector>(options));
        add_scene_objects(*detectors.back(), scene, c.self);
        layout.check_numbering(*detectors.back());
    }
    MarginPeer peer(layout);
    const std::size_t n = rows.size();
    std::vector<std::vector<double>> kdet_ms(n), peer_ms(n), pairs(n), candidates(n);
    std::vector<std::vector<StageTimes>> stages(n);
    std::vector<std::set<int>> mismatching(n);
    std::vector<float> xyz;
    for (int pass = 0; pass <= config.runs; ++pass) {
        const bool with_peer = pass == 0 || margin_config.peer_runs < 0 || pass <= margin_config.peer_runs;
        for (int f = first; f <= last; ++f) {
            layout.positions(scene, f, xyz);
            for (std::size_t m = 0; m < n; ++m) {
                Detector& detector = *detectors[m];
                for (std::size_t o = 0; o < layout.objects; ++o)
                    detector.set_positions(static_cast<ObjectId>(o), xyz.data() + 3 * std::size_t{layout.vertex_begin[o]},
                                           layout.vertex_begin[o + 1] - layout.vertex_begin[o]);
                auto start = std::chrono::steady_clock::now();
                const FrameResult& kdet = detector.detect();
                const double kdet_time = elapsed_ms(start);
                if (pass > 0) {
                    kdet_ms[m].push_back(kdet_time);
                    stages[m].push_back(kdet.times);
                    candidates[m].push_back(static_cast<double>(kdet.counts.candidates));
                }
                if (!with_peer) continue;
                start = std::chrono::steady_clock::now();
                std::vector<std::uint64_t> peer_keys = peer.detect(xyz, rows[m].margin);
                const double peer_time = elapsed_ms(start);
                std::vector<std::uint64_t> kdet_keys;
                kdet_keys.reserve(kdet.pairs.size());
                for (const TetPair& p : kdet.pairs)
                    kdet_keys.push_back(pair_key(layout.tet_begin[p.object_a] + p.tet_a, layout.tet_begin[p.object_b] + p.tet_b));
                std::sort(kdet_keys.begin(), kdet_keys.end());
                std::sort(peer_keys.begin(), peer_keys.end());
                char what[160];
                std::snprintf(what, sizeof what, "%s%s margin %g x median edge, frame %d pass %d", c.label.c_str(),
                              c.self ? " self" : "", rows[m].fraction, f, pass);
                if (keys_differ(kdet_keys, peer_keys, what)) mismatching[m].insert(f);
                if (pass == 0)
                    pairs[m].push_back(static_cast<double>(kdet_keys.size()));
                else
                    peer_ms[m].push_back(peer_time);
            }
        }
    }
    for (std::size_t m = 0; m < n; ++m) {
        MarginRow& row = rows[m];
        row.result.kdet_ms = median(kdet_ms[m]);
        row.result.peer_ms = median(peer_ms[m]);
        row.result.pairs = median(pairs[m]);
        row.result.mismatching_frames = mismatching[m].size();
        const auto stage = [&](double StageTimes::*field) {
            std::vector<double> values;
            for (const StageTimes& t : stages[m]) values.push_back(t.*field);
            return median(std::move(values));
        };
        row.stages = StageTimes{stage(&StageTimes::bounding_boxes), stage(&StageTimes::populate_grid),
                                stage(&StageTimes::find_candidates), stage(&StageTimes::sort_pairs),
                                stage(&StageTimes::narrow_phase), stage(&StageTimes::total)};
        row.candidates = median(candidates[m]);
        std::fprintf(stderr, "%s self %s margin %g: kdet %.3f ms, peer %.3f ms%s\n", c.label.c_str(), c.self ? "yes" : "no",
                     row.fraction, row.result.kdet_ms, row.result.peer_ms,
                     row.result.mismatching_frames ? ", MISMATCHING FRAMES" : "");
    }
    return rows;
}

/// kdet's time at margin 0 in the same case (the first row of each case).
double margin0_ms(const std::vector<MarginRow>& rows, std::size_t i) {
    return rows[i - i % k_margin_fractions.size()].result.kdet_ms;
}

std::string margin_table(const std::vector<MarginRow>& rows) {
    std::string out = "| scene | r | self | tets | frames | margin (x median edge) | margin | pairs | kdet ms | "
                      "kdet / kdet at 0 | peer ms | peer / kdet | candidates | boxes ms | grid ms | candidates ms | "
                      "narrow ms | sort ms | mismatching frames |\n"
                      "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    char line[512];
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const MarginRow& row = rows[i];
        const CaseResult& r = row.result;
        const double base = margin0_ms(rows, i);
        std::snprintf(line, sizeof line,
                      "| %s | %s | %s | %zu | %d | %g | %.4g | %.0f | %.2f | %.2f | %.2f | %.1f | %.0f | %.2f | %.2f | %.2f | "
                      "%.2f | %.2f | %zu |\n",
                      r.scene.c_str(), r.resolution.c_str(), r.self ? "yes" : "no", r.tets, r.frames, row.fraction,
                      static_cast<double>(row.margin), r.pairs, r.kdet_ms, base > 0 ? r.kdet_ms / base : 0.0, r.peer_ms,
                      r.kdet_ms > 0 ? r.peer_ms / r.kdet_ms : 0.0, row.candidates, row.stages.bounding_boxes,
                      row.stages.populate_grid, row.stages.find_candidates, row.stages.narrow_phase, row.stages.sort_pairs,
                      r.mismatching_frames);
        out += line;
    }
    return out;
}

std::string margin_csv(const std::vector<MarginRow>& rows) {
    std::string out = "scene,self,margin_fraction,margin,frames,pairs,kdet_ms,kdet_vs_margin0,peer_ms,ratio,same_pairs\n";
    char line[512];
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const CaseResult& r = rows[i].result;
        const double base = margin0_ms(rows, i);
        std::snprintf(line, sizeof line, "%s,%s,%g,%.9g,%d,%.0f,%.4f,%.3f,%.4f,%.3f,%s\n", r.label.c_str(),
                      r.self ? "yes" : "no", rows[i].fraction, static_cast<double>(rows[i].margin), r.frames, r.pairs,
                      r.kdet_ms, base > 0 ? r.kdet_ms / base : 0.0, r.peer_ms, r.kdet_ms > 0 ? r.peer_ms / r.kdet_ms : 0.0,
                      r.mismatching_frames ? "false" : "true");
        out += line;
    }
    return out;
}

} // namespace

int main(int argc, char** argv) {
    const char* program = "kdet_margin_vs_cgal";
    PeerConfig defaults;
    defaults.without_self = {"pass_through_armadillos"};
    const MarginConfig margin_config = take_margin_flags(argc, argv, program);
    const PeerConfig config = parse_peer_args(argc, argv, program, defaults, true);
    try {
        std::printf("cpu: %s, %d logical processors; kdet on %s, the peer on one thread; kdet %s\n", cpu_name().c_str(),
                    omp_get_num_procs(),
                    margin_config.backend == Backend::cpu ? (std::to_string(config.threads) + " threads").c_str() : "cuda",
                    version().c_str());
        std::printf("%d timed runs after one untimed; medians over frames x runs\n\n", config.runs);
        std::vector<MarginRow> rows;
        for_each_case(config, [&](const Scene& scene, const CaseResult& c) {
            for (MarginRow& row : run_margin_case(config, margin_config, scene, c)) rows.push_back(std::move(row));
        });
        std::printf("median edge length per scene:");
        for (std::size_t i = 0; i < rows.size(); i += k_margin_fractions.size())
            if (!rows[i].result.self) std::printf(" %s %.6g;", rows[i].result.scene.c_str(), rows[i].median_edge);
        std::printf("\n\n%s", margin_table(rows).c_str());
        if (!config.csv.empty() && !write_text(config.csv, margin_csv(rows), program)) return 1;
        std::size_t bad = 0;
        for (const MarginRow& row : rows) bad += row.result.mismatching_frames;
        if (bad) std::fprintf(stderr, "%s: %zu frames where kdet and the peer differ\n", program, bad);
        return bad ? 1 : 0;
    } catch (const std::exception& error) {
        std::fprintf(stderr, "%s: %s\n", program, error.what());
        return 1;
    }
}
