#pragma once
/// @file grid_populate.hpp
/// @brief Stage 2, the grid: the relevant tets inserted into the hash table's cells, then each cell's
/// chain of buckets compacted into one sorted list of entry blocks with their bounds.

#include "grid/bucket_table.hpp"
#include "grid/grid_math.hpp"
#include "pipeline/scene_view.hpp"

#include <cstdint>

namespace kdet {

/// @brief Stage 2: inserts each relevant tet into every cell its box overlaps on its layer. Once an
/// insert has failed (the table must grow), the remaining tets give up at once: the pass reruns anyway.
struct PopulateKernel {
    SceneView scene;
    GridView grid;
    const GridParams* params; ///< GridParamsKernel's

    KDET_HD void operator()(std::uint64_t t) const {
        const TetInfo& info = scene.info[t];
        if (info.layer < 0 || atomic_load_acquire(grid.failure)) return;
        const CellRange r = cell_range(*params, info.box, info.layer);
        const bool own_cells = has_own_cells(r);
        for_each_cell(r, [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
            const std::uint32_t bucket =
                grid_insert(grid, make_cell(x, y, z, info.layer), static_cast<std::uint32_t>(t), first_cell_axes(r, x, y, z));
            if (bucket == no_bucket) return false;
            if (own_cells) grid.own_cells[t].bucket[own_cell_index(r, x, y, z)] = bucket;
            return true;
        });
    }
};

/// @brief Stage 2, after populating: one work item per main bucket, the i-th for the cell claimed
/// i-th (GridView::claimed_slots; the items past the claimed cells record empty lists); copies each
/// cell's ids into one contiguous list (gather_cell), sorted next by the execution layer. Each thread
/// claims cells for neighbouring tets one after the other, so the lists this writes stay close
/// together in memory, as do the lists a tet's search reads (the CPU's threads, each populating a run
/// of tets of its own, interleave their claims).
struct GatherCellsKernel {
    SceneView scene;
    GridView grid;

    struct ObjectOf {
        const SceneView* scene;
        KDET_HD std::uint32_t operator()(std::uint32_t u) const { return scene->tet_object[u]; }
    };

    KDET_HD void operator()(std::uint64_t i) const { gather_cell(grid, static_cast<std::uint32_t>(i), ObjectOf{&scene}); }
};

/// @brief Stage 2, after the lists are sorted: one work item per entry of room (those past the
/// entries claimed do nothing), which fills the entry's rows from its sorted key (place_entry).
struct PlaceEntriesKernel {
    SceneView scene;
    GridView grid;
    const std::uint32_t* sorted_keys;

    struct EntryOf {
        const SceneView* scene;
        KDET_HD GridEntry operator()(std::uint32_t u) const { return GridEntry{scene->info[u].box, u, scene->tet_object[u]}; }
    };

    KDET_HD void operator()(std::uint64_t k) const {
        // A failed grid's lists are partly unwritten; it fills again.
        if (k >= *grid.entries_used || *grid.failure) return;
        place_entry(grid, sorted_keys, static_cast<std::uint32_t>(k), EntryOf{&scene});
    }
};

/// @brief Stage 2, after compacting: the bound of each block of entries (bound_entry_block).
struct BoundEntryBlocksKernel {
    GridView grid;
    KDET_HD void operator()(std::uint64_t block) const {
        if (*grid.failure) return; // the lists of a failed grid are partly unwritten; it fills again
        bound_entry_block(grid, static_cast<std::uint32_t>(block), *grid.entries_used);
    }
};

} // namespace kdet
