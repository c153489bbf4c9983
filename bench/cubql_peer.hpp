#pragma once
/// @file cubql_peer.hpp
/// @brief The cuBQL peer's per-tet work, written once for its GPU program (gpu_vs_cubql.cu) and its
/// CPU program (cpu_vs_cubql.cpp): a tet's box, and one cuBQL fixedBoxQuery per tet into the BVH of
/// each object it is checked against, every candidate decided by kdet's own narrow phase (the exact
/// test, kdet's default), with kdet's rules: tets of one object that share a vertex are never reported,
/// pairs inside an object only in self mode, pairs between objects only where the scene checks them.
///
/// One BVH per object, not one over all tets: without self-collision a shared BVH would lead every
/// query through its own object's neighbours only to drop them. A tet of object a queries the BVHs of
/// the objects b >= a, and inside its own object keeps only the tets after it, so each pair is tested
/// and reported once, lower global id first.

#include "scene_frames.hpp"

#include "geometry/tet_intersect.hpp"

#include <cuBQL/bvh.h>
#include <cuBQL/traversal/fixedBoxQuery.h>

#include <cstdint>

namespace kdet::bench {

struct CubqlView {
    const vec3* positions;
    const TetIndices* tets;
    const std::uint32_t* tet_object;
    const std::uint32_t* tet_begin; ///< [object + 1], as SceneLayout
    const std::uint8_t* checked;    ///< [a * object_count + b], as SceneLayout
    const cuBQL::bvh3f* bvhs;       ///< [object]: over that object's boxes, primitive ids counted from its first tet
    const cuBQL::box3f* boxes;      ///< [tet]
    std::uint32_t object_count;
};

KDET_HD inline cuBQL::box3f cubql_box(const vec3* positions, const TetIndices& tet) {
    vec3 v[4];
    load_tet_vertices(positions, tet, v);
    const Aabb b = tet_box(v);
    cuBQL::box3f box;
    box.lower = cuBQL::vec3f(b.lo.x, b.lo.y, b.lo.z);
    box.upper = cuBQL::vec3f(b.hi.x, b.hi.y, b.hi.z);
    return box;
}

/// Calls found(t, u) for every colliding pair (t, u), t < u, that tet t reports (see the file comment).
template <class Found>
KDET_HD inline void query_tet(const CubqlView& v, std::uint32_t t, Found&& found) {
    const std::uint32_t a = v.tet_object[t];
    const TetIndices tet = v.tets[t];
    vec3 va[4];
    load_tet_vertices(v.positions, tet, va);
    for (std::uint32_t b = a; b < v.object_count; ++b) {
        if (!v.checked[a * v.object_count + b] || v.tet_begin[b] == v.tet_begin[b + 1]) continue;
        const std::uint32_t begin = v.tet_begin[b];
        const bool same = a == b;
        cuBQL::fixedBoxQuery::forEachPrim(
            [&](std::uint32_t prim) {
                const std::uint32_t u = begin + prim;
                if (same && (u <= t || share_vertex(tet, v.tets[u]))) return CUBQL_CONTINUE_TRAVERSAL;
                vec3 vb[4];
                load_tet_vertices(v.positions, v.tets[u], vb);
                if (tets_intersect_exact(va, vb)) found(t, u);
                return CUBQL_CONTINUE_TRAVERSAL;
            },
            v.bvhs[b], v.boxes[t]);
    }
}

/// Depth of a BVH (nodes on the longest path from the root), from its nodes in host memory: cuBQL's
/// traversal keeps a stack of 64 entries, which a deeper BVH could overrun.
inline int bvh_depth(const cuBQL::bvh3f::Node* nodes, std::uint64_t node = 0) {
    if (nodes[node].admin.count != 0) return 1;
    const std::uint64_t child = nodes[node].admin.offset;
    return 1 + std::max(bvh_depth(nodes, child), bvh_depth(nodes, child + 1));
}

} // namespace kdet::bench
