/// @file narrow_phase_report.cpp
/// @brief Prints, for every narrow-phase test, its CPU time per pair and its false positives and false
/// negatives against CGAL per margin bucket; for `exact`, also both argument orders, the pairs that
/// reached its exact stage per kind, and zero-volume pairs. The numbers in docs/narrow-phase.md come
/// from here.
///
/// Usage: narrow_phase_report [pairs per kind/size/offset combination, default 3000]
///                            [zero-volume pairs, default 20000]

#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "geometry/tet_intersect.hpp"
#include "narrow_cases.hpp"

namespace {

using kdet::NarrowPhase;
using namespace kdet::cgal_check;

constexpr NarrowPhase k_all_tests[] = {NarrowPhase::sat, NarrowPhase::sat_no_edges, NarrowPhase::sat_mtv,
                                       NarrowPhase::gjk, NarrowPhase::fast, NarrowPhase::exact};
constexpr long long k_timed_calls = 1000000;

/// @brief CPU time of this thread in nanoseconds: unlike wall time, not inflated when other processes
/// share the cores.
double thread_ns() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return 1e9 * static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec);
}

/// @brief Nanoseconds of thread CPU time per call of `test` over `pairs`, cycling through them for
/// about 1e6 calls (best of five rounds).
template <class Test>
double time_per_pair(Test test, const std::vector<const Case*>& pairs) {
    if (pairs.empty()) return 0.0;
    double best = 1e300;
    long long hits = 0;
    for (int round = 0; round < 5; ++round) {
        const double start = thread_ns();
        long long calls = 0;
        while (calls < k_timed_calls)
            for (const Case* c : pairs) {
                hits += test(c->a, c->b);
                ++calls;
            }
        best = std::min(best, (thread_ns() - start) / static_cast<double>(calls));
    }
    volatile long long observed = hits; // keeps the pure calls from being optimised away
    (void)observed;
    return best;
}

/// @brief Times each test called directly (not through the dispatch), so that each is inlined
/// into its own loop.
double time_per_pair(NarrowPhase test, const std::vector<const Case*>& pairs) {
    using kdet::vec3;
    switch (test) {
    case NarrowPhase::sat_no_edges: return time_per_pair(kdet::tets_intersect_sat_no_edges, pairs);
    case NarrowPhase::sat_mtv:
        return time_per_pair(
            [](const vec3 a[4], const vec3 b[4]) {
                float depth;
                vec3 direction;
                return kdet::tets_intersect_sat_mtv(a, b, depth, direction);
            },
            pairs);
    case NarrowPhase::gjk: return time_per_pair(kdet::tets_intersect_gjk, pairs);
    case NarrowPhase::fast: return time_per_pair(kdet::tets_intersect_fast, pairs);
    case NarrowPhase::exact:
        return time_per_pair([](const vec3 a[4], const vec3 b[4]) { return kdet::tets_intersect_exact(a, b); }, pairs);
    case NarrowPhase::sat: break;
    }
    return time_per_pair([](const vec3 a[4], const vec3 b[4]) { return kdet::tets_intersect_sat(a, b); }, pairs);
}

/// @brief exact in both argument orders against CGAL, per kind, with the pairs that reached its exact
/// stage; then zero-volume pairs against CGAL's polytope distance.
void exact_report(const std::vector<Case>& cases, int degenerate_count) {
    std::printf("\nexact, both argument orders, per kind: calls, disagreements with CGAL, calls that reached the "
                "exact stage (all, and among clear pairs):\n");
    long long total_calls = 0, total_wrong = 0, total_stage = 0;
    for (CaseKind kind : k_case_kinds) {
        long long calls = 0, wrong = 0, stage_calls = 0, clear = 0, clear_stage = 0;
        for (const Case& c : cases) {
            if (c.kind != kind) continue;
            for (int order = 0; order < 2; ++order) {
                bool stage = false;
                const bool got = order ? kdet::tets_intersect_exact(c.b, c.a, stage) : kdet::tets_intersect_exact(c.a, c.b, stage);
                ++calls;
                wrong += got != c.truth;
                stage_calls += stage;
                if (bucket_of(c.margin) == Bucket::clear) {
                    ++clear;
                    clear_stage += stage;
                }
            }
        }
        std::printf("  %-24s %9lld  wrong %lld  exact stage %8lld (%5.2f%%), clear pairs %7lld of %8lld (%.3f%%)\n",
                    case_kind_name(kind), calls, wrong, stage_calls, 100.0 * static_cast<double>(stage_calls) / static_cast<double>(calls),
                    clear_stage, clear, clear ? 100.0 * static_cast<double>(clear_stage) / static_cast<double>(clear) : 0.0);
        total_calls += calls;
        total_wrong += wrong;
        total_stage += stage_calls;
    }
    std::printf("  %-24s %9lld  wrong %lld  exact stage %8lld\n", "all", total_calls, total_wrong, total_stage);

    const std::vector<DegenerateCase> degenerate = generate_degenerate_cases(0x7a65726fu, degenerate_count);
    long long by_dimensions[4][4] = {}, wrong = 0, intersecting = 0, lattice = 0;
    for (const DegenerateCase& c : degenerate) {
        ++by_dimensions[c.dim_a][c.dim_b];
        intersecting += c.truth;
        lattice += c.lattice;
        wrong += (kdet::tets_intersect_exact(c.a, c.b) != c.truth) + (kdet::tets_intersect_exact(c.b, c.a) != c.truth);
    }
    std::printf("\nexact on %zu zero-volume pairs (%lld on lattices, %lld intersecting), both orders: %lld "
                "disagreements with CGAL's polytope distance. Pairs by hull dimension (rows: first tet):\n",
                degenerate.size(), lattice, intersecting, wrong);
    for (const auto& row : by_dimensions) std::printf("  %7lld %7lld %7lld %7lld\n", row[0], row[1], row[2], row[3]);
}

} // namespace

int main(int argc, char** argv) {
    const int per_combination = argc > 1 ? std::atoi(argv[1]) : 3000;
    const int degenerate_count = argc > 2 ? std::atoi(argv[2]) : 20000;
    std::printf("compiler: %s\n", __VERSION__);
    const std::vector<Case> cases = generate_cases(0x7265706f7274u, per_combination);

    long long bucket_count[k_bucket_count][2] = {};
    for (const Case& c : cases) ++bucket_count[static_cast<int>(bucket_of(c.margin))][c.truth];
    std::printf("\n%zu pairs (%d kinds x %d sizes x 4 offsets x %d), CGAL truth per bucket:\n", cases.size(),
                k_case_kind_count, k_size_count, per_combination);
    for (int b = 0; b < k_bucket_count; ++b)
        std::printf("  %-24s intersecting %7lld  separated %7lld\n", bucket_name(static_cast<Bucket>(b)),
                    bucket_count[b][1], bucket_count[b][0]);

    std::printf("\nErrors against CGAL (first tet first), false positives / false negatives:\n");
    std::printf("  %-12s", "test");
    for (int b = 0; b < k_bucket_count; ++b) std::printf(" | %-24s", bucket_name(static_cast<Bucket>(b)));
    std::printf("\n");
    for (NarrowPhase test : k_all_tests) {
        long long fp[k_bucket_count] = {}, fn[k_bucket_count] = {};
        for (const Case& c : cases) {
            const bool got = kdet::tets_intersect(test, c.a, c.b);
            if (got != c.truth) ++(got ? fp : fn)[static_cast<int>(bucket_of(c.margin))];
        }
        std::printf("  %-12s", kdet::to_string(test));
        for (int b = 0; b < k_bucket_count; ++b) std::printf(" | FP %7lld  FN %7lld    ", fp[b], fn[b]);
        std::printf("\n");
    }

    exact_report(cases, degenerate_count);

    std::printf("\nFalse positives of sat_no_edges on clear separated pairs, per kind:\n");
    for (CaseKind kind : k_case_kinds) {
        long long separated = 0, fp = 0;
        for (const Case& c : cases)
            if (c.kind == kind && !c.truth && bucket_of(c.margin) == Bucket::clear) {
                ++separated;
                fp += kdet::tets_intersect_sat_no_edges(c.a, c.b);
            }
        std::printf("  %-16s %6lld of %6lld (%.1f%%)\n", case_kind_name(kind), fp, separated,
                    separated ? 100.0 * static_cast<double>(fp) / static_cast<double>(separated) : 0.0);
    }

    // Timing sets: everything generated; random pairs whose boxes overlap (what the narrow phase sees
    // after the broad phase), and those split by the truth.
    constexpr int k_sets = 4;
    const char* set_names[k_sets] = {"all kinds", "random, boxes overlap", "  of which hit", "  of which miss"};
    std::vector<const Case*> sets[k_sets];
    for (const Case& c : cases) {
        sets[0].push_back(&c);
        if (c.kind != CaseKind::random || !kdet::boxes_overlap(kdet::tet_box(c.a), kdet::tet_box(c.b))) continue;
        sets[1].push_back(&c);
        sets[c.truth ? 2 : 3].push_back(&c);
    }
    std::printf("\nthread CPU time per pair in ns (~1e6 calls, best of 5):\n  %-24s %8s", "set", "pairs");
    for (NarrowPhase test : k_all_tests) std::printf(" %12s", kdet::to_string(test));
    std::printf("\n");
    for (int set = 0; set < k_sets; ++set) {
        std::printf("  %-24s %8zu", set_names[set], sets[set].size());
        for (NarrowPhase test : k_all_tests) std::printf(" %12.1f", time_per_pair(test, sets[set]));
        std::printf("\n");
    }
    return 0;
}
