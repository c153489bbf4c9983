#pragma once
/// @file scene_view.hpp
/// @brief The scene as the kernels of every stage see it: the tets, their per-frame data and which
/// objects are checked against which. Written once for both backends (KDET_HD); views hold raw
/// pointers and counts only.

#include "geometry/face_planes.hpp"
#include "geometry/slabs.hpp"
#include "geometry/vec3.hpp"

#include <cstdint>

namespace kdet {

struct TetIndices {
    std::uint32_t v[4]; ///< global vertex ids (object offsets applied)
};

/// @brief Per-tet data recomputed every frame.
struct TetInfo {
    Aabb box;
    /// Of the minimum enclosing sphere, for relevant tets only (TetSizeKernel); a negative value is
    /// minus the tet's longest edge instead, which bounds it (sphere_diameter_bounds), for a tet whose
    /// sphere TetSizeKernel left to GridPlanKernel (tet_layer).
    float diameter;
    std::int32_t layer; ///< grid layer, or -1 when the tet cannot collide with anything enabled
};

/// @brief All objects' geometry, concatenated; tets of one object are contiguous.
struct SceneView {
    const vec3* positions;
    const TetIndices* tets;
    const std::uint32_t* tet_object;
    TetInfo* info;
    TetPlanes* planes; ///< per tet, for the pre-test; computed for the tets that can collide this frame
    /// Per tet, for the pre-test, computed with the planes; null where the narrow phase's test may call
    /// far-apart pairs intersecting (sat_no_edges, see slabs.hpp): no pair is rejected by them then.
    TetSlabs* slabs;
    const std::uint8_t* pair_active; ///< [object_count * object_count]; diagonal = self-collision
    /// [object_count] object_bit of every object a is checked against; any_object when that is all of them
    const std::uint32_t* checked_objects;
    /// [object_count] the smallest box holding where an object's box meets the box of each other object
    /// it is checked against (empty, lo above hi, when there is none): a tet whose box misses it
    /// cannot meet another object's tet.
    const Aabb* meeting_boxes;
    std::uint32_t tet_count;
    std::uint32_t object_count;
    /// [tet_count + 1] where each tet's excluded partners start in `excluded` (pair_exclusions.hpp), or
    /// null when no pair is excluded beyond shared vertices.
    const std::uint32_t* exclusion_begin;
    const std::uint32_t* excluded;
    /// DetectorOptions::margin: boxes grown by half of it, sizes by all of it, pairs within it reported.
    float margin = 0.0f;
};

KDET_HD inline void load_vertices(const SceneView& s, const TetIndices& tet, vec3 out[4]) {
    for (int k = 0; k < 4; ++k) out[k] = s.positions[tet.v[k]];
}

KDET_HD inline void load_tet(const SceneView& s, std::uint32_t t, vec3 out[4]) { load_vertices(s, s.tets[t], out); }

/// @brief A tet's four vertex indices, each repeated over four lanes (row k holds vertex k): made once
/// for a tet compared with many, so that each comparison reads the other tet's indices as one vector.
struct SpreadIndices {
    std::uint32_t v[4][4];
};

KDET_HD inline SpreadIndices spread_indices(const TetIndices& a) {
    SpreadIndices s;
    for (int k = 0; k < 4; ++k)
        for (int i = 0; i < 4; ++i) s.v[k][i] = a.v[k];
    return s;
}

/// @brief Whether two tets share a vertex: all 16 comparisons without a branch each (in a mesh many of
/// the pairs tested share one, and which do is unpredictable, so early exits mispredict); on the CPU
/// b's four vertices are compared with each of a's in one vector compare.
KDET_HD inline bool share_vertex(const SpreadIndices& a, const TetIndices& b) {
    std::uint32_t lane[4];
    KDET_VECTOR_LOOP
    for (int i = 0; i < 4; ++i)
        lane[i] = (b.v[i] == a.v[0][i] ? ~0u : 0u) | (b.v[i] == a.v[1][i] ? ~0u : 0u) |
                  (b.v[i] == a.v[2][i] ? ~0u : 0u) | (b.v[i] == a.v[3][i] ? ~0u : 0u);
    return lane_bits(lane) != 0;
}

KDET_HD inline bool share_vertex(const TetIndices& a, const TetIndices& b) { return share_vertex(spread_indices(a), b); }

KDET_HD inline bool pair_is_active(const SceneView& s, std::uint32_t object_a, std::uint32_t object_b) {
    return s.pair_active[static_cast<std::uint64_t>(object_a) * s.object_count + object_b] != 0;
}

/// @brief Sets every element of a buffer to one value.
template <class T>
struct FillKernel {
    T* data;
    T value;
    KDET_HD void operator()(std::uint64_t i) const { data[i] = value; }
};

} // namespace kdet
