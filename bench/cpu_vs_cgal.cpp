/// kdet on the CPU against the peer a CPU user would otherwise write: CGAL's box_intersection_d over the
/// tets' boxes, then kdet's own `sat` on each box-overlapping pair (tets sharing a vertex skipped in self
/// mode), on one thread. Both get the same float coordinates, and before any timing every frame of every
/// case is checked to give both the same pair set.
///
/// Cases: each model in the data folder against a moved copy of itself, each model folded onto itself
/// (self-collision), random tet soups whose tet sizes span three decades, and the procedural scene.
/// Modes: one-off (kdet::collide / collide_self: detector, objects and detection all timed) and frame by
/// frame (one Detector reused, every object's positions replaced each frame; the peer has nothing to keep).
///
/// usage: kdet_cpu_vs_cgal [--threads N] [--quick] [--cases REGEX] [--table FILE] [Google Benchmark flags]
///   --threads N    kdet's threads (default 2); the peer always runs on one
///   --quick        small cases only (for a smoke run)
///   --cases REGEX  only the cases whose names match (e.g. 'hand|soup 10k'); only those are built
///   --table FILE  also write the markdown table of medians and ratios to FILE
/// The table (stdout, after the benchmark output) uses the median of the repetitions when
/// --benchmark_repetitions is given, else the mean; a second table splits a one-off query and a reused Detector's frame by stage.

#include "peer.hpp"
#include "peer_cases.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <string>
#include <vector>

namespace {

using namespace kdet;
using bench::Peer;
using bench::PeerCase;

DetectorOptions kdet_options(int threads) {
    DetectorOptions options;
    options.threads = threads;
    options.narrow_phase = NarrowPhase::sat; // the peer's test, whatever the library's default
    return options;
}

std::vector<IndexPair> kdet_one_off(const PeerCase& c, int frame, int threads) {
    const std::vector<TetMesh>& objects = c.frames[static_cast<std::size_t>(frame)];
    return c.self ? collide_self(objects[0], kdet_options(threads)) : collide(objects[0], objects[1], kdet_options(threads));
}

std::vector<IndexPair> index_pairs(const FrameResult& result) {
    std::vector<IndexPair> pairs;
    pairs.reserve(result.pairs.size());
    for (const TetPair& p : result.pairs) pairs.emplace_back(p.tet_a, p.tet_b);
    return pairs;
}

/// A Detector holding the case's objects, positions to be set per frame.
std::unique_ptr<Detector> make_detector(const PeerCase& c, int threads) {
    auto detector = std::make_unique<Detector>(kdet_options(threads));
    for (const TetMesh& mesh : c.frames[0]) detector->set_self_collision(detector->add_object(mesh), c.self);
    return detector;
}

const FrameResult& detect_frame(Detector& detector, const PeerCase& c, std::size_t frame) {
    const std::vector<TetMesh>& objects = c.frames[frame];
    for (std::size_t o = 0; o < objects.size(); ++o)
        detector.set_positions(static_cast<ObjectId>(o), objects[o].positions.data(), objects[o].num_vertices());
    return detector.detect();
}

/// Every frame, one-off and frame by frame: kdet and the peer must agree exactly.
void check_same_pairs(const PeerCase& c, int threads) {
    Peer peer;
    auto detector = make_detector(c, threads);
    for (std::size_t f = 0; f < c.frames.size(); ++f) {
        const std::vector<IndexPair> expected = peer.collide(c.frames[f], c.self);
        const std::vector<IndexPair> one_off = kdet_one_off(c, static_cast<int>(f), threads);
        const std::vector<IndexPair> framed = index_pairs(detect_frame(*detector, c, f));
        if (one_off != expected || framed != expected) {
            std::fprintf(stderr, "%s frame %zu: kdet found %zu (one-off) / %zu (frame by frame) pairs, the peer %zu\n",
                         c.name.c_str(), f, one_off.size(), framed.size(), expected.size());
            std::exit(1);
        }
    }
}

void set_counters(benchmark::State& state, const PeerCase& c, std::size_t pairs) {
    state.counters["tets"] = static_cast<double>(c.tet_count());
    state.counters["pairs"] = static_cast<double>(pairs);
}

void register_case(const PeerCase& c, int threads) {
    const std::string base = c.name + "/";
    benchmark::RegisterBenchmark((base + "one-off/kdet").c_str(), [&c, threads](benchmark::State& state) {
        std::size_t pairs = 0;
        for (auto _ : state) pairs = kdet_one_off(c, 0, threads).size();
        set_counters(state, c, pairs);
    });
    benchmark::RegisterBenchmark((base + "one-off/peer").c_str(), [&c](benchmark::State& state) {
        std::size_t pairs = 0;
        for (auto _ : state) pairs = Peer().collide(c.frames[0], c.self).size();
        set_counters(state, c, pairs);
    });
    benchmark::RegisterBenchmark((base + "frames/kdet").c_str(), [&c, threads](benchmark::State& state) {
        auto detector = make_detector(c, threads);
        std::size_t frame = 0, pairs = 0;
        detect_frame(*detector, c, c.frames.size() - 1); // buffers sized as in a running simulation
        for (auto _ : state) {
            pairs = detect_frame(*detector, c, frame).counts.colliding_pairs;
            frame = (frame + 1) % c.frames.size();
        }
        set_counters(state, c, pairs);
    });
    benchmark::RegisterBenchmark((base + "frames/peer").c_str(), [&c](benchmark::State& state) {
        Peer peer;
        std::size_t frame = 0, pairs = 0;
        for (auto _ : state) {
            pairs = peer.collide(c.frames[frame], c.self).size();
            frame = (frame + 1) % c.frames.size();
        }
        set_counters(state, c, pairs);
    });
}

/// Where a frame's time goes, one-off and frame by frame: the first frame of a fresh Detector (what
/// kdet::collide runs), and a frame of one Detector reused as in the frames benchmark; each the run with
/// the median total of five, with its stage times, candidates and buffer regrowths.
std::string stage_table(const std::vector<PeerCase>& cases, int threads) {
    std::string out = "| case | mode | total ms | boxes | populate | candidates | narrow | sort | candidates found | "
                      "left by the pre-test | colliding | regrows |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    char line[512];
    const auto add_row = [&](const PeerCase& c, const char* mode, std::vector<FrameResult> runs) {
        std::sort(runs.begin(), runs.end(),
                  [](const FrameResult& a, const FrameResult& b) { return a.times.total < b.times.total; });
        const StageTimes& t = runs[runs.size() / 2].times;
        const FrameCounts& n = runs[runs.size() / 2].counts;
        std::snprintf(line, sizeof line, "| %s | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %llu | %llu | %llu | %u |\n",
                      c.name.c_str(), mode, t.total, t.bounding_boxes, t.populate_grid, t.find_candidates, t.narrow_phase,
                      t.sort_pairs, static_cast<unsigned long long>(n.candidates),
                      static_cast<unsigned long long>(n.narrow_phase_candidates),
                      static_cast<unsigned long long>(n.colliding_pairs), n.buffer_regrows);
        out += line;
    };
    for (const PeerCase& c : cases) {
        std::vector<FrameResult> one_off, frames;
        for (int r = 0; r < 5; ++r) one_off.push_back(detect_frame(*make_detector(c, threads), c, 0));
        add_row(c, "one-off", std::move(one_off));
        const auto detector = make_detector(c, threads);
        detect_frame(*detector, c, c.frames.size() - 1); // buffers sized as in the frames benchmark
        for (std::size_t r = 0; r < 5; ++r) frames.push_back(detect_frame(*detector, c, r % c.frames.size()));
        add_row(c, "frames", std::move(frames));
    }
    return out;
}

/// Collects each benchmark's time (median of the repetitions, or the mean) for the ratio table.
class TableReporter : public benchmark::ConsoleReporter {
public:
    void ReportRuns(const std::vector<Run>& runs) override {
        ConsoleReporter::ReportRuns(runs);
        for (const Run& run : runs) {
            const std::string name = run.run_name.str();
            const double ms = run.GetAdjustedRealTime() * 1e3 / benchmark::GetTimeUnitMultiplier(run.time_unit);
            if (run.run_type == Run::RT_Aggregate) {
                if (run.aggregate_name == "median") median_[name] = ms;
                continue;
            }
            auto& s = samples_[name];
            s.first += ms;
            s.second += 1;
            const auto tets = run.counters.find("tets");
            if (tets != run.counters.end()) tets_[name] = tets->second.value;
            const auto pairs = run.counters.find("pairs");
            if (pairs != run.counters.end()) pairs_[name] = pairs->second.value;
        }
    }

    double ms(const std::string& name) const {
        const auto m = median_.find(name);
        if (m != median_.end()) return m->second;
        const auto s = samples_.find(name);
        return s == samples_.end() ? -1.0 : s->second.first / s->second.second;
    }
    double counter(const std::map<std::string, double>& values, const std::string& name) const {
        const auto v = values.find(name);
        return v == values.end() ? 0.0 : v->second;
    }

    std::string table(const std::vector<PeerCase>& cases) const {
        std::string out = "| case | tets | pairs | mode | kdet ms | peer ms | peer / kdet |\n|---|---:|---:|---|---:|---:|---:|\n";
        char line[512];
        for (const PeerCase& c : cases)
            for (const char* mode : {"one-off", "frames"}) {
                const std::string k = c.name + "/" + mode + "/kdet", p = c.name + "/" + mode + "/peer";
                const double tk = ms(k), tp = ms(p);
                if (tk < 0.0 || tp < 0.0) continue;
                std::snprintf(line, sizeof line, "| %s | %.0f | %.0f | %s | %.2f | %.2f | %.1f |\n", c.name.c_str(),
                              counter(tets_, k), counter(pairs_, c.name + "/one-off/peer"), mode, tk, tp, tp / tk);
                out += line;
            }
        return out;
    }

private:
    std::map<std::string, std::pair<double, double>> samples_;
    std::map<std::string, double> median_, tets_, pairs_;
};

} // namespace

int main(int argc, char** argv) {
    int threads = 2;
    bool quick = false;
    std::string table_file, only = ".";
    std::vector<char*> rest{argv[0]};
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--threads" && i + 1 < argc) {
            threads = std::atoi(argv[++i]);
        } else if (arg == "--quick") {
            quick = true;
        } else if (arg == "--cases" && i + 1 < argc) {
            only = argv[++i];
        } else if (arg == "--table" && i + 1 < argc) {
            table_file = argv[++i];
        } else {
            rest.push_back(argv[i]);
        }
    }
    int rest_count = static_cast<int>(rest.size());
    benchmark::Initialize(&rest_count, rest.data());
    if (benchmark::ReportUnrecognizedArguments(rest_count, rest.data())) return 2;

    std::vector<PeerCase> cases;
    try {
        cases = bench::peer_cases(quick, std::regex(only));
    } catch (const Error& error) {
        std::fprintf(stderr, "kdet_cpu_vs_cgal: %s\n", error.what());
        return 1;
    } catch (const std::regex_error&) {
        std::fprintf(stderr, "kdet_cpu_vs_cgal: --cases '%s' is not a regular expression\n", only.c_str());
        return 2;
    }
    for (const PeerCase& c : cases) {
        check_same_pairs(c, threads);
        register_case(c, threads);
    }
    TableReporter reporter;
    benchmark::RunSpecifiedBenchmarks(&reporter);
    const std::string table = reporter.table(cases) + "\n" + stage_table(cases, threads);
    std::printf("\n%s", table.c_str());
    if (!table_file.empty()) std::ofstream(table_file) << table;
    benchmark::Shutdown();
    return 0;
}
