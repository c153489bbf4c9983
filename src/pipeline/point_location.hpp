#pragma once
/// @file point_location.hpp
/// @brief Point location's kernels (Locator, locate_driver.hpp, drives them): the query points in a
/// grid, then per located tet the points in its box tested exactly and the hits described there,
/// then, for `within`, the nearest tet of each point no tet holds from a tree of the tets' boxes,
/// then the hits sorted by point and indexed.
///
/// The points are gridded, not the tets: each point is one key (slot << 32 | point) per layer that
/// some tet uses, sorted, and a table gives each slot's run (dense rows of cells where the region's
/// cells are few, LocateGrid::dense; hashed blocks of cells along x otherwise). A tet reads only the
/// cells of its own layer that its box overlaps, so it meets each point in its box once, with its
/// vertices loaded and its orientation computed once for all of them. Cell sizes are powers of two
/// (layer l: c0 * 2^l, along x a quarter of that unless a dense table cannot hold those), and a tet's
/// layer depends only on the binary exponent of its box's extent: a tet whose extent lies in
/// [c_l, 2 c_l) goes to layer l and spans at most three cells of c_l per axis there. Blocks whose hashes
/// share slots only add candidates: a point is taken from a hashed block only if it lies in the
/// tet's box and that is its own block on the layer (each layer has slots of its own).

#include "exec/atomic.hpp"
#include "geometry/point_tet.hpp"
#include "grid/grid_math.hpp"
#include "grid/hash.hpp"
#include "pipeline/bounding_boxes.hpp"
#include "pipeline/nearest_tree.hpp"
#include "pipeline/pair_keys.hpp"
#include "pipeline/tet_runs.hpp"

#include <kdet/options.hpp>

#include <cstdint>

namespace kdet {

/// @brief What point location's kernels count and find, in the backend's memory; read by the host
/// between the steps.
struct LocateCounters {
    alignas(64) unsigned long long hits; ///< hits appended (counts past the buffer's end)
    unsigned long long point_keys;      ///< the points' grid keys (the count their sort reads)
    std::uint32_t first_non_finite_point;
    OrderedBox region;                       ///< the located tets' boxes
    std::uint32_t sampled[float_octaves];          ///< histogram of every eighth tet's box extent (float_octave)
    std::uint32_t present[float_octaves / 32];     ///< bit e: some tet's extent is in bin e
};

/// @brief The largest side of a box (infinite where the sides overflow float: such a tet goes to the
/// top layer).
KDET_HD inline float box_extent(const Aabb& b) {
    return max_f(b.hi.x - b.lo.x, max_f(b.hi.y - b.lo.y, b.hi.z - b.lo.z));
}

/// @brief A hashed grid's cells go to its table in blocks of this many neighbours along x: the hash
/// of (x / block, y, z, layer) picks a block of slots, and the cells of a block take its slots in
/// order, so that a tet's cells along x are one or two runs of points, as in a dense row.
constexpr std::uint32_t locate_block_bits = 7;
constexpr std::uint32_t locate_block_cells = 1u << locate_block_bits;

/// @brief The points' grid: cells of layer l are c0 * 2^l with c0 = 2^(base_octave - 127), the lower
/// end of float_octave bin base_octave (the median of the tets' extents). Each layer the tets use has
/// slots of its own, from layer_slots[l] on: a slot holds one layer's points. Where the region's cells
/// on those layers are few (`dense`), a cell's slot is its index in the region, x fastest, so that a
/// tet's cells along x are neighbours in the table and their points in the sorted keys; otherwise
/// the hash of the cell's block (locate_block_bits) picks one of 2^slot_bits / locate_block_cells
/// blocks of slots.
struct LocateGrid {
    GridParams params;
    std::uint32_t base_octave;
    HashFunction hash;
    std::uint32_t slot_bits;
    bool dense;
    int refine[3]; ///< cells along axis a are 2^refine[a] times thinner than c_l (the rows along x)
    std::uint32_t layer_slots[max_grid_layers];
    std::uint32_t cells[max_grid_layers][2]; ///< dense: the region's cells along x and y per layer
};

/// @brief The layer of a box of extent `extent`: bin base_octave + l of float_octave goes to layer l
/// (the bins below to layer 0, those above the top layer to it), so that the box spans at most three
/// cells per axis but on the top layer. Only the extent's bits decide it: the host predicts from the
/// histograms which layers the tets use.
KDET_HD inline int locate_layer_of_octave(const LocateGrid& g, std::uint32_t octave) {
    const int layer = octave > g.base_octave ? static_cast<int>(octave - g.base_octave) : 0;
    return layer < g.params.layer_count ? layer : g.params.layer_count - 1;
}
KDET_HD inline int locate_layer(const LocateGrid& g, float extent) { return locate_layer_of_octave(g, float_octave(extent)); }

/// @brief Cell index of coordinate x along axis a on `layer` (cell_index, monotone in x).
KDET_HD inline std::uint32_t locate_cell(const LocateGrid& g, float x, int axis, int layer) {
    const float origin = axis == 0 ? g.params.origin.x : axis == 1 ? g.params.origin.y : g.params.origin.z;
    return cell_index(g.params, x, origin, layer - g.refine[axis]);
}
KDET_HD inline CellRange locate_cell_range(const LocateGrid& g, const Aabb& box, int layer) {
    CellRange r;
    r.lo[0] = locate_cell(g, box.lo.x, 0, layer);
    r.lo[1] = locate_cell(g, box.lo.y, 1, layer);
    r.lo[2] = locate_cell(g, box.lo.z, 2, layer);
    r.hi[0] = locate_cell(g, box.hi.x, 0, layer);
    r.hi[1] = locate_cell(g, box.hi.y, 1, layer);
    r.hi[2] = locate_cell(g, box.hi.z, 2, layer);
    return r;
}

/// @brief The table slot of a cell of a layer the tets use.
KDET_HD inline std::uint32_t locate_slot(const LocateGrid& g, std::uint32_t x, std::uint32_t y, std::uint32_t z, int layer) {
    if (g.dense) return g.layer_slots[layer] + (z * g.cells[layer][1] + y) * g.cells[layer][0] + x;
    const std::uint32_t block = table_slot(hash_cell(g.hash, make_cell(x >> locate_block_bits, y, z, layer), 0u),
                                           g.slot_bits - locate_block_bits);
    return g.layer_slots[layer] + (block << locate_block_bits) + (x & (locate_block_cells - 1));
}

/// @brief Per located tet (stored tets first .. first + count): the bin of its box's extent (which
/// decides the layer its points are gridded on), the histogram of a sample of the extents (which only
/// sizes the cells: a count per tet contended for a few bins' counters) and the region of the boxes.
struct LocateTetBoxesKernel {
    const vec3* positions;
    const TetIndices* tets;
    std::uint32_t first;
    LocateCounters* counters;
    KDET_HD static void mark_present(std::uint32_t* bits, std::uint32_t octave) {
        std::uint32_t* word = &bits[octave / 32];
        const std::uint32_t bit = 1u << (octave % 32);
        if (!(atomic_load_acquire(word) & bit)) atomic_fetch_or(word, bit);
    }
    KDET_HD void operator()(std::uint64_t i) const {
        vec3 v[4];
        for (int k = 0; k < 4; ++k) v[k] = positions[tets[first + i].v[k]];
        const Aabb box = tet_box(v);
        const std::uint32_t octave = float_octave(box_extent(box));
        if (i % 8 == 0) atomic_fetch_add_gathered(&counters->sampled[octave], 1u);
        mark_present(counters->present, octave);
        const float lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
        for (int a = 0; a < 3; ++a) {
            atomic_lower_to(&counters->region.lo[a], float_to_ordered(lo[a]));
            atomic_raise_to(&counters->region.hi[a], float_to_ordered(hi[a]));
        }
    }
};

/// @brief Per point: its keys, one per layer the tets use (slot << 32 | point, at point * layers +
/// j), or, for a point outside the region that the tets' boxes cover, which no tet can hold,
/// `no_point_key` in each: sorted after every other key.
struct LocatePointKeysKernel {
    const vec3* points;
    LocateGrid grid;
    Aabb region;
    std::uint32_t layer_mask;
    std::uint32_t layers; ///< set bits of layer_mask
    std::uint64_t no_point_key;
    std::uint64_t* keys;
    KDET_HD void operator()(std::uint64_t i) const {
        const vec3 p = points[i];
        std::uint64_t* out = keys + i * layers;
        if (!box_holds(region, p)) {
            for (std::uint32_t j = 0; j < layers; ++j) out[j] = no_point_key;
            return;
        }
        std::uint32_t j = 0;
        for (int layer = 0; layer < grid.params.layer_count; ++layer) {
            if (!((layer_mask >> layer) & 1u)) continue;
            const std::uint32_t x = locate_cell(grid, p.x, 0, layer), y = locate_cell(grid, p.y, 1, layer), z = locate_cell(grid, p.z, 2, layer);
            out[j++] = static_cast<std::uint64_t>(locate_slot(grid, x, y, z, layer)) << 32 | i;
        }
    }
};

/// @brief For keys sorted by their high word: start[r] = the first key whose high word is >= r, for r
/// up to `runs` (keys whose high word is `runs` or more end the last run). Each start is written by
/// the one key that follows it; with no keys, nothing is (the caller fills them).
template <class Index>
struct KeyRunStartsKernel {
    const std::uint64_t* keys;
    std::uint64_t count;
    std::uint32_t runs;
    Index* start; ///< [runs + 1]
    KDET_HD void operator()(std::uint64_t k) const {
        const std::uint32_t run = key_first(keys[k]);
        const std::uint32_t from = k == 0 ? 0u : key_first(keys[k - 1]) + 1u;
        for (std::uint32_t r = from; r <= run && r <= runs; ++r) start[r] = static_cast<Index>(k);
        if (k + 1 == count)
            for (std::uint32_t r = run + 1; r <= runs; ++r) start[r] = static_cast<Index>(count);
    }
};

/// @brief After the point keys are sorted: each key's point, so that a tet scanning a slot's run
/// reads the coordinates one after the other (the keys of points outside the region, whose slot is
/// one past the table's, have none).
struct LocateSortedPointsKernel {
    const std::uint64_t* keys;
    std::uint32_t slots;
    const vec3* points;
    vec3* sorted;
    KDET_HD void operator()(std::uint64_t k) const {
        if (key_first(keys[k]) < slots) sorted[k] = points[key_second(keys[k])];
    }
};

/// @brief The gridded points as the tets read them.
struct LocatePointsView {
    LocateGrid grid;
    const std::uint32_t* start; ///< each slot's first entry (KeyRunStartsKernel), one past the table's last
    const std::uint64_t* keys; ///< sorted: key k's point is key_second(keys[k])
    const vec3* sorted;        ///< key k's point's coordinates
    const vec3* points; ///< every point, in the caller's order
    std::uint32_t point_count;
};

/// @brief Calls visit(i, p) once for each point i (at p) that `box` holds: from the cells of the box's
/// layer that it overlaps (a dense grid's row of them at once), or, when those are more than there
/// are points, from all points.
template <class Visit>
KDET_HD inline void for_each_point_in_box(const LocatePointsView& g, const Aabb& box, Visit&& visit) {
    const int layer = locate_layer(g.grid, box_extent(box));
    const CellRange r = locate_cell_range(g.grid, box, layer);
    const std::uint64_t span[3] = {std::uint64_t{r.hi[0] - r.lo[0]} + 1, std::uint64_t{r.hi[1] - r.lo[1]} + 1,
                                   std::uint64_t{r.hi[2] - r.lo[2]} + 1};
    // Checked one axis at a time: the product of three spans of up to 2^30 cells overflows.
    const bool few_cells = span[0] <= g.point_count && span[0] * span[1] <= g.point_count &&
                           span[0] * span[1] * span[2] <= g.point_count;
    if (!few_cells) {
        for (std::uint32_t i = 0; i < g.point_count; ++i)
            if (box_holds(box, g.points[i])) visit(i, g.points[i]);
        return;
    }
    // The points in the box are gathered without a branch (most of a run's are outside, at random)
    // and visited a batch at a time. In a hashed grid a point counts only in its own block: another
    // block whose hash shares the slots adds candidates, not hits.
    constexpr std::uint32_t batch = 16;
    std::uint32_t held[batch];
    std::uint32_t count = 0;
    const auto visit_held = [&]() {
        for (std::uint32_t j = 0; j < count; ++j) visit(key_second(g.keys[held[j]]), g.sorted[held[j]]);
        count = 0;
    };
    // The points of slots first .. last, those that `own` keeps. The loop's state is in locals:
    // through the references the lambdas share, the compiler reloaded it at every point.
    const auto scan = [&](std::uint32_t first, std::uint32_t last, const auto& own) {
        const vec3* sorted = g.sorted;
        const Aabb b = box;
        std::uint32_t n = count;
        const std::uint32_t end = g.start[last + 1];
        for (std::uint32_t k = g.start[first]; k < end; ++k) {
            const vec3 p = sorted[k];
            held[n] = k;
            n += box_holds(b, p) && own(p) ? 1u : 0u;
            if (n == batch) {
                count = n;
                visit_held();
                n = 0;
            }
        }
        count = n;
    };
    for (std::uint32_t z = r.lo[2]; z <= r.hi[2]; ++z)
        for (std::uint32_t y = r.lo[1]; y <= r.hi[1]; ++y) {
            if (g.grid.dense) {
                const std::uint32_t row = g.grid.layer_slots[layer] + (z * g.grid.cells[layer][1] + y) * g.grid.cells[layer][0];
                scan(row + r.lo[0], row + r.hi[0], [](vec3) { return true; });
                continue;
            }
            for (std::uint32_t block = r.lo[0] >> locate_block_bits; block <= r.hi[0] >> locate_block_bits; ++block) {
                const std::uint32_t from = block << locate_block_bits > r.lo[0] ? block << locate_block_bits : r.lo[0];
                const std::uint32_t block_end = (block << locate_block_bits) | (locate_block_cells - 1);
                const std::uint32_t to = block_end < r.hi[0] ? block_end : r.hi[0];
                const std::uint32_t first = locate_slot(g.grid, from, y, z, layer);
                scan(first, first + (to - from), [&](vec3 p) {
                    return (locate_cell(g.grid, p.x, 0, layer) >> locate_block_bits) == block && locate_cell(g.grid, p.y, 1, layer) == y &&
                           locate_cell(g.grid, p.z, 2, layer) == z;
                });
            }
        }
    visit_held();
}

/// @brief The located tets as the kernels read them.
struct LocateTetsView {
    const vec3* positions;
    const TetIndices* tets;
    std::uint32_t first;                   ///< stored id of located tet 0
    const std::uint32_t* user_id;          ///< stored tet -> the caller's global id
    const std::uint32_t* stored_id;        ///< the caller's global id -> stored tet
    const std::uint32_t* tet_object;       ///< per stored tet
    const std::uint32_t* object_tet_begin; ///< the caller's global id of each object's first tet
};

KDET_HD inline void load_stored_tet(const LocateTetsView& s, std::uint32_t stored, vec3 v[4]) {
    for (int k = 0; k < 4; ++k) v[k] = s.positions[s.tets[stored].v[k]];
}

/// @brief One (point, tet) answer as a kernel finds it: the tet's object and index there, and the
/// barycentric coordinates of the point (or, for a nearest tet, of its closest point). The closest
/// point is the point itself for a tet that holds it, and a nearest tet's is kept per point.
struct LocateHit {
    std::uint32_t object;
    std::uint32_t tet;
    double barycentric[4];
};

KDET_HD inline LocateHit make_hit(const LocateTetsView& s, std::uint32_t stored, const point_query::PointInTet& where) {
    LocateHit h;
    h.object = s.tet_object[stored];
    h.tet = s.user_id[stored] - s.object_tet_begin[h.object];
    for (int k = 0; k < 4; ++k) h.barycentric[k] = where.barycentric[k];
    return h;
}

/// @brief Appends hits: hit s goes to hits[s] with the key (point << 32 | s) that sorts it by point.
/// Past the capacity only the count goes on, and the step runs again with room for all.
struct HitAppender {
    std::uint64_t* keys;
    LocateHit* hits;
    std::uint64_t capacity;
    unsigned long long* count;
    KDET_HD void write(const std::uint32_t* points, const LocateHit* found, std::uint32_t n) const {
        const unsigned long long first = atomic_fetch_add_gathered(count, static_cast<unsigned long long>(n));
        for (std::uint32_t k = 0; k < n && first + k < capacity; ++k) {
            keys[first + k] = static_cast<std::uint64_t>(points[k]) << 32 | (first + k);
            hits[first + k] = found[k];
        }
    }
    KDET_HD void push(std::uint32_t point, const LocateHit& hit) const { write(&point, &hit, 1); }
};

/// @brief A work item's hits, appended Size at a time: one atomic per batch, where the threads of
/// the CPU passed the counter's cache line between them at every hit.
template <std::uint32_t Size>
struct HitBatch {
    const HitAppender* out;
    std::uint32_t n = 0;
    std::uint32_t points[Size];
    LocateHit hits[Size];
    KDET_HD explicit HitBatch(const HitAppender* appender) : out(appender) {}
    KDET_HD void push(std::uint32_t point, const LocateHit& hit) {
        points[n] = point;
        hits[n] = hit;
        if (++n == Size) flush();
    }
    KDET_HD void flush() {
        if (n) out->write(points, hits, n);
        n = 0;
    }
};

/// @brief A located tet as a group's scan tests it: its vertices, box, orientation and faces.
struct LocateMember {
    vec3 v[4];
    Aabb box;
    int orientation;
    point_query::TetFaces faces;
    std::uint32_t stored;
    LocateMember() = default;
    KDET_HD LocateMember(const LocateTetsView& scene, std::uint32_t stored_tet) : stored(stored_tet) {
        load_stored_tet(scene, stored_tet, v);
        box = tet_box(v);
        orientation = point_query::orient3d_sign(v[0], v[1], v[2], v[3]);
        faces = point_query::TetFaces(v);
    }
};

/// @brief Whether a group's scan may take `box` too: the union of its boxes stays, on every axis,
/// within a quarter more than the largest side along it (or than a quarter of the largest side of
/// all, for flat boxes). Tets that share a box (the tets of one cube of a cut grid) or nearly so
/// are then scanned once for all, and a group never reads many points that none of its boxes holds.
KDET_HD inline bool locate_group_takes(const Aabb& group, vec3 largest_sides, const Aabb& box) {
    const Aabb joint = box_union(group, box);
    const vec3 joined = joint.hi - joint.lo;
    const vec3 sides = max_v(largest_sides, box.hi - box.lo);
    const float floor = 0.25f * max_f(sides.x, max_f(sides.y, sides.z));
    return (joined.x <= 1.25f * max_f(sides.x, floor)) & (joined.y <= 1.25f * max_f(sides.y, floor)) &
           (joined.z <= 1.25f * max_f(sides.z, floor));
}

/// @brief Per run of located tets (TetRuns, Tuning::search_tets_per_item): a hit for every point a
/// tet holds (exactly), described here, where its vertices and the point's signs are at hand, and
/// appended with the run's others; with `held`, marks those points. Consecutive tets whose boxes
/// nearly coincide (locate_group_takes, at most group_size) read the points of their boxes' union
/// once, and each tests those its own box holds.
template <std::uint32_t TetsPerItem>
struct LocateContainingKernel {
    static constexpr std::uint32_t group_size = TetsPerItem < 8 ? TetsPerItem : 8;
    LocateTetsView scene;
    LocatePointsView points;
    HitAppender out;
    std::uint32_t* held; ///< per point, or null
    std::uint32_t tet_count;
    template <class Batch>
    KDET_HD void scan_group(const LocateMember* group, std::uint32_t members, const Aabb& box, Batch& batch) const {
        for_each_point_in_box(points, box, [&](std::uint32_t i, vec3 p) {
            for (std::uint32_t m = 0; m < members; ++m) {
                const LocateMember& tet = group[m];
                point_query::PointTetSigns signs;
                // A lone member's box is the scanned box, which already holds p.
                if (members > 1 && !box_holds(tet.box, p)) continue;
                if (!point_query::tet_holds_point(tet.faces, tet.v, p, tet.orientation, signs)) continue;
                batch.push(i, make_hit(scene, tet.stored, point_query::locate_in_tet(tet.v, p, true, signs)));
                if (held) atomic_store_relaxed(&held[i], 1u);
            }
        });
    }
    KDET_HD void operator()(std::uint64_t run) const {
        HitBatch<TetsPerItem == 1 ? 1 : 8> batch(&out);
        if constexpr (group_size == 1) {
            TetRuns<TetsPerItem>::for_each_tet(static_cast<std::uint32_t>(run), tet_count, [&](std::uint32_t t) {
                const LocateMember tet(scene, scene.first + t);
                scan_group(&tet, 1, tet.box, batch);
                return true;
            });
        } else {
            LocateMember group[group_size];
            std::uint32_t members = 0;
            Aabb box{};
            vec3 sides{};
            TetRuns<TetsPerItem>::for_each_tet(static_cast<std::uint32_t>(run), tet_count, [&](std::uint32_t t) {
                const LocateMember tet(scene, scene.first + t);
                if (members == group_size || (members && !locate_group_takes(box, sides, tet.box))) {
                    scan_group(group, members, box, batch);
                    members = 0;
                }
                box = members ? box_union(box, tet.box) : tet.box;
                sides = members ? max_v(sides, tet.box.hi - tet.box.lo) : tet.box.hi - tet.box.lo;
                group[members++] = tet;
                return true;
            });
            if (members) scan_group(group, members, box, batch);
        }
        batch.flush();
    }
};

/// @brief A NearestSearchOrderKernel key's high word for a point that some tet holds: past every
/// Morton code, so those points sort last.
constexpr std::uint32_t held_point_order = 1u << 30;

/// @brief Per point, for `within`: (Morton code of its place in `box`) << 32 | point, or, for a point
/// some tet holds, held_point_order << 32 | point. Sorted, neighbouring points search one after the
/// other and find the tree's nodes and tets where the one before left them.
struct NearestSearchOrderKernel {
    const vec3* points;
    const std::uint32_t* held;
    Aabb box;
    std::uint64_t* keys;
    KDET_HD void operator()(std::uint64_t i) const {
        const std::uint32_t code = held[i] ? held_point_order : morton_code_in_box(points[i], box.lo, box.hi);
        keys[i] = static_cast<std::uint64_t>(code) << 32 | i;
    }
};

/// @brief Per point that no tet holds, for `within`: the located tet nearest it, at most `within`
/// away (the least computed distance, the smaller global id on a tie), from the tree of the located
/// tets, and its hit, closest point and distance.
///
/// The search skips a node or tet whose box lies farther than the best distance so far, plus
/// `slack`: a computed distance to a tet's boundary falls short of the true one (and so of the
/// distance to its box) by a few roundings of the coordinates' size at most, so no tet that could
/// win is skipped.
struct LocateNearestKernel {
    LocateTetsView scene;
    NearestTreeView tree;
    const vec3* points;
    double within;
    float scale; ///< the largest magnitude of the tets' coordinates
    const std::uint64_t* order; ///< NearestSearchOrderKernel's keys, sorted
    HitAppender out;
    double* closest;  ///< 3 per point
    double* distance; ///< per point
    KDET_HD void operator()(std::uint64_t k) const {
        if (key_first(order[k]) == held_point_order) return;
        const std::uint32_t i = key_second(order[k]);
        const vec3 p = points[i];
        const narrow::dvec3 q = narrow::widen(p);
        const double size = max_f(scale, max_abs(p));
        const double slack = 0x1p-30 * size;
        double best = within;
        std::uint32_t best_id = 0xffffffffu, best_stored = 0;
        point_query::PointInTet best_where{};
        for_each_tet_within_reach(tree, q, [&] { return best + slack; }, [&](std::uint32_t stored) {
            vec3 v[4];
            load_stored_tet(scene, stored, v);
            const double reach = best + slack;
            if (squared_distance_to_box(tet_box(v), q) > reach * reach) return;
            const point_query::PointInTet where = point_query::closest_on_tet_boundary(v, p);
            const std::uint32_t id = scene.user_id[stored];
            if (where.distance < best || (where.distance == best && id < best_id)) {
                best = where.distance;
                best_id = id;
                best_stored = stored;
                best_where = where;
            }
        });
        if (best_id == 0xffffffffu) return;
        out.push(i, make_hit(scene, best_stored, best_where));
        closest[3 * std::uint64_t{i}] = best_where.closest.x;
        closest[3 * std::uint64_t{i} + 1] = best_where.closest.y;
        closest[3 * std::uint64_t{i} + 2] = best_where.closest.z;
        distance[i] = best_where.distance;
    }
};

/// @brief Per sorted hit: its description, from where the kernel that found it left it, into the
/// result's arrays.
struct LocateDescribeKernel {
    const std::uint64_t* keys;
    const LocateHit* hits;
    const vec3* points;
    const std::uint32_t* held;      ///< per point, or null: every hit's tet holds its point
    const double* nearest_closest;  ///< LocateNearestKernel's, for the points no tet holds
    const double* nearest_distance;
    std::uint32_t* objects;
    std::uint32_t* tets;
    double* barycentrics;
    double* closest_points;
    double* distances;
    KDET_HD void operator()(std::uint64_t h) const {
        const std::uint64_t key = keys[h];
        const std::uint32_t point = key_first(key);
        const LocateHit& hit = hits[key_second(key)];
        objects[h] = hit.object;
        tets[h] = hit.tet;
        for (int k = 0; k < 4; ++k) barycentrics[4 * h + k] = hit.barycentric[k];
        if (!held || held[point]) {
            const vec3 p = points[point];
            closest_points[3 * h] = p.x;
            closest_points[3 * h + 1] = p.y;
            closest_points[3 * h + 2] = p.z;
            distances[h] = 0.0;
            return;
        }
        for (int k = 0; k < 3; ++k) closest_points[3 * h + k] = nearest_closest[3 * std::uint64_t{point} + k];
        distances[h] = nearest_distance[point];
    }
};

/// @brief Per point: its hits (in the order they were found) sorted by object and tet; a point has
/// few, so an insertion sort.
struct LocateHitOrderKernel {
    const std::uint64_t* offsets;
    std::uint32_t* objects;
    std::uint32_t* tets;
    double* barycentrics;
    double* closest_points;
    double* distances;
    KDET_HD bool before(std::uint64_t a, std::uint64_t b) const {
        return objects[a] < objects[b] || (objects[a] == objects[b] && tets[a] < tets[b]);
    }
    KDET_HD void swap_hits(std::uint64_t a, std::uint64_t b) const {
        const auto swap = [](auto& x, auto& y) {
            const auto t = x;
            x = y;
            y = t;
        };
        swap(objects[a], objects[b]);
        swap(tets[a], tets[b]);
        for (int k = 0; k < 4; ++k) swap(barycentrics[4 * a + k], barycentrics[4 * b + k]);
        for (int k = 0; k < 3; ++k) swap(closest_points[3 * a + k], closest_points[3 * b + k]);
        swap(distances[a], distances[b]);
    }
    KDET_HD void operator()(std::uint64_t p) const {
        const std::uint64_t begin = offsets[p], end = offsets[p + 1];
        for (std::uint64_t h = begin + 1; h < end; ++h)
            for (std::uint64_t k = h; k > begin && before(k, k - 1); --k) swap_hits(k, k - 1);
    }
};

} // namespace kdet
