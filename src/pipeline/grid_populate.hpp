#pragma once
/// @file grid_populate.hpp
/// @brief Stage 2, the grid: the relevant tets inserted into the hash table's cells, then each cell's
/// chain of buckets compacted into one sorted list of entry blocks with their bounds.

#include "grid/bucket_table.hpp"
#include "grid/grid_math.hpp"
#include "pipeline/scene_view.hpp"

#include <cstdint>

namespace kdet {

/// @brief Stage 2's populate step, written once for every hashed grid and parameterised by what the
/// grid stores for a (cell, tet): per tet t that Store::place puts on a layer (its box and that layer;
/// false: not gridded), Store::open sees the range of cells its box overlaps there (false: the tet is
/// kept another way), Store::add keeps one (cell, tet) per cell of the range (false: stop) and
/// Store::close ends the tet. Store::Tet is what one tet's steps share.
template <class Store>
struct PopulateKernel {
    Store store;

    KDET_HD void operator()(std::uint64_t t) const {
        Aabb box;
        int layer;
        if (!store.place(t, box, layer)) return;
        const CellRange r = cell_range(store.params(), box, layer);
        typename Store::Tet tet;
        if (!store.open(t, r, layer, tet)) return;
        if (for_each_cell(r, [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) { return store.add(tet, x, y, z); }))
            store.close(tet);
    }
};

/// @brief What the collision grid stores: each relevant tet in the hash table's bucket of every cell
/// its box overlaps on its layer (and those buckets, for a tet with cells of its own). Once an insert
/// has failed (the table must grow), the remaining tets give up at once: the pass reruns anyway.
struct TableCells {
    SceneView scene;
    GridView grid;
    const GridParams* grid_params; ///< GridParamsKernel's

    struct Tet {
        std::uint32_t id;
        int layer;
        CellRange range;
        bool own_cells;
    };
    KDET_HD const GridParams& params() const { return *grid_params; }
    KDET_HD bool place(std::uint64_t t, Aabb& box, int& layer) const {
        const TetInfo& info = scene.info[t];
        if (info.layer < 0 || atomic_load_acquire(grid.failure)) return false;
        box = info.box;
        layer = info.layer;
        return true;
    }
    KDET_HD bool open(std::uint64_t t, const CellRange& r, int layer, Tet& tet) const {
        tet = Tet{static_cast<std::uint32_t>(t), layer, r, has_own_cells(r)};
        return true;
    }
    KDET_HD bool add(Tet& tet, std::uint32_t x, std::uint32_t y, std::uint32_t z) const {
        const std::uint32_t bucket = grid_insert(grid, make_cell(x, y, z, tet.layer), tet.id, first_cell_axes(tet.range, x, y, z));
        if (bucket == no_bucket) return false;
        if (tet.own_cells) grid.own_cells[tet.id].bucket[own_cell_index(tet.range, x, y, z)] = bucket;
        return true;
    }
    KDET_HD void close(Tet&) const {}
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
