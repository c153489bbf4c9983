#pragma once
/// @file baseline_kernels.hpp
/// @brief The kernels of the thesis's baselines (Method::kdet_no_pairs, brute_force_loop,
/// brute_force_pairs), which BaselinePipeline runs in place of kdet's candidate search.

#include "exec/atomic.hpp"
#include "pipeline/candidate_search.hpp"
#include "pipeline/pair_keys.hpp"
#include "pipeline/pair_tests.hpp"
#include "pipeline/scene_view.hpp"

#include <kdet/options.hpp>

#include <cmath>
#include <cstdint>

namespace kdet {

/// @brief The brute-force methods' predicate: adjacency, boxes, then the test itself, without the
/// pre-test, so that they stay the oracle the grid methods (which use it) are compared with. With a
/// margin every pair whose grown boxes overlap passes too: the narrow phase tests it again and hands
/// it to NearPairsKernel where it does not intersect.
template <NarrowPhase Test>
KDET_HD inline bool tets_collide_tested(const SceneView& s, std::uint32_t t, std::uint32_t u, bool& exact_stage) {
    const std::uint32_t first = t < u ? t : u, second = t < u ? u : t;
    return may_collide(s, first, second) && (test_pair<Test>(s, first, second, exact_stage) || s.margin > 0.0f);
}

/// @brief The thesis's old method (algorithm 4.2): test inline and only flag colliding tets,
/// skipping a pair when both tets are already flagged. An item searches a run of TetsPerItem tets
/// (TetRuns) and adds its counts once. With a margin, each pair tested and found apart is appended
/// to `near` (stored tets, lower first; an overflow reruns the stage with more room), which
/// NearPairsKernel decides.
template <NarrowPhase Test, std::uint32_t TetsPerItem>
struct NoPairsKernel {
    SceneView scene;
    GridView grid;
    const GridParams* params;        ///< GridParamsKernel's
    const std::uint32_t* layer_mask; ///< GridPlanKernel's
    std::uint32_t* colliding;
    unsigned long long* tests_run;
    unsigned long long* exact_stage_pairs;
    KeyAppender near;

    struct TestAndFlag {
        const NoPairsKernel* kernel;
        std::uint32_t t;
        unsigned long long tests;
        unsigned long long exact_stage;
        KDET_HD void operator()(const GridEntry& e) {
            const std::uint32_t u = e.id();
            std::uint32_t* flags = kernel->colliding;
            if (atomic_load_acquire(&flags[t]) && atomic_load_acquire(&flags[u])) return;
            ++tests;
            const std::uint32_t first = t < u ? t : u, second = t < u ? u : t;
            bool reached_exact = false;
            if (may_collide(kernel->scene, first, second)) {
                if (candidate_collides<Test>(kernel->scene, first, second, reached_exact)) {
                    atomic_store_relaxed(&flags[t], 1u);
                    atomic_store_relaxed(&flags[u], 1u);
                } else if (kernel->scene.margin > 0.0f) {
                    kernel->near.push(pair_key(first, second));
                }
            }
            exact_stage += reached_exact;
        }
        KDET_HD bool finished() const { return false; }
    };

    KDET_HD void operator()(std::uint64_t i) const {
        TestAndFlag visit{this, 0, 0, 0};
        TetRuns<TetsPerItem>::for_each_tet(static_cast<std::uint32_t>(i), scene.tet_count, [&](std::uint32_t t) {
            visit.t = t;
            search(visit);
            return true;
        });
        if (visit.tests) atomic_fetch_add(tests_run, visit.tests);
        if (visit.exact_stage) atomic_fetch_add(exact_stage_pairs, visit.exact_stage);
    }

    /// @brief The search of tet visit.t, its tests and exact stages added to visit's counts.
    KDET_HD void search(TestAndFlag& visit) const {
        const GridParams grid_params = *params;
        for_each_larger_neighbour(scene, grid, grid_params, *layer_mask, visit.t, visit);
    }
};

/// @brief Brute force, one work item per tet: tests it against every later tet it may collide with.
template <NarrowPhase Test>
struct BruteForceLoopKernel {
    SceneView scene;
    const std::uint32_t* object_tet_begin; ///< [object_count + 1]
    KeyAppender out;
    unsigned long long* exact_stage_pairs;

    KDET_HD void operator()(std::uint64_t i) const {
        const auto t = static_cast<std::uint32_t>(i);
        const std::uint32_t object = scene.tet_object[t];
        KeyBatch batch(&out);
        unsigned long long exact_stage = 0;
        for (std::uint32_t other = object; other < scene.object_count; ++other) {
            if (!pair_is_active(scene, object, other)) continue;
            const std::uint32_t begin = other == object ? t + 1 : object_tet_begin[other];
            for (std::uint32_t u = begin; u < object_tet_begin[other + 1]; ++u) {
                bool reached_exact = false;
                if (tets_collide_tested<Test>(scene, t, u, reached_exact)) batch.push(pair_key(t, u));
                exact_stage += reached_exact;
            }
        }
        batch.flush();
        if (exact_stage) atomic_fetch_add(exact_stage_pairs, exact_stage);
    }
};

/// @brief Brute force, one work item per pair. Work is laid out in blocks, one per active object
/// pair; a self block enumerates i < j row by row.
template <NarrowPhase Test>
struct BruteForcePairsKernel {
    SceneView scene;
    const std::uint32_t* object_tet_begin; ///< [object_count + 1]
    const std::uint64_t* block_begin;      ///< [block_count + 1] work offsets
    const std::uint32_t* block_objects;    ///< [2 * block_count]
    std::uint32_t block_count;
    KeyAppender out;
    unsigned long long* exact_stage_pairs;

    KDET_HD void operator()(std::uint64_t work) const {
        std::uint32_t b = 0;
        while (b + 1 < block_count && block_begin[b + 1] <= work) ++b;
        const std::uint64_t r = work - block_begin[b];
        const std::uint32_t oa = block_objects[2 * b], ob = block_objects[2 * b + 1];
        std::uint64_t i, j;
        if (oa == ob) {
            const std::uint64_t n = object_tet_begin[oa + 1] - object_tet_begin[oa];
            // Row i holds n-1-i pairs; invert the row offsets with a square root, then fix rounding.
            const double m = 2.0 * static_cast<double>(n) - 1.0;
            double guess = (m - sqrt(m * m - 8.0 * static_cast<double>(r))) * 0.5;
            i = guess > 0.0 ? static_cast<std::uint64_t>(guess) : 0;
            auto row_start = [n](std::uint64_t row) { return row * (2 * n - row - 1) / 2; };
            while (i > 0 && row_start(i) > r) --i;
            while (row_start(i + 1) <= r) ++i;
            j = i + 1 + (r - row_start(i));
        } else {
            const std::uint64_t nb = object_tet_begin[ob + 1] - object_tet_begin[ob];
            i = r / nb;
            j = r % nb;
        }
        const auto t = static_cast<std::uint32_t>(object_tet_begin[oa] + i);
        const auto u = static_cast<std::uint32_t>(object_tet_begin[ob] + j);
        bool reached_exact = false;
        if (tets_collide_tested<Test>(scene, t, u, reached_exact)) out.push(pair_key(t, u));
        if (reached_exact) atomic_fetch_add(exact_stage_pairs, 1ull);
    }
};

} // namespace kdet
