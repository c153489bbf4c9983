#pragma once
/// @file static_grid.hpp
/// @brief Static objects (Detector::set_static): their tets are stored after the moving ones and
/// placed once, with their boxes, sizes, face planes and slabs, into a grid of their own that stays
/// between frames; a frame grids and searches the moving tets only, and each of them also searches
/// this grid.
///
/// A moving tet m and a static tet s must meet whichever of them is larger. The static grid therefore
/// holds each static tet in the cells of its own layer and, as a copy, in the copy cells of every
/// layer above it (keys of their own: layer + max_grid_layers), up to a top layer whose cells span
/// the whole static region. m searches the static grid from the layer its own size gives it (`L`, at
/// most the top) upwards: the own cells of L and of every layer above (the tets of its size and
/// larger), and the copy cells of L alone (the smaller tets). Each pair is so found on one layer only,
/// and on that layer in one cell only, by the rule of for_each_larger_neighbour (the cell of the lower
/// corner of the boxes' intersection); no search reads a copy it must skip. m's box is cut
/// to the static region first, so that a moving tet larger than the region still visits at most two
/// cells per axis of the top layer.
///
/// Pairs of two static tets are never searched, as PhysX never reports static-static contacts: they
/// cannot change.

#include "exec/atomic.hpp"
#include "geometry/enclosing_sphere.hpp"
#include "grid/bucket_table.hpp"
#include "grid/grid_math.hpp"
#include "pipeline/bounding_boxes.hpp"
#include "pipeline/frame_counters.hpp"
#include "pipeline/grid_sizing.hpp"
#include "pipeline/scene_view.hpp"

#include <cstdint>

namespace kdet {

/// @brief Placing static tets, per tet t = first + i: its box (TetBoundsKernel's, grown by half the margin).
struct StaticBoundsKernel {
    SceneView scene;
    std::uint32_t first;
    KDET_HD void operator()(std::uint64_t i) const { TetBoundsKernel{scene}(first + i); }
};

/// @brief Placing static tets, per tet t = first + i (boxes already computed): its face planes, slabs
/// and exact sphere diameter, the range of the sizes and the spacing histogram (as TetSizeKernel).
struct StaticSizeKernel {
    SceneView scene;
    std::uint32_t first;
    std::uint32_t* min_size; ///< float_to_ordered
    std::uint32_t* max_size;
    std::uint32_t* spacing_octaves;

    KDET_HD void operator()(std::uint64_t i) const {
        const std::uint64_t t = first + i;
        TetInfo& info = scene.info[t];
        vec3 v[4];
        load_tet(scene, static_cast<std::uint32_t>(t), v);
        if (t % spacing_sample == 1 && i > 0 && scene.tet_object[t - 1] == scene.tet_object[t])
            atomic_fetch_add_gathered(&spacing_octaves[float_octave(tet_spacing(info.box, scene.info[t - 1].box))], 1u);
        scene.planes[t] = tet_planes(v);
        if (scene.slabs) scene.slabs[t] = tet_slabs(v, scene.planes[t].longest, scene.margin);
        info.diameter = grown_size(enclosing_sphere_diameter(v), scene.margin); // as TetSizeKernel's
        atomic_lower_to(min_size, float_to_ordered(info.diameter));
        atomic_raise_to(max_size, float_to_ordered(info.diameter));
    }
};

/// @brief Placing static tets, one work item: the static region from the boxes of the static objects
/// (the runs the box reduction left), and the largest size raised to the region's largest extent, so
/// that GridParamsKernel gives the grid a top layer whose cells span the region.
struct StaticRegionKernel {
    const Aabb* run_boxes;
    const std::uint32_t* run_count;
    OrderedBox* region;
    std::uint32_t* max_size;

    KDET_HD void operator()(std::uint64_t) const {
        for (std::uint32_t r = 0; r < *run_count; ++r)
            for (int axis = 0; axis < 3; ++axis) {
                region->lo[axis] = min_u(region->lo[axis], float_to_ordered(component(run_boxes[r].lo, axis)));
                region->hi[axis] = max_u(region->hi[axis], float_to_ordered(component(run_boxes[r].hi, axis)));
            }
        if (*run_count == 0) return;
        float extent = 0.0f;
        for (int axis = 0; axis < 3; ++axis)
            extent = max_f(extent, ordered_to_float(region->hi[axis]) - ordered_to_float(region->lo[axis]));
        if (float_to_ordered(extent) > *max_size) *max_size = float_to_ordered(extent);
    }

    KDET_HD static std::uint32_t min_u(std::uint32_t a, std::uint32_t b) { return a < b ? a : b; }
    KDET_HD static std::uint32_t max_u(std::uint32_t a, std::uint32_t b) { return a > b ? a : b; }
};

/// @brief Placing static tets, one work item per chunk of them: each tet's layer (kept in its
/// TetInfo::layer, which no frame changes), and per layer the entries of the tets held there (own
/// layer and the copies above) with a bound on their cells, as GridPlanKernel counts them: the cells a
/// tet does not share with the chunk's previous tet on that layer.
struct StaticPlanKernel {
    SceneView scene;
    const GridParams* grid_params;
    std::uint32_t first, count, chunk;
    unsigned long long* layer_entries; ///< [max_grid_layers]
    unsigned long long* layer_cells;

    KDET_HD void operator()(std::uint64_t c) const {
        const GridParams params = *grid_params;
        unsigned long long entries[max_grid_layers] = {}, cells[max_grid_layers] = {};
        CellRange previous[max_grid_layers];
        for (int l = 0; l < max_grid_layers; ++l) previous[l] = CellRange{{1, 1, 1}, {0, 0, 0}};
        const std::uint64_t begin = c * chunk, end = begin + chunk < count ? begin + chunk : count;
        for (std::uint64_t i = begin; i < end; ++i) {
            TetInfo& info = scene.info[first + i];
            info.layer = layer_of(params, info.diameter);
            for (int l = info.layer; l < params.layer_count; ++l) {
                const CellRange r = cell_range(params, info.box, l);
                entries[l] += cell_count(r);
                cells[l] += cell_count(r) - shared_cell_count(r, previous[l]);
                previous[l] = r;
            }
        }
        for (int l = 0; l < params.layer_count; ++l)
            if (entries[l]) {
                atomic_fetch_add(&layer_entries[l], entries[l]);
                atomic_fetch_add(&layer_cells[l], cells[l]);
            }
    }
};

/// @brief The key of a copy cell (see the file's comment): apart from every layer's own cells.
KDET_HD inline CellCoord copy_cell(std::uint32_t x, std::uint32_t y, std::uint32_t z, int layer) {
    return make_cell(x, y, z, layer + max_grid_layers);
}

/// @brief Placing static tets, per tet: inserts it into the cells of its box on its own layer and the
/// copy cells of every layer above (start bits relative to its range on each). Once an insert has failed, the rest
/// give up: the pass runs again with more room.
struct StaticPopulateKernel {
    SceneView scene;
    GridView grid;
    const GridParams* params;
    std::uint32_t first;

    KDET_HD void operator()(std::uint64_t i) const {
        const std::uint32_t t = first + static_cast<std::uint32_t>(i);
        const TetInfo& info = scene.info[t];
        for (int l = info.layer; l < params->layer_count; ++l) {
            if (atomic_load_acquire(grid.failure)) return;
            const CellRange r = cell_range(*params, info.box, l);
            for_each_cell(r, [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
                const CellCoord cell = l == info.layer ? make_cell(x, y, z, l) : copy_cell(x, y, z, l);
                return grid_insert(grid, cell, t, first_cell_axes(r, x, y, z)) != no_bucket;
            });
        }
    }
};

/// @brief The static grid as a frame's search reads it; `active` is false where no static tet is placed.
struct StaticGridSearch {
    GridView grid;
    const GridParams* params;  ///< the static grid's geometry
    const OrderedBox* region;  ///< the static tets' region
    bool active;
};

/// @brief Calls filter(entry) once for every static tet u that moving tet t must test and whose box
/// overlaps t's, in a cell holding one of the objects t is checked against; the filter checks u's
/// object (ObjectFilter) and passes it on to `visit` (adjacency cannot occur: they are different
/// objects). Ends early, after a cell, once visit.finished().
template <class Filter, class Visitor>
KDET_HD inline void for_each_static_neighbour(const SceneView& scene, const StaticGridSearch& statics, std::uint32_t t,
                                              const Filter& filter, const Visitor& visit) {
    if (!statics.active || *statics.grid.failure) return;
    const GridParams params = *statics.params;
    if (params.layer_count == 0) return;
    const TetInfo self = scene.info[t];
    const std::uint32_t object = scene.tet_object[t];
    const std::uint32_t checked_objects = scene.checked_objects[object];
    // Cut to the region: cells beyond it hold nothing.
    const OrderedBox& region = *statics.region;
    const vec3 region_lo{ordered_to_float(region.lo[0]), ordered_to_float(region.lo[1]), ordered_to_float(region.lo[2])};
    const vec3 region_hi{ordered_to_float(region.hi[0]), ordered_to_float(region.hi[1]), ordered_to_float(region.hi[2])};
    const Aabb cut{max_v(self.box.lo, region_lo), min_v(self.box.hi, region_hi)};
    if (!(cut.lo.x <= cut.hi.x && cut.lo.y <= cut.hi.y && cut.lo.z <= cut.hi.z)) return;
    const int from = tet_layer(scene, params, t, self.diameter);
    for (int layer = from; layer < params.layer_count; ++layer) {
        const CellRange r = cell_range(params, cut, layer);
        const bool searched_all = for_each_cell(r, [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
            const std::uint32_t required_starts = ~first_cell_axes(r, x, y, z) & 7u;
            grid_for_each_in_cell(statics.grid, make_cell(x, y, z, layer), 0u, checked_objects, self.box, required_starts, filter);
            if (layer == from)
                grid_for_each_in_cell(statics.grid, copy_cell(x, y, z, layer), 0u, checked_objects, self.box, required_starts,
                                      filter);
            return !visit.finished();
        });
        if (!searched_all) return;
    }
}

/// @brief The static grid's buffers and sizes, kept between frames (Pipeline::place_static fills them).
template <class Exec>
struct StaticGridStore {
    template <class T>
    using buffer = typename Exec::template buffer<T>;

    buffer<FrameCounters> counters; ///< the placing's sizes, geometry and region, read by every search
    buffer<BucketHeader> headers;
    buffer<std::uint32_t> ids;
    buffer<EntryBlock> entry_blocks;
    buffer<BlockBoundGroup> block_bounds;
    buffer<std::uint32_t> claimed_slots;
    buffer<std::uint32_t> list_keys;
    buffer<std::uint32_t> sorted_keys;
    buffer<std::uint32_t> list_begin;
    buffer<std::uint32_t> list_end;
    StaticGridSearch search{};
    bool placed = false; ///< the grid holds the static tets where they are now

    std::size_t bytes() const {
        return counters.capacity_bytes() + headers.capacity_bytes() + ids.capacity_bytes() + entry_blocks.capacity_bytes() +
               block_bounds.capacity_bytes() + claimed_slots.capacity_bytes() + list_keys.capacity_bytes() +
               sorted_keys.capacity_bytes() + list_begin.capacity_bytes() + list_end.capacity_bytes();
    }
};

} // namespace kdet
