#pragma once
/// @file tuning.hpp
/// @brief How each backend's pipeline divides its work: the values that measurements chose
/// (docs/performance.md), apart from the execution layers, which run loops, hold memory, sort and
/// launch. Each execution layer names its tuning (Exec::tuning) and the pipeline reads it at compile
/// time (Pipeline's Tuning), so that the CPU backend can run with CudaTuning to test the GPU's shape.
/// The constraints the pipeline relies on are checked by tests/test_tuning.cpp.

#include <cstddef>
#include <cstdint>

namespace kdet {

/// @brief The CPU's: few threads, each with large caches, so a work item takes much work and reads
/// what its thread has just read.
struct CpuTuning {
    /// @brief How many of the tets' spacings layer 0's cells span at least (GridParamsKernel): four,
    /// so that a cell holds dozens of tets. A query's visit of a cell costs far more than reading an
    /// entry of its list, and the block bounds skip most of a large cell's entries.
    static constexpr float grid_cell_spacings = 4.0f;

    /// @brief Consecutive tets per work item of the grid's plan (GridPlanKernel): many, since an item
    /// adds its counts with a few atomics and bounds the cells by what its previous tet covered.
    static constexpr std::uint32_t plan_chunk = 256;

    /// @brief Work items a tet's candidate search is split into, by layers and by blocks of each list
    /// (SearchPart), whether a scene has self-collision and however many tets: none, so that a thread
    /// loads the tet once and its dynamic chunks stay balanced.
    static constexpr std::uint32_t search_layer_parts(bool /*self_collision*/, std::size_t /*tets*/) { return 1; }
    static constexpr std::uint32_t search_block_parts(bool /*self_collision*/, std::size_t /*tets*/) { return 1; }

    /// @brief Consecutive tets per work item of the grid's searches (the candidates', kdet_no_pairs',
    /// point location's scans): a thread appends their keys and adds their counts with one atomic per
    /// run, where an item per tet passed the counters' cache line between the threads at every tet.
    static constexpr std::uint32_t search_tets_per_item = 32;

    /// @brief The face-plane pre-test runs inside the candidate search, where the searching tet's
    /// planes and its neighbours' data are in the thread's caches, so that only the pairs it cannot
    /// decide are written. In the narrow phase instead (the GPU's way) the meshes' frames took longer.
    static constexpr bool face_planes_in_search = true;

    /// @brief Consecutive keys per work item of a stage that appends what it finds (the narrow phase):
    /// a batch's worth (KeyBatch), so that a thread appends them with one atomic, the threads
    /// contending for the one counter. More would leave a small stage too few items to share
    /// (CpuExec::for_each runs a stage of few items on one thread).
    static constexpr std::uint32_t keys_per_appending_item = 16;
};

/// @brief The GPU's: many threads in warps that run in step, so a work item is short, and the
/// lanes of a warp should do the same work at the same time.
struct CudaTuning {
    /// @brief How many of the tets' spacings layer 0's cells span at least (GridParamsKernel): one, the
    /// spacing. A thread scans a tet's lists and a thread gathers each cell's list, so the longer lists
    /// of larger cells keep a warp's other threads waiting, and they took several times the memory on
    /// large scenes; only some scenes with self-collision searched faster in wider cells.
    static constexpr float grid_cell_spacings = 1.0f;

    /// @brief Consecutive tets per work item of the grid's plan (GridPlanKernel): few, since a thread
    /// walks its tets in series, and longer chunks left most of the warp slots idle. The plan's bound
    /// on the cells loosens a little with shorter chunks (each item counts its first tet's cells
    /// whole).
    static constexpr std::uint32_t plan_chunk = 4;

    /// @brief Work items a tet's candidate search is split into (SearchPart): every fourth of its layers
    /// and in each list every second block (4 x 2), or, for a scene of at most split_by_blocks_max_tets
    /// tets without self-collision, every second layer and every fourth block (2 x 4). A thread's search
    /// is a chain of dependent loads (cells, then blocks of entries) that occupancy cannot hide when a
    /// scene has few tets: the longest chains set the kernel's time, and a warp's lanes ran mostly
    /// idle behind them. The block parts of a tet are neighbouring lanes that walk the same cells in
    /// step. Of the splits tried, 4 x 2 searched the scenes with self-collision fastest, and those of
    /// more than a few hundred thousand tets; 2 x 4 the smaller scenes without self-collision. Both
    /// keep 8 items a tet.
    static constexpr std::size_t split_by_blocks_max_tets = 300000;
    static constexpr bool split_by_blocks(bool self_collision, std::size_t tets) {
        return !self_collision && tets <= split_by_blocks_max_tets;
    }
    static constexpr std::uint32_t search_layer_parts(bool self_collision, std::size_t tets) {
        return split_by_blocks(self_collision, tets) ? 2 : 4;
    }
    static constexpr std::uint32_t search_block_parts(bool self_collision, std::size_t tets) {
        return split_by_blocks(self_collision, tets) ? 4 : 2;
    }

    /// @brief Consecutive tets per work item of the grid's searches: one, a thread's search is long
    /// enough (its appends are gathered per warp).
    static constexpr std::uint32_t search_tets_per_item = 1;

    /// @brief The face-plane pre-test runs in the narrow phase, a thread a pair, not inside the
    /// candidate search: there a lane with a match ran it (a few hundred instructions) while the others
    /// of its warp waited. The search writes the pairs the slabs leave, more keys for fuller warps, and
    /// needs far fewer registers without it.
    static constexpr bool face_planes_in_search = false;

    /// @brief Consecutive keys per work item of a stage that appends what it finds: one, a thread each
    /// (the appends of a warp's lanes are gathered into one atomic).
    static constexpr std::uint32_t keys_per_appending_item = 1;
};

} // namespace kdet
