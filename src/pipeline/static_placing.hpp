#pragma once
/// @file static_placing.hpp
/// @brief Pipeline::place_static: the static objects' tets placed into their own grid
/// (static_grid.hpp), once for as long as they stay where they are.

#include "pipeline/capacity.hpp"
#include "pipeline/pipeline_stages.hpp"

#include <kdet/error.hpp>

#include <cmath>

namespace kdet {

/// @brief Places the static tets (stored from frame_tets_ on): their boxes, their objects' boxes,
/// sizes, face planes and slabs, each tet's layer, and the grid that holds them on their layers and
/// above, sized from a plan read back at once. Runs in a frame after its positions are current, when
/// the static objects or their positions changed; their data then stays until the next change, as no
/// frame's stage touches a static tet.
template <class Exec>
void Pipeline<Exec>::place_static() {
    StaticGridStore<Exec>& s = statics_;
    const std::uint32_t first = frame_tets_;
    const std::uint32_t count = static_cast<std::uint32_t>(tets_.size()) - first;
    s.counters.resize_discard(1);
    const FrameCounters fresh = FrameCounters::fresh();
    exec_.upload(s.counters.data(), &fresh, 1);
    FrameCounters* c = s.counters.data();
    const SceneView scene = scene_view();
    exec_.for_each(count, StaticBoundsKernel{scene, first});
    exec_.reduce_runs(tet_object_.data() + first, TetBoxOf{info_.data() + first}, count, BoxUnion{}, run_objects_.data(),
                      run_boxes_.data(), &c->object_runs);
    exec_.for_each(object_boxes_.size(), ObjectBoxesKernel{run_objects_.data(), run_boxes_.data(), &c->object_runs,
                                                           object_boxes_.data()});
    exec_.for_each(count, StaticSizeKernel{scene, first, &c->min_size, &c->max_size, c->spacing_octaves});
    exec_.for_each(1, StaticRegionKernel{run_boxes_.data(), &c->object_runs, &c->region, &c->max_size});
    exec_.for_each(1, GridParamsKernel{&c->min_size, &c->max_size, c->spacing_octaves, &c->region, &c->params,
                                       Tuning::grid_cell_spacings});
    constexpr std::uint32_t chunk = Tuning::plan_chunk;
    exec_.for_each((count + chunk - 1) / chunk,
                   StaticPlanKernel{scene, &c->params, first, count, chunk, c->layer_entries, c->layer_cells}, chunk);
    FrameCounters plan;
    exec_.download(&plan, c, 1);
    double entries = 0.0, cells = 0.0;
    for (int layer = 0; layer < plan.params.layer_count; ++layer) {
        entries += static_cast<double>(plan.layer_entries[layer]);
        cells += static_cast<double>(plan.layer_cells[layer]);
    }
    if (entries > 4294967295.0)
        throw Error("the static objects need " + std::to_string(static_cast<unsigned long long>(entries)) +
                    " grid entries, more than 2^32 - 1");
    const std::uint32_t capacity = options_.bucket_capacity ? options_.bucket_capacity : automatic_bucket_capacity(entries, cells);
    std::uint32_t slots = 1024;
    while (slots < 1.25 * cells && slots < (1u << 30)) slots *= 2;
    auto pool = static_cast<std::uint32_t>(
        std::min(std::ceil(1.125 * entries / capacity) + 64.0, static_cast<double>(max_overflow_buckets)));
    const auto entry_capacity = static_cast<std::uint32_t>(entries);
    // The plan counts the entries exactly and bounds the cells; only a table or pool that probing or
    // racing threads overran needs another pass.
    for (;;) {
        const std::size_t buckets = std::size_t{slots} + pool;
        s.headers.resize_discard(buckets);
        s.ids.resize_discard(buckets * capacity);
        fill(s.headers, BucketHeader{});
        const std::uint32_t blocks = (entry_capacity + entry_block - 1) / entry_block;
        s.entry_blocks.resize_discard(blocks);
        fill(s.entry_blocks, EntryBlock{});
        s.block_bounds.resize_discard((blocks + bound_group - 1) / bound_group);
        fill(s.block_bounds, BlockBoundGroup{});
        s.claimed_slots.resize_discard(slots);
        s.list_keys.resize_discard(entry_capacity);
        s.sorted_keys.resize_discard(entry_capacity);
        s.list_begin.resize_discard(slots);
        s.list_end.resize_discard(slots);
        FrameCounters start = plan;
        start.grid_entries = start.overflow_used = start.grid_failure = start.cells_claimed = 0;
        exec_.upload(c, &start, 1);
        std::uint32_t slot_bits = 0;
        while ((1u << slot_bits) < slots) ++slot_bits;
        const GridView grid{s.headers.data(), s.ids.data(), s.entry_blocks.data(), s.list_keys.data(), s.list_begin.data(),
                            s.list_end.data(), s.block_bounds.data(), nullptr, &c->grid_entries, entry_capacity,
                            &c->overflow_used, &c->grid_failure, &c->cells_claimed, s.claimed_slots.data(), slots, slot_bits,
                            capacity, pool, 1u, 64u, options_.hash};
        exec_.for_each_in_runs(count, StaticPopulateKernel{scene, grid, &c->params, first});
        exec_.for_each(slots, GatherCellsKernel{scene, grid});
        exec_.sort_lists(s.list_keys.data(), s.sorted_keys.data(), entry_capacity, s.list_begin.data(), s.list_end.data(), slots);
        exec_.for_each(entry_capacity, PlaceEntriesKernel{scene, grid, s.sorted_keys.data()});
        exec_.for_each(blocks, BoundEntryBlocksKernel{grid});
        FrameCounters done;
        exec_.download(&done, c, 1);
        if (!done.grid_failure) {
            s.search = StaticGridSearch{grid, &c->params, &c->region, count > 0};
            s.placed = true;
            return;
        }
        ++regrows_;
        if (done.grid_failure & grid_table_full) slots = slots < (1u << 30) ? 2 * slots : slots;
        if (done.grid_failure & grid_overflow_pool_full)
            pool = static_cast<std::uint32_t>(std::min(rerun_capacity(pool, done.overflow_used), max_overflow_buckets));
    }
}

} // namespace kdet
