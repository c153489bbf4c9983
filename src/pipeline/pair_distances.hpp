#pragma once
/// @file pair_distances.hpp
/// @brief Stage 6 with DetectorOptions::distances: each reported pair's distance and a closest point
/// on each tet (tet_distance.hpp), parallel to the sorted pairs.

#include "geometry/tet_distance.hpp"
#include "geometry/tet_intersect.hpp"
#include "pipeline/narrow_phase.hpp"

#include <kdet/results.hpp>

#include <cstdint>

namespace kdet {

/// @brief Distance and closest points of each pair given in the caller's ids (`keys`, `key_count` of
/// them appended into a `window`), into `distances` and `closest_points`; the pair's first tet (the
/// lower id) is a. A pair the exact test finds intersecting gets 0 and a common point, whatever test
/// reported it. Nothing when the pairs outgrew their window (see ContactKernel).
struct DistanceKernel {
    SceneView scene;
    const std::uint32_t* stored_id; ///< [tets] caller's global id -> stored id
    const std::uint64_t* keys;
    const unsigned long long* key_count;
    std::uint64_t window;
    float* distances;
    ClosestPoints* closest_points;
    KDET_HD void operator()(std::uint64_t k) const {
        if (*key_count > window) return;
        vec3 a[4], b[4];
        load_key_tets(scene, stored_id, keys[k], a, b);
        bool exact_stage = false;
        const bool intersecting = tets_intersect_as<NarrowPhase::exact>(a, b, exact_stage);
        vec3 on_a, on_b;
        distances[k] = narrow::tets_distance(a, b, intersecting, on_a, on_b);
        closest_points[k] = ClosestPoints{{on_a.x, on_a.y, on_a.z}, {on_b.x, on_b.y, on_b.z}};
    }
};

} // namespace kdet
