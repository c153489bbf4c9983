#pragma once
/// @file frame_counters.hpp
/// @brief What a frame's kernels count and compute for the stages after them, in the backend's memory.

#include "exec/atomic.hpp"
#include "grid/grid_math.hpp"
#include "pipeline/bounding_boxes.hpp"
#include "pipeline/positions_check.hpp"

#include <cstdint>
#include <limits>

namespace kdet {

/// @brief What the kernels of a frame count and compute for the stages after them, in the backend's
/// memory; the host reads it once, when the frame is done. The counters that work items add to as
/// they go (appends, claimed cells, rejections) each have a cache line of their own, apart from the
/// values every item reads (the grid's failure bits, its geometry): sharing one, the CPU's threads
/// passed the line back and forth on every add and read.
struct FrameCounters {
    alignas(64) unsigned long long candidates; ///< appended (counts past the buffer's end)
    unsigned long long candidate_padding; ///< of which slots hold no_pair_key (see KeyAppender)
    alignas(64) unsigned long long rejected; ///< candidate pairs the pre-test (slabs, face planes) proved separated
    /// Of the candidates written, those the face planes proved separated in the narrow phase (where the
    /// search does not run them: Tuning::face_planes_in_search)
    alignas(64) unsigned long long rejected_after_search;
    alignas(64) unsigned long long colliding_pairs; ///< appended (counts past the window's end)
    alignas(64) std::uint32_t cells_claimed;
    alignas(64) std::uint32_t grid_entries; ///< entries of the compacted cells
    alignas(64) std::uint32_t overflow_used;
    alignas(64) unsigned long long exact_stage_pairs; ///< pairs that reached the exact stage of NarrowPhase::exact
    unsigned long long colliding_tets;
    unsigned long long involved_tets; ///< tets of the objects in a pair checked this frame
    std::uint32_t stopped_items; ///< ResumePoints the candidate search left (items, not tets): its buffer was full
    std::uint32_t grid_failure;
    std::uint32_t layer_mask;
    std::uint32_t first_non_finite_vertex; ///< lowest staged vertex found non-finite, or no_vertex
    std::uint32_t object_runs; ///< runs of tets of one object, i.e. non-empty objects
    std::uint32_t min_size; ///< float_to_ordered, over the relevant tets
    std::uint32_t max_size;
    std::uint32_t min_upper_size; ///< float_to_ordered, of the relevant tets' upper bounds on their size (TetSizeKernel)
    std::uint32_t max_lower_size; ///< and of their lower bounds
    OrderedBox region; ///< the gridded region: the boxes of the objects in a checked pair
    GridParams params; ///< GridParamsKernel's
    std::uint32_t spacing_octaves[float_octaves]; ///< TetSizeKernel's histogram of the tets' spacings
    unsigned long long layer_entries[max_grid_layers]; ///< cell entries the relevant tets need, per layer
    unsigned long long layer_cells[max_grid_layers];   ///< bound on the cells they occupy, per layer

    /// The values a frame starts from: empty size range and region.
    static FrameCounters fresh() {
        FrameCounters c{};
        c.min_size = float_to_ordered(std::numeric_limits<float>::infinity());
        c.max_size = float_to_ordered(0.0f);
        c.min_upper_size = float_to_ordered(std::numeric_limits<float>::infinity());
        c.max_lower_size = float_to_ordered(0.0f);
        c.first_non_finite_vertex = no_vertex;
        for (int a = 0; a < 3; ++a) {
            c.region.lo[a] = float_to_ordered(std::numeric_limits<float>::infinity());
            c.region.hi[a] = float_to_ordered(-std::numeric_limits<float>::infinity());
        }
        return c;
    }
};

} // namespace kdet
