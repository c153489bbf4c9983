#pragma once
/// @file point_location.hpp
/// @brief Point location's kernels (Locator, locate_driver.hpp, drives them): a hashed grid of the
/// located tets, then per point the tets that hold it and, for `within`, the nearest one, then the
/// hits described (barycentric coordinates, closest points, distances) and indexed per point.
///
/// The grid is the hierarchical one of the collision pipeline (grid_math.hpp: layer l has cell size
/// c0 * 2^l, a tet goes to the layer whose cells its box's extent fits, so it spans at most two cells
/// per axis), filled by the pipeline's populate step (PopulateKernel) and stored for queries by points
/// instead of tets: each (cell slot, tet) is one 64-bit key,
/// sorted, and a table gives each slot's run of keys. A point visits one cell per occupied layer;
/// a box (a point grown by `within`) the cells it overlaps. Cells whose hashes share a slot only add
/// candidates: every candidate passes a box test and the exact test.

#include "exec/atomic.hpp"
#include "geometry/point_tet.hpp"
#include "grid/grid_math.hpp"
#include "pipeline/bounding_boxes.hpp"
#include "pipeline/grid_populate.hpp"
#include "pipeline/pair_keys.hpp"
#include "pipeline/scene_view.hpp"

#include <kdet/options.hpp>

#include <cstdint>

namespace kdet {

/// @brief What point location's kernels count and find, in the backend's memory; read by the host
/// between the steps.
struct LocateCounters {
    alignas(64) unsigned long long entries; ///< grid keys appended (counts past the buffer's end)
    alignas(64) unsigned long long hits;    ///< hit keys appended (counts past the buffer's end)
    alignas(64) std::uint32_t big_count;    ///< tets too large for the top layer's cells
    unsigned long long points;              ///< the query points (the count the sort of their order reads)
    std::uint32_t layer_mask;
    std::uint32_t first_non_finite_point;
    OrderedBox region; ///< the located tets' boxes
    std::uint32_t octaves[float_octaves]; ///< histogram of the tets' box extents (float_octave)
};

/// @brief The largest side of a box (infinite where the sides overflow float: such a tet goes to the
/// top layer and, spanning too many cells there, to the list every query scans).
KDET_HD inline float box_extent(const Aabb& b) {
    return max_f(b.hi.x - b.lo.x, max_f(b.hi.y - b.lo.y, b.hi.z - b.lo.z));
}

/// @brief Per located tet (stored tets first .. first + count): its box and orientation (each query
/// that tests the tet reads it instead of computing it), the histogram of extents and the region.
struct LocateTetBoxesKernel {
    const vec3* positions;
    const TetIndices* tets;
    std::uint32_t first;
    Aabb* boxes; ///< per located tet
    std::int8_t* orientation; ///< per located tet: point_query::orient3d_sign of its vertices
    LocateCounters* counters;
    KDET_HD void operator()(std::uint64_t i) const {
        vec3 v[4];
        for (int k = 0; k < 4; ++k) v[k] = positions[tets[first + i].v[k]];
        const Aabb box = tet_box(v);
        boxes[i] = box;
        orientation[i] = static_cast<std::int8_t>(point_query::orient3d_sign(v[0], v[1], v[2], v[3]));
        atomic_fetch_add_gathered(&counters->octaves[float_octave(box_extent(box))], 1u);
        const float lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
        for (int a = 0; a < 3; ++a) {
            atomic_lower_to(&counters->region.lo[a], float_to_ordered(lo[a]));
            atomic_raise_to(&counters->region.hi[a], float_to_ordered(hi[a]));
        }
    }
};

/// @brief Bits of a located tet's index in a grid key's low word.
constexpr std::uint64_t locate_key_low = 0xffffffffull;

/// @brief The table slot of a cell.
KDET_HD inline std::uint32_t locate_slot(HashFunction hash, std::uint32_t x, std::uint32_t y, std::uint32_t z, int layer,
                                         std::uint32_t slot_bits) {
    return table_slot(hash_cell(hash, make_cell(x, y, z, layer), 0u), slot_bits);
}

/// @brief What point location's grid stores (run by the populate step, PopulateKernel): per located
/// tet, on the layer its box's extent picks, a key (slot << 32 | tet) per cell its box overlaps, or,
/// when it spans more than two cells along an axis there (larger than the top layer's cells), its
/// index in the list that every query scans.
struct LocateCells {
    const Aabb* boxes;
    GridParams grid;
    HashFunction hash;
    std::uint32_t slot_bits;
    KeyAppender out;
    std::uint32_t* big; ///< [located tets]
    LocateCounters* counters;

    struct Tet {
        std::uint64_t keys[8];
        std::uint32_t count;
        std::uint32_t id;
        int layer;
    };
    KDET_HD const GridParams& params() const { return grid; }
    KDET_HD bool place(std::uint64_t i, Aabb& box, int& layer) const {
        box = boxes[i];
        layer = layer_of(grid, box_extent(box));
        return true;
    }
    KDET_HD bool open(std::uint64_t i, const CellRange& r, int layer, Tet& tet) const {
        if (r.hi[0] - r.lo[0] > 1u || r.hi[1] - r.lo[1] > 1u || r.hi[2] - r.lo[2] > 1u) {
            big[atomic_fetch_add(&counters->big_count, 1u)] = static_cast<std::uint32_t>(i);
            return false;
        }
        const std::uint32_t bit = 1u << layer;
        if (!(atomic_load_acquire(&counters->layer_mask) & bit)) atomic_fetch_or(&counters->layer_mask, bit);
        tet.count = 0;
        tet.id = static_cast<std::uint32_t>(i);
        tet.layer = layer;
        return true;
    }
    KDET_HD bool add(Tet& tet, std::uint32_t x, std::uint32_t y, std::uint32_t z) const {
        // Two of a tet's cells that share a slot keep one key: a query scans each slot's keys once.
        const std::uint64_t key = static_cast<std::uint64_t>(locate_slot(hash, x, y, z, tet.layer, slot_bits)) << 32 | tet.id;
        for (std::uint32_t k = 0; k < tet.count; ++k)
            if (tet.keys[k] == key) return true;
        tet.keys[tet.count++] = key;
        return true;
    }
    KDET_HD void close(Tet& tet) const { out.write(tet.keys, tet.count); }
};

/// @brief After the keys are sorted: the run of keys of each slot, [begin, end) (both 0 for a slot
/// that holds none: filled so beforehand).
struct LocateSlotRunsKernel {
    const std::uint64_t* keys;
    std::uint64_t count;
    std::uint32_t* begin;
    std::uint32_t* end;
    KDET_HD void operator()(std::uint64_t i) const {
        const std::uint32_t slot = key_first(keys[i]);
        if (i == 0 || key_first(keys[i - 1]) != slot) begin[slot] = static_cast<std::uint32_t>(i);
        if (i + 1 == count || key_first(keys[i + 1]) != slot) end[slot] = static_cast<std::uint32_t>(i + 1);
    }
};

/// @brief After the keys are sorted: each key's tet box beside it, so that a query scanning a slot's
/// run reads the boxes one after the other instead of each at its tet.
struct LocateEntryBoxesKernel {
    const std::uint64_t* keys;
    const Aabb* boxes;
    Aabb* entry_boxes;
    KDET_HD void operator()(std::uint64_t k) const { entry_boxes[k] = boxes[keys[k] & locate_key_low]; }
};

/// @brief The located tets and their grid, as the queries read them.
struct LocateGridView {
    const vec3* positions;
    const TetIndices* tets;
    const std::uint32_t* user_id; ///< stored tet -> the caller's global id
    std::uint32_t first;          ///< stored id of located tet 0
    const Aabb* boxes;
    const std::int8_t* orientation; ///< per located tet
    const std::uint64_t* keys;
    const Aabb* entry_boxes; ///< the box of each key's tet
    std::uint64_t key_count;
    const std::uint32_t* begin;
    const std::uint32_t* end;
    const std::uint32_t* big;
    std::uint32_t big_count;
    GridParams params;
    HashFunction hash;
    std::uint32_t slot_bits;
    std::uint32_t layer_mask;
};

/// @brief Calls visit(t) for located tets t whose box overlaps `box`: every such tet at least once; a
/// point's box (a single cell per layer) visits each at most once, since a tet is visited only from
/// its own layer's cell. A box spanning more cells on a layer than the table has slots scans every key
/// instead.
template <class Visit>
KDET_HD inline void locate_candidates(const LocateGridView& g, const Aabb& box, Visit& visit) {
    const std::uint64_t slots = std::uint64_t{1} << g.slot_bits;
    const auto try_tet = [&](std::uint32_t t, const Aabb& b, int layer) {
        if (boxes_overlap(b, box) && (layer < 0 || layer_of(g.params, box_extent(b)) == layer)) visit(t);
    };
    for (int layer = 0; layer < g.params.layer_count; ++layer) {
        if (!((g.layer_mask >> layer) & 1u)) continue;
        const CellRange r = cell_range(g.params, box, layer);
        const std::uint64_t cells = std::uint64_t{r.hi[0] - r.lo[0] + 1} * (r.hi[1] - r.lo[1] + 1) * (r.hi[2] - r.lo[2] + 1);
        if (cells > slots) {
            for (std::uint64_t k = 0; k < g.key_count; ++k)
                try_tet(static_cast<std::uint32_t>(g.keys[k] & locate_key_low), g.entry_boxes[k], -1);
            break;
        }
        for_each_cell(r, [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
            const std::uint32_t slot = locate_slot(g.hash, x, y, z, layer, g.slot_bits);
            for (std::uint32_t k = g.begin[slot], e = g.end[slot]; k < e; ++k)
                try_tet(static_cast<std::uint32_t>(g.keys[k] & locate_key_low), g.entry_boxes[k], layer);
            return true;
        });
    }
    for (std::uint32_t k = 0; k < g.big_count; ++k) try_tet(g.big[k], g.boxes[g.big[k]], -1);
}

/// @brief A hit's key: the point in the high word, the tet's global id (the caller's) in the low one.
KDET_HD inline std::uint64_t hit_key(std::uint64_t point, std::uint32_t user_tet) { return point << 32 | user_tet; }

KDET_HD inline void load_located(const LocateGridView& g, std::uint32_t stored, vec3 v[4]) {
    for (int k = 0; k < 4; ++k) v[k] = g.positions[g.tets[stored].v[k]];
}

/// @brief Per point: its key in the order the queries run, the Morton code of its place in a grid of
/// 1024 cells per axis over the located tets' region (high word) and its index (low word): queries in
/// that order read the cells their neighbours just read, where queries in the caller's order (at
/// random, say) fetched each cell's keys and boxes from memory anew.
struct LocatePointOrderKernel {
    const vec3* points;
    vec3 lo;
    vec3 scale; ///< order cells per unit along each axis
    std::uint64_t* keys;
    KDET_HD static std::uint32_t cell(float x, float lo, float scale) {
        const float v = (x - lo) * scale;
        return v >= 0.0f ? static_cast<std::uint32_t>(v < 1023.0f ? v : 1023.0f) : 0u; // NaN: 0
    }
    KDET_HD void operator()(std::uint64_t i) const {
        const vec3 p = points[i];
        const std::uint32_t code = hash_detail::spread_bits_3(cell(p.x, lo.x, scale.x)) |
                                   hash_detail::spread_bits_3(cell(p.y, lo.y, scale.y)) << 1 |
                                   hash_detail::spread_bits_3(cell(p.z, lo.z, scale.z)) << 2;
        keys[i] = static_cast<std::uint64_t>(code) << 32 | i;
    }
};

/// @brief Per query (item): its point's coordinates, copied from the caller's order into the queries'
/// (one pass whose reads overlap, where each query's read of its point waited on memory).
struct LocateSortedPointsKernel {
    const vec3* points;
    const std::uint64_t* order; ///< LocatePointOrderKernel's keys, sorted
    vec3* sorted;
    KDET_HD void operator()(std::uint64_t item) const { sorted[item] = points[key_second(order[item])]; }
};

/// @brief Per query: a hit for every tet that holds its point (exactly), and whether it has one.
struct LocateContainingKernel {
    LocateGridView grid;
    const vec3* points;         ///< per query (LocateSortedPointsKernel)
    const std::uint64_t* order; ///< LocatePointOrderKernel's keys, sorted: item i queries point key_second(order[i])
    KeyAppender out;
    std::uint8_t* held; ///< per query
    struct Visit {
        const LocateGridView* grid;
        vec3 p;
        std::uint64_t point;
        KeyBatch* batch;
        std::uint32_t hits;
        KDET_HD void operator()(std::uint32_t t) {
            const std::uint32_t stored = grid->first + t;
            vec3 v[4];
            load_located(*grid, stored, v);
            point_query::PointTetSigns signs;
            if (!point_query::tet_holds_point(v, p, grid->orientation[t], signs)) return;
            batch->push(hit_key(point, grid->user_id[stored]));
            ++hits;
        }
    };
    KDET_HD void operator()(std::uint64_t item) const {
        const std::uint32_t i = key_second(order[item]);
        const vec3 p = points[item];
        KeyBatch batch(&out);
        Visit visit{&grid, p, i, &batch, 0};
        locate_candidates(grid, Aabb{p, p}, visit);
        batch.flush();
        held[item] = visit.hits > 0 ? 1 : 0;
    }
};

/// @brief The float below (down) or above x - d or x + d in double: a box that holds every point
/// within d of x.
KDET_HD inline float grown_down(float x, double d) {
    const double target = static_cast<double>(x) - d;
    float f = static_cast<float>(target);
    if (static_cast<double>(f) > target) f = next_float_down(f);
    return f;
}
KDET_HD inline float grown_up(float x, double d) {
    const double target = static_cast<double>(x) + d;
    float f = static_cast<float>(target);
    if (static_cast<double>(f) < target) f = next_float_up(f);
    return f;
}

/// @brief Per point that no tet holds: a hit for the nearest tet at distance at most `within` (the
/// smaller global id on a tie), if any.
struct LocateNearestKernel {
    LocateGridView grid;
    const vec3* points;         ///< as LocateContainingKernel's
    const std::uint64_t* order; ///< as LocateContainingKernel's
    const std::uint8_t* held;   ///< per query
    double within;
    KeyAppender out;
    struct Visit {
        const LocateGridView* grid;
        vec3 p;
        double best_distance;
        std::uint32_t best; ///< the caller's global id, or none
        KDET_HD void operator()(std::uint32_t t) {
            const std::uint32_t stored = grid->first + t;
            vec3 v[4];
            load_located(*grid, stored, v);
            const double d = point_query::closest_on_tet_boundary(v, p).distance;
            const std::uint32_t id = grid->user_id[stored];
            if (d < best_distance || (d == best_distance && id < best)) {
                best_distance = d;
                best = id;
            }
        }
    };
    KDET_HD void operator()(std::uint64_t item) const {
        if (held[item]) return;
        const std::uint32_t i = key_second(order[item]);
        const vec3 p = points[item];
        const Aabb box{{grown_down(p.x, within), grown_down(p.y, within), grown_down(p.z, within)},
                       {grown_up(p.x, within), grown_up(p.y, within), grown_up(p.z, within)}};
        Visit visit{&grid, p, within, 0xffffffffu};
        locate_candidates(grid, box, visit);
        if (visit.best != 0xffffffffu) out.push(hit_key(i, visit.best));
    }
};

/// @brief The located scene as the description of hits reads it.
struct LocateHitsView {
    const vec3* positions;
    const TetIndices* tets;
    const std::uint32_t* stored_id;        ///< the caller's global id -> stored tet
    const std::uint32_t* tet_object;       ///< per stored tet
    const std::uint32_t* object_tet_begin; ///< the caller's global id of each object's first tet
    const vec3* points;
};

/// @brief Per sorted hit: its object, tet, barycentric coordinates, closest point and distance.
struct LocateDescribeKernel {
    LocateHitsView scene;
    const std::uint64_t* keys;
    std::uint32_t* objects;
    std::uint32_t* tets;
    double* barycentrics;
    double* closest_points;
    double* distances;
    KDET_HD void operator()(std::uint64_t h) const {
        const std::uint64_t key = keys[h];
        const vec3 p = scene.points[key_first(key)];
        const std::uint32_t user = key_second(key), stored = scene.stored_id[user];
        vec3 v[4];
        for (int k = 0; k < 4; ++k) v[k] = scene.positions[scene.tets[stored].v[k]];
        point_query::PointTetSigns signs;
        const bool holds = point_query::tet_holds_point(v, p, signs);
        const point_query::PointInTet where = point_query::locate_in_tet(v, p, holds, signs);
        const std::uint32_t object = scene.tet_object[stored];
        objects[h] = object;
        tets[h] = user - scene.object_tet_begin[object];
        for (int k = 0; k < 4; ++k) barycentrics[4 * h + k] = where.barycentric[k];
        closest_points[3 * h] = where.closest.x;
        closest_points[3 * h + 1] = where.closest.y;
        closest_points[3 * h + 2] = where.closest.z;
        distances[h] = where.distance;
    }
};

/// @brief Per point p (and one past the last): offsets[p], the first sorted hit of a point >= p.
struct LocateOffsetsKernel {
    const std::uint64_t* keys;
    std::uint64_t count;
    std::uint64_t* offsets;
    KDET_HD void operator()(std::uint64_t p) const {
        std::uint64_t lo = 0, hi = count;
        while (lo < hi) {
            const std::uint64_t mid = lo + (hi - lo) / 2;
            if ((keys[mid] >> 32) < p)
                lo = mid + 1;
            else
                hi = mid;
        }
        offsets[p] = lo;
    }
};

} // namespace kdet
