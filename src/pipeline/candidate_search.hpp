#pragma once
/// @file candidate_search.hpp
/// @brief Stage 3, candidates: each gridded tet's search of the cells of its layer and the layers above
/// for the larger tets its box overlaps, and the kdet kernel that writes the pairs the pre-test leaves.

#include "exec/atomic.hpp"
#include "grid/bucket_table.hpp"
#include "grid/grid_math.hpp"
#include "pipeline/pair_keys.hpp"
#include "pipeline/pair_tests.hpp"
#include "pipeline/scene_view.hpp"
#include "pipeline/static_grid.hpp"
#include "pipeline/tet_runs.hpp"

#include <cstdint>

namespace kdet {

/// @brief Passes on the entries whose object t's object is checked against.
template <class Visitor>
struct ObjectFilter {
    /// t's object's row of the active pairs: one load per entry, where pair_is_active would reload
    /// the scene's fields for each (the visitor's stores keep the compiler from hoisting them).
    const std::uint8_t* checked_against;
    Visitor* visit;

    KDET_HD void operator()(const GridEntry& e) const {
        if (checked_against[e.object]) (*visit)(e);
    }
};

/// @brief The share of a tet's candidate search that one work item takes: the layers t's own + layer,
/// + layer + layers, ..., and in each cell's list the blocks of each group that
/// group_blocks_of_part(block, blocks) names. The GPU splits a search (Tuning::search_layer_parts(),
/// Tuning::search_block_parts()) because a thread's search is a chain of dependent loads that occupancy
/// cannot hide; the CPU searches a tet whole.
struct SearchPart {
    std::uint32_t layer = 0, layers = 1;
    std::uint32_t block = 0, blocks = 1;
};

/// @brief Calls visit(entry) once for every tet u (entry.id) that tet t must test, with what the
/// cell's list holds about u (box, object): u is stored in a cell that t's
/// box overlaps on t's layer or a higher one, u is "larger" than t (higher layer, or same layer and
/// higher id, so each direction of a pair is found by one tet only), the objects are checked against
/// each other, and the boxes overlap. Adjacency and the narrow phase are left to the caller. The
/// search ends early, after a cell, once visit.finished().
///
/// A pair shares every cell that both boxes overlap; it is reported from one of them only, the cell
/// holding the lower corner of the boxes' intersection. That corner is max(t.lo, u.lo) per axis, and
/// cell indices are monotone, so its cell is max(t's first cell, u's first cell): inside both ranges,
/// hence always visited. No duplicates are written, so the candidate buffer holds unique pairs. Along
/// an axis where the cell is not t's first, it must be u's: the entry says so (GridEntry::starts),
/// and the cell's scan passes only such entries.
///
/// A search may be split (SearchPart): the parts together visit what the whole search does, each
/// pair once.
template <class Visitor>
KDET_HD inline void for_each_larger_neighbour(const SceneView& scene, const GridView& grid, const GridParams& params,
                                             std::uint32_t layer_mask, std::uint32_t t, Visitor& visit,
                                             SearchPart part = SearchPart{}) {
    const TetInfo self = scene.info[t];
    // A grid that failed to fill runs again before anything reads its results; its rows and lists
    // are partly unwritten.
    if (self.layer < 0 || *grid.failure) return;
    const std::uint32_t object = scene.tet_object[t];
    const std::uint8_t* checked_against = scene.pair_active + static_cast<std::uint64_t>(object) * scene.object_count;
    const std::uint32_t checked_objects = scene.checked_objects[object];
    ObjectFilter<Visitor> filter{checked_against, &visit};
    const std::uint32_t group_blocks = group_blocks_of_part(part.block, part.blocks);
    for (int layer = self.layer + static_cast<int>(part.layer); layer < params.layer_count;
         layer += static_cast<int>(part.layers)) {
        if (!((layer_mask >> layer) & 1u)) continue;
        // A cell holds only tets of its own layer: on t's, the larger tets are the higher ids, and the
        // sorted list skips the others unread (from t's own entry on, found through its row where it
        // has one); on a higher layer every tet is larger.
        const bool own_layer = layer == self.layer;
        const CellRange r = cell_range(params, self.box, layer);
        const bool own_cells = own_layer && has_own_cells(r);
        const bool searched_all = for_each_cell(r, [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
            // Along an axis where this is not t's first cell, u's box must start here.
            const std::uint32_t required_starts = ~first_cell_axes(r, x, y, z) & 7u;
            if (own_cells)
                grid_for_each_after_own_entry(grid, t, own_cell_index(r, x, y, z), checked_objects, self.box,
                                              required_starts, filter, group_blocks);
            else
                grid_for_each_in_cell(grid, make_cell(x, y, z, layer), own_layer ? t + 1 : 0u, checked_objects, self.box,
                                      required_starts, filter, group_blocks);
            return !visit.finished();
        });
        if (!searched_all) return;
    }
}

/// @brief Where a work item stopped when the buffer it appends to was full: after growing, the
/// stage reruns only such items, each skipping the keys it had already stored.
struct ResumePoint {
    std::uint32_t item;
    std::uint32_t stored;
};

/// @brief Stage 3 (kdet): writes the candidate pairs, each once, that the pre-test (the slabs where the
/// scene has them, then, with FacePlanesInSearch, the face planes) cannot prove separated (those it
/// can are only counted): a rejected pair is never written, sorted or loaded again. A pair the face
/// planes prove intersecting is written as a proven_pair_key, so that the narrow phase neither
/// repeats the pre-test nor runs the test on it. Without FacePlanesInSearch the narrow phase runs the
/// face planes, a thread a pair (Tuning::face_planes_in_search). An item searches a run of TetsPerItem
/// consecutive tets (SearchPart's share of each) and appends their keys and adds their rejections
/// together (Tuning::search_tets_per_item: a constant, so that the GPU's item of one tet keeps no loop).
/// An item whose keys did not all fit leaves a ResumePoint instead of counting its rejections; a rerun
/// after growing (`resume_from` set) runs only those items.
template <std::uint32_t TetsPerItem, bool FacePlanesInSearch>
struct FindCandidatesKernel {
    SceneView scene;
    GridView grid;
    const GridParams* params;        ///< GridParamsKernel's
    const std::uint32_t* layer_mask; ///< GridPlanKernel's
    KeyAppender out;
    unsigned long long* rejected; ///< pairs the pre-test proved separated
    const ResumePoint* resume_from; ///< null: every item, from the start; else item i resumes resume_from[i]
    ResumePoint* stopped;           ///< [stopped_capacity] where the items that did not fit stopped
    std::uint32_t* stopped_count;   ///< items that stopped, also those past the capacity (not recorded)
    std::uint32_t stopped_capacity;
    /// Work items per run of tets (SearchPart): layer_parts x block_parts, item (l * runs + r) *
    /// block_parts + b searching layer part l and block part b of the tets of run r. The block parts of
    /// a run are neighbouring items, which walk the same cells in step and read neighbouring blocks;
    /// the layer parts are far apart, so that a scene whose tets sit on one or two layers leaves whole
    /// warps of later layer parts idle, not lanes of every warp.
    std::uint32_t layer_parts;
    std::uint32_t block_parts;
    /// A frame that resumes the items that did not fit (a first frame): such an item stops searching at
    /// once, since its resumption searches again. Otherwise it searches on, counting the room the
    /// whole frame needs, so that a single rerun fits.
    bool stop_when_full;
    /// The static grid, which every moving tet also searches (its first search part does).
    StaticGridSearch statics;

    struct Emit {
        const SceneView* scene;
        KeyBatch* batch;
        bool stop_when_full;
        std::uint32_t t;
        SpreadIndices tet;
        std::uint32_t object;
        TetPlanes planes; ///< t's, its vertices included (with FacePlanesInSearch)
        TetSlabs slabs;   ///< t's, where the scene has them
        unsigned long long rejected;
        ExcludedPartners excluded; ///< t's, left out before any geometry
        KDET_HD void operator()(const GridEntry& e) {
            const std::uint32_t u = e.id();
            // Tets of one object that share a vertex are skipped first: they touch, so the slabs would
            // never separate them, and a self-colliding mesh's box-overlapping pairs hold many (its
            // neighbours); u's indices are loaded only for a pair within one object. Then the slabs,
            // whose 64 bytes separate many of the rest (slabs.hpp), before the costlier face planes.
            // Excluded pairs (pair_exclusions.hpp) go before any geometry, so filters save the tests.
            if (e.object == object && share_vertex(tet, scene->tets[u])) return;
            if (excluded.holds(u)) return;
            if (scene->slabs && slabs_separate(slabs, scene->slabs[u])) {
                ++rejected;
                return;
            }
            if constexpr (FacePlanesInSearch)
                pretest(u);
            else
                batch->push(pair_key(t, u));
        }
        /// The face-plane pre-test of (t, u); writes the pair unless it is proven separated.
        KDET_HD void pretest(std::uint32_t u) {
            const TetPlanes& other = scene->planes[u];
            // With a margin, separated means farther apart than the margin.
            const PlaneVerdict verdict = face_plane_pretest(planes, planes.vertex, other, other.vertex, false, scene->margin);
            if (verdict == PlaneVerdict::separated) {
                ++rejected;
                return;
            }
            batch->push(verdict == PlaneVerdict::intersecting ? proven_pair_key(t, u) : pair_key(t, u));
        }
        KDET_HD bool finished() const { return stop_when_full && batch->stopped; }
    };

    KDET_HD void operator()(std::uint64_t i) const {
        const auto item = resume_from ? resume_from[i].item : static_cast<std::uint32_t>(i);
        const std::uint32_t run_part = item / block_parts;
        using Runs = TetRuns<TetsPerItem>;
        const std::uint32_t runs = Runs::count(scene.tet_count), run = run_part % runs;
        const SearchPart part{run_part / runs, layer_parts, item % block_parts, block_parts};
        // An item of one tet (the GPU's) that the search skips returns before it touches the buffer's count.
        if (TetsPerItem == 1 && !searched(Runs::first(run), part)) return;
        const std::uint32_t already_stored = resume_from ? resume_from[i].stored : 0u;
        // Once a first frame's buffer is full, an item that has not started would only search until
        // its first batch and then search again after the buffer grows: it waits for that at once.
        if (stop_when_full && atomic_load_acquire(out.count) >= out.capacity) {
            record_stop(ResumePoint{item, already_stored});
            return;
        }
        KeyBatch batch(&out, already_stored);
        unsigned long long run_rejected = 0;
        Runs::for_each_tet(run, scene.tet_count, [&](std::uint32_t t) {
            if (TetsPerItem == 1 || searched(t, part)) run_rejected += search(t, part, batch);
            return !(stop_when_full && batch.stopped);
        });
        batch.flush();
        if (batch.stopped) {
            record_stop(ResumePoint{item, batch.stored});
            return;
        }
        if (run_rejected) atomic_fetch_add_gathered(rejected, run_rejected);
    }

    /// @brief Whether tet t has a share of the search in `part`: it is gridded, and it has layers there.
    KDET_HD bool searched(std::uint32_t t, const SearchPart& part) const {
        const int layer = scene.info[t].layer;
        return layer >= 0 && layer + static_cast<int>(part.layer) < params->layer_count;
    }

    /// @brief Tet t's share of the search, its keys into `batch`; returns the pairs it rejected.
    KDET_HD unsigned long long search(std::uint32_t t, const SearchPart& part, KeyBatch& batch) const {
        Emit emit{&scene, &batch, stop_when_full, t, spread_indices(scene.tets[t]), scene.tet_object[t],
                  FacePlanesInSearch ? scene.planes[t] : TetPlanes{}, scene.slabs ? scene.slabs[t] : TetSlabs{}, 0,
                  excluded_partners(scene, t)};
        const GridParams grid_params = *params;
        for_each_larger_neighbour(scene, grid, grid_params, *layer_mask, t, emit, part);
        if (part.layer == 0 && part.block == 0 && !emit.finished()) {
            const ObjectFilter<Emit> filter{scene.pair_active + static_cast<std::uint64_t>(emit.object) * scene.object_count, &emit};
            for_each_static_neighbour(scene, statics, t, filter, emit);
        }
        return emit.rejected;
    }

    KDET_HD void record_stop(const ResumePoint& point) const {
        const std::uint32_t slot = atomic_fetch_add(stopped_count, 1u);
        if (slot < stopped_capacity) stopped[slot] = point;
    }
};

} // namespace kdet
