#pragma once
/// @file nearest_tree.hpp
/// @brief A tree of boxes over a run of stored tets, for the tets nearest a point. A leaf holds
/// `nearest_leaf_tets` consecutive stored tets (an object's tets are stored close in space,
/// spatial_order.hpp), and each node above is the box of two neighbours of the level below. The shape
/// is implicit (node i of a level has children 2i and 2i + 1 below it): it is built one level at a
/// time, one pass each, the same on every backend, and deforming tets only change its boxes.
///
/// A search descends into the nearer child first and skips a node whose box lies farther than a
/// bound the visitor may lower as it goes (the best distance so far): its cost follows the tets near
/// the point, not how far the search may reach.

#include "geometry/dvec3.hpp"
#include "geometry/vec3.hpp"
#include "pipeline/scene_view.hpp"

#include <cstdint>

namespace kdet {

constexpr std::uint32_t nearest_leaf_tets = 4;
/// Levels of a tree over up to 2^32 tets, and room for the nearer-first search's pending nodes (at
/// most one per level).
constexpr int nearest_tree_levels = 32;

/// @brief The tree's boxes as the kernels read them: level 0 (the leaves) from level_begin[0], the
/// root alone on level levels - 1.
struct NearestTreeView {
    const Aabb* boxes;
    std::uint32_t level_begin[nearest_tree_levels + 1];
    int levels; ///< 0: no tets
    std::uint32_t first; ///< stored id of the tree's tet 0
    std::uint32_t count;
};

/// @brief The nodes of each level, from `count` tets: the levels' first boxes and how many there are.
inline int nearest_tree_shape(std::uint32_t count, std::uint32_t level_begin[nearest_tree_levels + 1]) {
    std::uint64_t nodes = (std::uint64_t{count} + nearest_leaf_tets - 1) / nearest_leaf_tets, begin = 0;
    int levels = 0;
    level_begin[0] = 0;
    while (nodes > 0) {
        begin += nodes;
        level_begin[++levels] = static_cast<std::uint32_t>(begin);
        if (nodes == 1) break;
        nodes = (nodes + 1) / 2;
    }
    return levels;
}

/// @brief Per leaf: the box of its tets.
struct NearestLeafBoxesKernel {
    const vec3* positions;
    const TetIndices* tets;
    std::uint32_t first, count;
    Aabb* leaves;
    KDET_HD void operator()(std::uint64_t k) const {
        const std::uint64_t begin = k * nearest_leaf_tets;
        const std::uint64_t end = begin + nearest_leaf_tets < count ? begin + nearest_leaf_tets : count;
        Aabb box{};
        for (std::uint64_t t = begin; t < end; ++t) {
            vec3 v[4];
            for (int i = 0; i < 4; ++i) v[i] = positions[tets[first + t].v[i]];
            box = t == begin ? tet_box(v) : box_union(box, tet_box(v));
        }
        leaves[k] = box;
    }
};

/// @brief Per node of a level: the box of its one or two children on the level below.
struct NearestParentBoxesKernel {
    const Aabb* below;
    std::uint32_t below_count;
    Aabb* level;
    KDET_HD void operator()(std::uint64_t i) const {
        const std::uint64_t child = 2 * i;
        level[i] = child + 1 < below_count ? box_union(below[child], below[child + 1]) : below[child];
    }
};

/// @brief The squared distance from p to a box (0 inside it), in double.
KDET_HD inline double squared_distance_to_box(const Aabb& b, const narrow::dvec3& p) {
    const double lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z}, q[3] = {p.x, p.y, p.z};
    double sum = 0.0;
    for (int a = 0; a < 3; ++a) {
        const double d = q[a] < lo[a] ? lo[a] - q[a] : q[a] > hi[a] ? q[a] - hi[a] : 0.0;
        sum += d * d;
    }
    return sum;
}

/// @brief Calls visit(stored tet) for the tets of each leaf whose box is within reach() of p, nearer
/// children first; reach() is read again before each node, so a visit that lowers it prunes the rest.
template <class Reach, class Visit>
KDET_HD inline void for_each_tet_within_reach(const NearestTreeView& tree, const narrow::dvec3& p, Reach&& reach, Visit&& visit) {
    if (tree.levels == 0) return;
    const auto within_reach = [&](double squared) {
        const double r = reach();
        return squared <= r * r;
    };
    struct Pending {
        double squared;
        std::uint32_t node;
        int level;
    };
    Pending stack[nearest_tree_levels];
    int pending = 0;
    const int root_level = tree.levels - 1;
    const double root = squared_distance_to_box(tree.boxes[tree.level_begin[root_level]], p);
    if (within_reach(root)) stack[pending++] = Pending{root, 0, root_level};
    while (pending > 0) {
        Pending at = stack[--pending];
        // Down the nearer child; the farther waits on the stack (one per level at most).
        while (at.level > 0 && within_reach(at.squared)) {
            const int below = at.level - 1;
            const std::uint32_t nodes = tree.level_begin[below + 1] - tree.level_begin[below];
            const std::uint32_t left = 2 * at.node, right = left + 1;
            const double to_left = squared_distance_to_box(tree.boxes[tree.level_begin[below] + left], p);
            if (right >= nodes) {
                at = Pending{to_left, left, below};
                continue;
            }
            const double to_right = squared_distance_to_box(tree.boxes[tree.level_begin[below] + right], p);
            const bool left_first = to_left <= to_right;
            const Pending far{left_first ? to_right : to_left, left_first ? right : left, below};
            if (within_reach(far.squared)) stack[pending++] = far;
            at = Pending{left_first ? to_left : to_right, left_first ? left : right, below};
        }
        if (at.level > 0 || !within_reach(at.squared)) continue;
        const std::uint64_t begin = std::uint64_t{at.node} * nearest_leaf_tets;
        const std::uint64_t end = begin + nearest_leaf_tets < tree.count ? begin + nearest_leaf_tets : tree.count;
        for (std::uint64_t t = begin; t < end; ++t) visit(tree.first + static_cast<std::uint32_t>(t));
    }
}

} // namespace kdet
