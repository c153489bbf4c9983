#pragma once
/// @file near_pairs.hpp
/// @brief DetectorOptions::margin: the pairs that the narrow phase (or kdet_no_pairs' search) found
/// apart, decided against the margin exactly (tet_distance.hpp) by one kernel for every method and
/// narrow-phase test. The distance decision is large: called from each test's kernels it was compiled
/// into every one of them and took their registers, with or without a margin.

#include "exec/atomic.hpp"
#include "geometry/tet_distance.hpp"
#include "pipeline/pair_keys.hpp"
#include "pipeline/scene_view.hpp"

#include <cstdint>

namespace kdet {

/// @brief Decides near[k], a pair of stored tets (first < second) that does not intersect, or
/// no_pair_key for none: within the margin, both tets are flagged and, where `user_id` is given, the
/// pair is appended under the caller's ids as the narrow phase appends its pairs. Without `user_id`
/// (kdet_no_pairs, which only flags) a pair whose tets are both flagged already is skipped.
struct NearPairsKernel {
    SceneView scene;
    const std::uint64_t* near;
    std::uint32_t* colliding;     ///< per stored tet
    const std::uint32_t* user_id; ///< [tets] stored id -> caller's global id; null: flags only
    KeyAppender out;

    KDET_HD void operator()(std::uint64_t k) const {
        const std::uint64_t key = near[k];
        if (key == no_pair_key) return;
        const std::uint32_t t = key_first(key), u = key_second(key);
        if (!user_id && atomic_load_acquire(&colliding[t]) && atomic_load_acquire(&colliding[u])) return;
        vec3 a[4], b[4];
        load_tet(scene, t, a);
        load_tet(scene, u, b);
        // The search or the narrow phase tried the face planes with the margin on every listed pair
        // the grid brought (brute force's have none); repeating them rejects next to nothing.
        if (!narrow::disjoint_tets_within(a, b, scene.margin, false)) return;
        atomic_store_relaxed(&colliding[t], 1u);
        atomic_store_relaxed(&colliding[u], 1u);
        if (user_id) out.push(pair_key(user_id[t], user_id[u]));
    }
};

} // namespace kdet
