#pragma once
/// @file bounding_boxes.hpp
/// @brief Stage 1, bounding boxes: each tet's box, each object's box, and which pairs of objects are
/// checked this frame.

#include "exec/atomic.hpp"
#include "grid/bucket_table.hpp"
#include "pipeline/scene_view.hpp"

#include <cfloat>
#include <cmath>
#include <cstdint>

namespace kdet {

/// @brief At least half of `margin`: what each side of a tet's box grows by.
KDET_HD inline float half_margin(float margin) {
    const float half = 0.5f * margin;
    return half + half < margin ? next_float_up(half) : half;
}

/// @brief `box` grown by `half` on every side, each bound rounded outward (and kept finite): two tets
/// at most 2 half apart have overlapping grown boxes, since along every axis their boxes are at most
/// that apart.
KDET_HD inline Aabb grown_box(const Aabb& box, float half) {
    const auto down = [half](float x) { return max_f(next_float_down(x - half), -FLT_MAX); };
    const auto up = [half](float x) { return min_f(next_float_up(x + half), FLT_MAX); };
    return Aabb{{down(box.lo.x), down(box.lo.y), down(box.lo.z)}, {up(box.hi.x), up(box.hi.y), up(box.hi.z)}};
}

/// @brief Stage 1: box of each tet, grown by half the margin; no size and no layer yet.
struct TetBoundsKernel {
    SceneView scene;
    KDET_HD void operator()(std::uint64_t t) const {
        vec3 v[4];
        load_tet(scene, static_cast<std::uint32_t>(t), v);
        const Aabb box = tet_box(v);
        scene.info[t] = TetInfo{scene.margin > 0.0f ? grown_box(box, half_margin(scene.margin)) : box, 0.0f, -1};
    }
};

/// @brief Stage 1: the box of tet t, the value the per-object box reduction merges.
struct TetBoxOf {
    const TetInfo* info;
    KDET_HD Aabb operator()(std::uint64_t t) const { return info[t].box; }
};

/// @brief The smallest box holding two boxes.
struct BoxUnion {
    KDET_HD Aabb operator()(const Aabb& a, const Aabb& b) const { return Aabb{min_v(a.lo, b.lo), max_v(a.hi, b.hi)}; }
};

/// @brief Stage 1: puts the box of each run of tets (one run per non-empty object: its tets are
/// contiguous) at its object's place.
struct ObjectBoxesKernel {
    const std::uint32_t* run_objects;
    const Aabb* run_boxes;
    const std::uint32_t* run_count;
    Aabb* object_boxes;
    KDET_HD void operator()(std::uint64_t r) const {
        if (r < *run_count) object_boxes[run_objects[r]] = run_boxes[r];
    }
};

/// @brief A box as order-preserving integers (float_to_ordered), so that threads can merge boxes atomically.
struct OrderedBox {
    std::uint32_t lo[3], hi[3];
};

/// @brief Stage 1, one work item per object a: which pairs (a, b) are checked this frame (enabled,
/// both objects hold tets, their boxes overlap; the diagonal is self-collision), where a's box meets
/// those of the other objects it is checked against (SceneView::meeting_boxes), and, when a is in
/// one, its box merged into the region the grid covers and its tets counted. No tets counted: nothing
/// can collide, and every later stage finds nothing to do.
struct ObjectCullingKernel {
    const std::uint8_t* pair_enabled; ///< [object_count * object_count]
    std::uint8_t* pair_active;
    std::uint32_t* checked_objects; ///< [object_count] SceneView::checked_objects
    const Aabb* object_boxes;
    Aabb* meeting_boxes; ///< [object_count] SceneView::meeting_boxes
    const std::uint32_t* object_tet_begin; ///< [object_count + 1]
    std::uint32_t object_count;
    OrderedBox* region;
    unsigned long long* involved_tets;

    KDET_HD void operator()(std::uint64_t a) const {
        const std::uint32_t tets = object_tet_begin[a + 1] - object_tet_begin[a];
        bool involved = false;
        std::uint32_t checked = 0;
        const float inf = INFINITY;
        Aabb meeting{{inf, inf, inf}, {-inf, -inf, -inf}};
        for (std::uint32_t b = 0; b < object_count; ++b) {
            const std::uint64_t k = a * object_count + b;
            const bool on = tets && object_tet_begin[b + 1] != object_tet_begin[b] && pair_enabled[k] &&
                            (a == b || boxes_overlap(object_boxes[a], object_boxes[b]));
            pair_active[k] = on ? 1 : 0;
            if (on) checked |= object_bit(b);
            if (on && a != b) meeting = box_union(meeting, box_intersection(object_boxes[a], object_boxes[b]));
            involved = involved || on;
        }
        meeting_boxes[a] = meeting;
        // Checked against every object, a tet filters none: any_object spares its scans the blocks' objects.
        checked_objects[a] = checked == all_object_bits(object_count) ? any_object : checked;
        if (!involved) return;
        const Aabb& box = object_boxes[a];
        for (int axis = 0; axis < 3; ++axis) {
            atomic_min(&region->lo[axis], float_to_ordered(component(box.lo, axis)));
            atomic_max(&region->hi[axis], float_to_ordered(component(box.hi, axis)));
        }
        atomic_fetch_add(involved_tets, static_cast<unsigned long long>(tets));
    }
};

} // namespace kdet
