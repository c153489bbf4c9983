#pragma once
/// @file candidate_bound.hpp
/// @brief A lower bound on a frame's candidate pairs, found in time linear in the gridded tets from the
/// grid's lists, so that a first frame whose candidates the memory cannot hold is refused before its
/// search counts them one pair at a time (the pre-test of every pair, where they all overlap).
///
/// Tets that hold a common point intersect: no pre-test separates them (the slabs and the face planes
/// prove only true gaps), their boxes overlap, and the search writes every such pair of one layer that
/// it does not leave out (adjacent within an object, excluded, objects not checked against each other).
/// A gridded tet starts (GridEntry::starts on all three axes) in exactly one cell of its layer, so the
/// sets of tets that start in each cell are disjoint, and a pair within one of them is counted by that
/// cell alone. In each cell the tets starting there that hold the centroid of the first of them
/// (decided exactly: point_query::tet_holds_point) are counted per object, and every pair of them
/// whose objects are checked against each other counts, less what the left-out pairs could remove:
/// for a tet, at most the other tets sharing one of its vertices (from the vertices' valences) and the
/// partners its exclusion list names (each excluded pair is listed under its lower tet only).

#include "exec/atomic.hpp"
#include "geometry/point_tet.hpp"
#include "grid/bucket_table.hpp"
#include "pipeline/scene_view.hpp"

#include <cstdint>

namespace kdet {

/// @brief Objects per cell that the bound counts: tets of one object are contiguous in the sorted
/// lists, and the pairs of the objects after these are left out (which keeps it a lower bound).
constexpr std::uint32_t candidate_bound_objects = 8;

/// @brief Counts, per vertex, the tets that use it (a tet naming a vertex twice counts twice, which
/// only lowers the bound).
struct VertexValenceKernel {
    const TetIndices* tets;
    std::uint32_t* valence;
    KDET_HD void operator()(std::uint64_t t) const {
        for (int k = 0; k < 4; ++k) atomic_fetch_add(&valence[tets[t].v[k]], 1u);
    }
};

/// @brief One work item per claimed cell: adds to `bound` the candidate pairs that the cell's tets
/// holding a common point make at least (see the file comment).
struct CellCandidateBoundKernel {
    SceneView scene;
    GridView grid;
    const std::uint32_t* valence; ///< VertexValenceKernel's
    unsigned long long* bound;

    /// Whether the search pairs tets of objects a and b, whichever of them it starts from.
    KDET_HD bool checked(std::uint32_t a, std::uint32_t b) const {
        return pair_is_active(scene, a, b) && pair_is_active(scene, b, a);
    }

    KDET_HD void operator()(std::uint64_t i) const {
        // A grid that failed to fill has partly unwritten lists; its frame fills it again.
        if (*grid.failure || i >= *grid.cells_claimed) return;
        const BucketHeader& cell = grid.headers[grid.claimed_slots[i]];
        std::uint32_t object[candidate_bound_objects], held[candidate_bound_objects];
        unsigned long long adjacent[candidate_bound_objects];
        unsigned long long excluded = 0;
        std::uint32_t objects = 0;
        vec3 point{};
        bool have_point = false;
        for (std::uint32_t k = cell.first_entry, end = cell.first_entry + cell.count; k < end; ++k) {
            const std::uint32_t tagged = entry_id_and_starts(grid, k);
            if ((tagged >> grid_id_bits) != 7u) continue;
            const std::uint32_t t = tagged & grid_id_mask;
            vec3 v[4];
            load_tet(scene, t, v);
            if (!have_point) {
                point = (v[0] + v[1] + v[2] + v[3]) * 0.25f;
                have_point = true;
            }
            point_query::PointTetSigns signs;
            if (!point_query::tet_holds_point(v, point, signs)) continue;
            const std::uint32_t o = scene.tet_object[t];
            if (objects == 0 || object[objects - 1] != o) {
                if (objects == candidate_bound_objects) break;
                object[objects] = o;
                held[objects] = 0;
                adjacent[objects] = 0;
                ++objects;
            }
            ++held[objects - 1];
            for (int j = 0; j < 4; ++j) adjacent[objects - 1] += valence[scene.tets[t].v[j]] - 1u;
            if (scene.exclusion_begin) excluded += scene.exclusion_begin[t + 1] - scene.exclusion_begin[t];
        }
        // Ordered pairs: each tet with every other counted tet its object is checked against.
        unsigned long long ordered = 0, left_out = 0;
        for (std::uint32_t a = 0; a < objects; ++a) {
            unsigned long long partners = 0;
            for (std::uint32_t b = 0; b < objects; ++b)
                if (checked(object[a], object[b])) partners += held[b];
            if (checked(object[a], object[a])) {
                partners -= 1; // not itself
                left_out += adjacent[a];
            }
            ordered += held[a] * partners;
        }
        if (ordered <= left_out) return;
        const unsigned long long pairs = (ordered - left_out) / 2;
        if (pairs > excluded) atomic_fetch_add(bound, pairs - excluded);
    }
};

/// @brief The lower bound on the candidate pairs of a frame whose grid is populated (`cells` claimed
/// cells, CellCandidateBoundKernel), run on `exec`; 0 where the memory does not hold its vertex counts.
template <class Exec>
std::uint64_t candidate_lower_bound(Exec& exec, const SceneView& scene, const GridView& grid, std::uint32_t cells,
                                    std::uint32_t all_tets, std::size_t vertices) {
    typename Exec::template buffer<std::uint32_t> valence;
    typename Exec::template buffer<unsigned long long> bound;
    if (!valence.try_resize_discard(vertices) || !bound.try_resize_discard(1)) return 0;
    exec.for_each(vertices, FillKernel<std::uint32_t>{valence.data(), 0u});
    const unsigned long long zero = 0;
    exec.upload(bound.data(), &zero, 1);
    exec.for_each(all_tets, VertexValenceKernel{scene.tets, valence.data()});
    exec.for_each(cells, CellCandidateBoundKernel{scene, grid, valence.data(), bound.data()});
    unsigned long long found = 0;
    exec.download(&found, bound.data(), 1);
    return found;
}

} // namespace kdet
