#pragma once
/// @file exchange_kernels.hpp
/// @brief kdet::mpi's per-tet steps as per-element functors: each owned tet's box, the coarse cells a
/// rank's part occupies, which ranks a tet goes to, and its record. Boxes and cell indices are the
/// pipeline's (bounding_boxes.hpp, grid_math.hpp); the functors run through the CPU execution layer
/// and, written as KDET_HD without exceptions or containers, could be launched on a device as they are.

#include "exec/atomic.hpp"
#include "grid/grid_math.hpp"
#include "pipeline/bounding_boxes.hpp"

#include <cstdint>

namespace kdet::mpi::detail {

/// Cells per axis of the coarse grid over each rank's part of each object: which of them the part
/// occupies travels with its bounds, so that a tet goes only where it may meet a tet (a slab of a
/// curved object fills little of its box). 16^3 cells are 512 bytes per object and rank.
constexpr int grid_cells = 16;
constexpr int cell_words = grid_cells * grid_cells * grid_cells / 64;

/// What every rank gathers about every other rank's part of one object.
struct PartSummary {
    Aabb box;                          ///< the union of the part's tets' boxes (empty: no tets)
    std::uint64_t cells[cell_words];   ///< bit (z * 16 + y) * 16 + x: a tet's box overlaps cell (x, y, z)
};

/// One tet on its way to another rank: its object, global id, global vertex ids and positions.
struct TetRecord {
    std::uint32_t object, tet;
    std::uint32_t vertex[4];
    float position[12];
};
static_assert(sizeof(TetRecord) == 72, "tet records travel as raw bytes");

/// The box nothing overlaps, which a union with any box leaves as that box.
KDET_HD inline Aabb empty_box() { return Aabb{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}}; }
KDET_HD inline bool box_is_empty(const Aabb& box) { return !(box.lo.x <= box.hi.x); }

/// The coarse grid over a part's box: along each axis grid_cells cells over the box's extent (a slab
/// is cut as finely across as along), each axis's index by the pipeline's monotone cell_index. The
/// rank marking cells and the one testing them derive it from the same box alike, so two boxes
/// sharing a point share a cell: a tet meeting a tet of the part overlaps one of its marked cells.
struct CoarseGrid {
    GridParams axis[3]; ///< axis k's origin and inverse cell size (only its component k is used)
};

KDET_HD inline CoarseGrid coarse_grid(const Aabb& box) {
    CoarseGrid grid;
    for (int k = 0; k < 3; ++k) {
        // Halved like cell_index's differences, so that no extent overflows; a flat or empty extent
        // puts everything in cell 0.
        const float half_extent = component(box.hi, k) * 0.5f - component(box.lo, k) * 0.5f;
        const float inv = half_extent > 0.0f ? (0.5f * grid_cells) / half_extent : 0.0f;
        grid.axis[k] = GridParams{box.lo, inv > 0.0f ? 1.0f / inv : 0.0f, inv, 1};
    }
    return grid;
}

/// The cells of @p grid that @p box overlaps, clamped to the grid (monotone, so never empty).
KDET_HD inline CellRange coarse_cells(const CoarseGrid& grid, const Aabb& box) {
    CellRange r;
    for (int k = 0; k < 3; ++k) {
        const GridParams& g = grid.axis[k];
        const std::uint32_t last = grid_cells - 1;
        const std::uint32_t lo = cell_index(g, component(box.lo, k), component(g.origin, k), 0);
        const std::uint32_t hi = cell_index(g, component(box.hi, k), component(g.origin, k), 0);
        r.lo[k] = lo < last ? lo : last;
        r.hi[k] = hi < last ? hi : last;
    }
    return r;
}

KDET_HD inline std::uint32_t coarse_cell_bit(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    return (z * grid_cells + y) * grid_cells + x;
}

/// Box of owned tet t from the rank's float32 positions, grown as the pipeline grows it for a margin.
struct OwnedTetBoxes {
    const float* positions;     ///< x y z per held vertex
    const std::uint32_t* tets;  ///< 4 held-vertex indices per owned tet
    float margin;
    Aabb* boxes;
    KDET_HD void operator()(std::uint64_t t) const {
        vec3 v[4];
        for (int c = 0; c < 4; ++c) {
            const float* p = positions + 3 * static_cast<std::uint64_t>(tets[4 * t + static_cast<std::uint64_t>(c)]);
            v[c] = vec3{p[0], p[1], p[2]};
        }
        const Aabb box = tet_box(v);
        boxes[t] = margin > 0.0f ? grown_box(box, half_margin(margin)) : box;
    }
};

/// The union of each chunk of `chunk` boxes, chunk i into chunk_boxes[i]: the part's box is the union
/// of these few.
struct ChunkBoxes {
    const Aabb* boxes;
    std::uint64_t count;
    std::uint64_t chunk;
    Aabb* chunk_boxes;
    KDET_HD void operator()(std::uint64_t i) const {
        Aabb u = empty_box();
        const std::uint64_t end = (i + 1) * chunk < count ? (i + 1) * chunk : count;
        for (std::uint64_t t = i * chunk; t < end; ++t) u = BoxUnion{}(u, boxes[t]);
        chunk_boxes[i] = u;
    }
};

/// Marks the coarse cells owned tet t's box overlaps in its part's summary. Neighbouring tets share
/// most cells: a bit already set is only read, not written again by a locked instruction.
struct MarkCells {
    const Aabb* boxes;
    CoarseGrid grid;
    std::uint64_t* cells;
    KDET_HD void operator()(std::uint64_t t) const {
        for_each_cell(coarse_cells(grid, boxes[t]), [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
            const std::uint32_t bit = coarse_cell_bit(x, y, z);
            const std::uint64_t mask = std::uint64_t{1} << (bit % 64);
            if (!(atomic_load_acquire(&cells[bit / 64]) & mask)) atomic_fetch_or(&cells[bit / 64], mask);
            return true;
        });
    }
};

/// Whether a tet with box @p box may meet a tet of the part @p s summarises (on grid @p grid).
KDET_HD inline bool may_meet(const PartSummary& s, const CoarseGrid& grid, const Aabb& box) {
    if (box_is_empty(s.box) || !boxes_overlap(s.box, box)) return false;
    return !for_each_cell(coarse_cells(grid, box), [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
        const std::uint32_t bit = coarse_cell_bit(x, y, z);
        return !((s.cells[bit / 64] >> (bit % 64)) & 1u);
    });
}

/// For owned tet t of one object and each of `ranks` other ranks j: 1 in sends[j * (count + 1) + t]
/// when the tet may meet rank j's part of an object it is checked against, else 0.
struct ChooseRanks {
    const Aabb* boxes;
    std::uint64_t count;              ///< owned tets of the object
    const PartSummary* summaries;     ///< [j * objects + b]: rank j's part of object b
    const CoarseGrid* grids;          ///< the coarse grid of each of those summaries
    const std::uint8_t* checked;      ///< [b]: the tet's object is checked against object b
    std::uint32_t objects;
    std::uint32_t ranks;
    std::uint32_t* sends;
    KDET_HD void operator()(std::uint64_t t) const {
        for (std::uint32_t j = 0; j < ranks; ++j) {
            bool send = false;
            for (std::uint32_t b = 0; b < objects && !send; ++b) {
                const std::uint64_t k = std::uint64_t{j} * objects + b;
                send = checked[b] && may_meet(summaries[k], grids[k], boxes[t]);
            }
            sends[j * (count + 1) + t] = send ? 1u : 0u;
        }
    }
};

/// Writes owned tet t's record for each rank j it goes to, at place at[j * (count + 1) + t] of that
/// rank's records (the exclusive sum of ChooseRanks' flags: the next place differs where it goes).
struct PackRecords {
    std::uint32_t object;
    std::uint64_t count;
    const std::uint32_t* tet_ids;     ///< global ids of the owned tets
    const std::uint32_t* tets;        ///< 4 held-vertex indices per owned tet
    const std::uint32_t* vertex_ids;  ///< global id of each held vertex
    const float* positions;           ///< x y z per held vertex
    const std::uint32_t* at;
    std::uint32_t ranks;
    TetRecord* const* records;        ///< [j]: where rank j's records of this object begin
    KDET_HD void operator()(std::uint64_t t) const {
        for (std::uint32_t j = 0; j < ranks; ++j) {
            const std::uint32_t* places = at + j * (count + 1);
            if (places[t + 1] == places[t]) continue;
            TetRecord& rec = records[j][places[t]];
            rec.object = object;
            rec.tet = tet_ids[t];
            for (int c = 0; c < 4; ++c) {
                const std::uint32_t h = tets[4 * t + static_cast<std::uint64_t>(c)];
                rec.vertex[c] = vertex_ids[h];
                for (int k = 0; k < 3; ++k) rec.position[3 * c + k] = positions[3 * std::uint64_t{h} + static_cast<std::uint64_t>(k)];
            }
        }
    }
};

} // namespace kdet::mpi::detail
