#pragma once
/// @file narrow_phase.hpp
/// @brief Stage 4, narrow phase: each candidate decided once, the colliding pairs appended under the
/// caller's ids; then each colliding pair's contact and the per-tet flags in the caller's numbering.

#include "exec/atomic.hpp"
#include "geometry/tet_intersect.hpp"
#include "pipeline/pair_keys.hpp"
#include "pipeline/pair_tests.hpp"
#include "pipeline/scene_view.hpp"

#include <kdet/options.hpp>
#include <kdet/results.hpp>

#include <cstdint>

namespace kdet {

/// @brief Stage 5: decides each candidate once (a no_pair_key slot is none), flags colliding tets and
/// appends each colliding pair under the caller's tet ids (lower id first; sorted afterwards, so
/// the order of appends does not matter). A proven_pair_key collides (the candidate search's pre-test
/// proved it); every other pair, which the pre-test left undecided or never saw (brute force), gets
/// the test, after the face planes with FacePlanesHere (the search did not run them: rejections are
/// counted in `rejected`). Work item i decides keys [i KeysPerItem, (i + 1) KeysPerItem) of the first
/// min(*key_count, key_capacity): with more than one, its pairs are appended a batch at a time (one
/// atomic per batch where every pair would take one, all on the same counter). With a margin, `near`
/// (parallel to the keys) gets each key's pair of stored tets that the test found apart, no_pair_key
/// for every other key (the planes' separations lie beyond the margin): NearPairsKernel decides those against the margin.
template <NarrowPhase Test, std::uint32_t KeysPerItem, bool FacePlanesHere>
struct NarrowPhaseKernel {
    SceneView scene;
    const std::uint64_t* keys;
    const unsigned long long* key_count;
    std::uint64_t key_capacity;
    std::uint32_t* colliding;
    const std::uint32_t* user_id; ///< [tets] stored id -> caller's global id
    KeyAppender out;
    unsigned long long* exact_stage_pairs;
    unsigned long long* rejected; ///< with FacePlanesHere: the pairs the face planes proved separated
    std::uint64_t* near;          ///< [key_capacity] where the scene has a margin, else null

    /// @brief Decides key k; true, with the pair under the caller's ids, when it collides. Counts a
    /// pair the face planes proved separated in `planes_rejected`.
    KDET_HD bool decide(std::uint64_t k, std::uint64_t& pair, unsigned long long& planes_rejected) const {
        if (keys[k] == no_pair_key) return keep_near(k, no_pair_key);
        const std::uint32_t a = key_first(keys[k]), b = key_second(keys[k]);
        const std::uint32_t t = a < b ? a : b, u = a < b ? b : a;
        bool reached_exact = false;
        bool collides = a > b, planes_separate = false;
        if (!collides) {
            // Edge axes first: the pre-test left this pair undecided, or brute force found it colliding
            // (every axis runs then anyway).
            if constexpr (FacePlanesHere) {
                collides = planes_or_test_collide<Test>(scene, t, u, reached_exact, planes_separate);
                planes_rejected += planes_separate ? 1u : 0u;
            } else {
                collides = test_pair<Test>(scene, t, u, reached_exact, true);
            }
        }
        if (reached_exact) atomic_fetch_add(exact_stage_pairs, 1ull); // rare: one atomic per such pair
        // A pair the planes separate lies farther apart than the margin: nothing to decide.
        if (!collides) return keep_near(k, planes_separate ? no_pair_key : pair_key(t, u));
        keep_near(k, no_pair_key);
        atomic_store_relaxed(&colliding[t], 1u);
        atomic_store_relaxed(&colliding[u], 1u);
        pair = pair_key(user_id[t], user_id[u]);
        return true;
    }

    /// @brief Writes key k's near pair where there is a near list; false (no pair to append).
    KDET_HD bool keep_near(std::uint64_t k, std::uint64_t pair) const {
        if (near) near[k] = pair;
        return false;
    }

    KDET_HD void operator()(std::uint64_t item) const {
        std::uint64_t pair = 0;
        unsigned long long planes_rejected = 0;
        if constexpr (KeysPerItem == 1) {
            if (decide(item, pair, planes_rejected)) out.push(pair);
        } else {
            const std::uint64_t count = *key_count < key_capacity ? *key_count : key_capacity;
            const std::uint64_t begin = item * KeysPerItem;
            const std::uint64_t end = count - begin < KeysPerItem ? count : begin + KeysPerItem;
            KeyBatch batch(&out);
            for (std::uint64_t k = begin; k < end; ++k)
                if (decide(k, pair, planes_rejected)) batch.push(pair);
            batch.flush();
        }
        if (FacePlanesHere && planes_rejected) atomic_fetch_add_gathered(rejected, planes_rejected);
    }
};

/// @brief The two tets of a pair key in the caller's ids: a the first (lower id), b the second.
KDET_HD inline void load_key_tets(const SceneView& scene, const std::uint32_t* stored_id, std::uint64_t key, vec3 a[4],
                                  vec3 b[4]) {
    load_tet(scene, stored_id[key_first(key)], a);
    load_tet(scene, stored_id[key_second(key)], b);
}

/// @brief Stage 6: contact of each colliding pair given in the caller's ids; tet b is the pair's second.
/// Nothing when the pairs outgrew their window: a batch that did not fit left its slots unwritten
/// (they hold no pair, maybe no valid id), and the narrow phase runs again with a larger window.
struct ContactKernel {
    SceneView scene;
    const std::uint32_t* stored_id; ///< [tets] caller's global id -> stored id
    const std::uint64_t* keys;
    const unsigned long long* key_count; ///< the pairs appended, counted past the window's end
    std::uint64_t window;
    Contact* contacts;
    KDET_HD void operator()(std::uint64_t k) const {
        if (*key_count > window) return;
        vec3 a[4], b[4];
        load_key_tets(scene, stored_id, keys[k], a, b);
        float depth = 0.0f;
        vec3 direction{0.0f, 0.0f, 0.0f};
        tets_intersect_sat_mtv(a, b, depth, direction);
        contacts[k] = Contact{depth, {direction.x, direction.y, direction.z}};
    }
};

/// @brief Stage 6: per-tet colliding flags in the caller's numbering.
struct UserFlagsKernel {
    const std::uint32_t* stored_id; ///< [tets] caller's global id -> stored id
    const std::uint32_t* colliding; ///< per stored tet
    std::uint32_t* user_colliding;
    KDET_HD void operator()(std::uint64_t i) const { user_colliding[i] = colliding[stored_id[i]]; }
};

} // namespace kdet
