#pragma once
/// @file kernels.hpp
/// @brief Every per-element step of the pipeline, written once as a functor that the CPU layer runs
/// in an OpenMP loop and the CUDA layer runs as a kernel. Views hold raw pointers and counts only.

#include "geometry/enclosing_sphere.hpp"
#include "geometry/face_planes.hpp"
#include "geometry/slabs.hpp"
#include "geometry/tet_intersect.hpp"
#include "exec/radix_sort.hpp"
#include "grid/bucket_table.hpp"

#include <kdet/results.hpp>

#include <cfloat>
#include <cmath>
#include <cstdint>

namespace kdet {

struct TetIndices {
    std::uint32_t v[4]; ///< global vertex ids (object offsets applied)
};

/// @brief Per-tet data recomputed every frame.
struct TetInfo {
    Aabb box;
    /// Of the minimum enclosing sphere, for relevant tets only (TetSizeKernel); a negative value is
    /// minus the tet's longest edge instead, which bounds it (sphere_diameter_bounds), for a tet whose
    /// sphere TetSizeKernel left to GridPlanKernel (tet_layer).
    float diameter;
    std::int32_t layer; ///< grid layer, or -1 when the tet cannot collide with anything enabled
};

/// @brief All objects' geometry, concatenated; tets of one object are contiguous.
struct SceneView {
    const vec3* positions;
    const TetIndices* tets;
    const std::uint32_t* tet_object;
    TetInfo* info;
    TetPlanes* planes; ///< per tet, for the pre-test; computed for the tets that can collide this frame
    /// Per tet, for the pre-test, computed with the planes; null where the narrow phase's test may call
    /// far-apart pairs intersecting (sat_no_edges, see slabs.hpp): no pair is rejected by them then.
    TetSlabs* slabs;
    const std::uint8_t* pair_active; ///< [object_count * object_count]; diagonal = self-collision
    /// [object_count] object_bit of every object a is checked against; any_object when that is all of them
    const std::uint32_t* checked_objects;
    const Aabb* object_boxes;
    std::uint32_t tet_count;
    std::uint32_t object_count;
};

KDET_HD inline void load_vertices(const SceneView& s, const TetIndices& tet, vec3 out[4]) {
    for (int k = 0; k < 4; ++k) out[k] = s.positions[tet.v[k]];
}

KDET_HD inline void load_tet(const SceneView& s, std::uint32_t t, vec3 out[4]) { load_vertices(s, s.tets[t], out); }

/// @brief A tet's four vertex indices, each repeated over four lanes (row k holds vertex k): made once
/// for a tet compared with many, so that each comparison reads the other tet's indices as one vector.
struct SpreadIndices {
    std::uint32_t v[4][4];
};

KDET_HD inline SpreadIndices spread_indices(const TetIndices& a) {
    SpreadIndices s;
    for (int k = 0; k < 4; ++k)
        for (int i = 0; i < 4; ++i) s.v[k][i] = a.v[k];
    return s;
}

/// @brief Whether two tets share a vertex: all 16 comparisons without a branch each (about half the
/// pairs tested share one, so early exits mispredict); on the CPU b's four vertices are compared with
/// each of a's in one vector compare.
KDET_HD inline bool share_vertex(const SpreadIndices& a, const TetIndices& b) {
    std::uint32_t lane[4];
    KDET_VECTOR_LOOP
    for (int i = 0; i < 4; ++i)
        lane[i] = (b.v[i] == a.v[0][i] ? ~0u : 0u) | (b.v[i] == a.v[1][i] ? ~0u : 0u) |
                  (b.v[i] == a.v[2][i] ? ~0u : 0u) | (b.v[i] == a.v[3][i] ? ~0u : 0u);
    return lane_bits(lane) != 0;
}

KDET_HD inline bool share_vertex(const TetIndices& a, const TetIndices& b) { return share_vertex(spread_indices(a), b); }

KDET_HD inline bool pair_is_active(const SceneView& s, std::uint32_t object_a, std::uint32_t object_b) {
    return s.pair_active[static_cast<std::uint64_t>(object_a) * s.object_count + object_b] != 0;
}

/// @brief Sort key of a pair of global tet ids; the lower id goes first.
KDET_HD inline std::uint64_t pair_key(std::uint32_t t, std::uint32_t u) {
    const std::uint32_t lo = t < u ? t : u, hi = t < u ? u : t;
    return (static_cast<std::uint64_t>(lo) << 32) | hi;
}

/// @brief A candidate's key when the face-plane pre-test has already proven the pair intersecting:
/// the higher id goes first, which no pair_key does, so the narrow phase knows without testing again.
KDET_HD inline std::uint64_t proven_pair_key(std::uint32_t t, std::uint32_t u) {
    const std::uint32_t lo = t < u ? t : u, hi = t < u ? u : t;
    return (static_cast<std::uint64_t>(hi) << 32) | lo;
}
/// @brief Bits a pair key of tet ids below tet_count needs: the lower id fills the high word.
inline int pair_key_bits(std::uint32_t tet_count) { return high_word_key_bits(tet_count); }
/// @brief Bits of a pair key's low word (the higher id) that a tet id below tet_count can set.
inline int pair_key_low_word_bits(std::uint32_t tet_count) { return pair_key_bits(tet_count) - 32; }
KDET_HD inline std::uint32_t key_first(std::uint64_t key) { return static_cast<std::uint32_t>(key >> 32); }
KDET_HD inline std::uint32_t key_second(std::uint64_t key) { return static_cast<std::uint32_t>(key & 0xffffffffu); }

/// @brief The narrow-phase test alone on stored tets first < second: the lower stored id goes first, so
/// every method sees the same floating-point computation. `exact_stage` is set when the pair reached
/// the exact stage of NarrowPhase::exact. `after_pretest`: see tets_intersect_as.
template <NarrowPhase Test>
KDET_HD inline bool test_pair(const SceneView& s, std::uint32_t first, std::uint32_t second, bool& exact_stage,
                              bool after_pretest = false) {
    vec3 a[4], b[4];
    load_tet(s, first, a);
    load_tet(s, second, b);
    return tets_intersect_as<Test>(a, b, exact_stage, after_pretest);
}

/// @brief The decision for a grid method's pair (first < second) whose boxes overlap, that is not
/// adjacent and that the slabs did not separate: the face planes' verdict where they are sure (the
/// answer the test gives, see face_planes.hpp), else the test. `planes_separate` is set when the
/// planes proved the pair apart.
template <NarrowPhase Test>
KDET_HD inline bool planes_or_test_collide(const SceneView& s, std::uint32_t first, std::uint32_t second,
                                           bool& exact_stage, bool& planes_separate) {
    // Both tets' planes and the vertices beside them are this frame's.
    const TetPlanes &pa = s.planes[first], &pb = s.planes[second];
    const PlaneVerdict verdict = face_plane_pretest(pa, pa.vertex, pb, pb.vertex, false);
    planes_separate = verdict == PlaneVerdict::separated;
    if (verdict != PlaneVerdict::unsure) return verdict == PlaneVerdict::intersecting;
    return tets_intersect_as<Test>(pa.vertex, pb.vertex, exact_stage, true);
}

/// @brief The decision for a grid method's pair whose boxes overlap and that is not adjacent (first <
/// second): the pre-test where it is sure (the slabs where the scene has them, then the face planes;
/// see slabs.hpp), else the test.
template <NarrowPhase Test>
KDET_HD inline bool candidate_collides(const SceneView& s, std::uint32_t first, std::uint32_t second,
                                       bool& exact_stage) {
    if (s.slabs && slabs_separate(s.slabs[first], s.slabs[second])) return false;
    bool planes_separate = false;
    return planes_or_test_collide<Test>(s, first, second, exact_stage, planes_separate);
}

/// @brief Whether a pair of stored tets first < second needs a decision at all: not adjacent, and
/// their boxes overlap.
KDET_HD inline bool may_collide(const SceneView& s, std::uint32_t first, std::uint32_t second) {
    if (s.tet_object[first] == s.tet_object[second] && share_vertex(s.tets[first], s.tets[second])) return false;
    return boxes_overlap(s.info[first].box, s.info[second].box);
}

/// @brief The brute-force methods' predicate: adjacency, boxes, then the test itself, without the
/// pre-test, so that they stay the oracle the grid methods (which use it) are compared with.
template <NarrowPhase Test>
KDET_HD inline bool tets_collide_tested(const SceneView& s, std::uint32_t t, std::uint32_t u, bool& exact_stage) {
    const std::uint32_t first = t < u ? t : u, second = t < u ? u : t;
    return may_collide(s, first, second) && test_pair<Test>(s, first, second, exact_stage);
}

/// @brief Stage 1: box of each tet; no size and no layer yet.
struct TetBoundsKernel {
    SceneView scene;
    KDET_HD void operator()(std::uint64_t t) const {
        vec3 v[4];
        load_tet(scene, static_cast<std::uint32_t>(t), v);
        scene.info[t] = TetInfo{tet_box(v), 0.0f, -1};
    }
};

/// @brief Stage 1: the box of tet t, the value the per-object box reduction merges.
struct TetBoxOf {
    const TetInfo* info;
    KDET_HD Aabb operator()(std::uint64_t t) const { return info[t].box; }
};

/// @brief The smallest box holding two boxes.
struct BoxUnion {
    KDET_HD Aabb operator()(const Aabb& a, const Aabb& b) const { return Aabb{min_v(a.lo, b.lo), max_v(a.hi, b.hi)}; }
};

/// @brief Stage 1: puts the box of each run of tets (one run per non-empty object: its tets are
/// contiguous) at its object's place.
struct ObjectBoxesKernel {
    const std::uint32_t* run_objects;
    const Aabb* run_boxes;
    const std::uint32_t* run_count;
    Aabb* object_boxes;
    KDET_HD void operator()(std::uint64_t r) const {
        if (r < *run_count) object_boxes[run_objects[r]] = run_boxes[r];
    }
};

/// @brief A box as order-preserving integers (float_to_ordered), so that threads can merge boxes atomically.
struct OrderedBox {
    std::uint32_t lo[3], hi[3];
};

/// @brief Stage 1, one work item per object a: which pairs (a, b) are checked this frame (enabled,
/// both objects hold tets, their boxes overlap; the diagonal is self-collision), and, when a is in
/// one, its box merged into the region the grid covers and its tets counted. No tets counted: nothing
/// can collide, and every later stage finds nothing to do.
struct ObjectCullingKernel {
    const std::uint8_t* pair_enabled; ///< [object_count * object_count]
    std::uint8_t* pair_active;
    std::uint32_t* checked_objects; ///< [object_count] SceneView::checked_objects
    const Aabb* object_boxes;
    const std::uint32_t* object_tet_begin; ///< [object_count + 1]
    std::uint32_t object_count;
    OrderedBox* region;
    unsigned long long* involved_tets;

    KDET_HD void operator()(std::uint64_t a) const {
        const std::uint32_t tets = object_tet_begin[a + 1] - object_tet_begin[a];
        bool involved = false;
        std::uint32_t checked = 0;
        for (std::uint32_t b = 0; b < object_count; ++b) {
            const std::uint64_t k = a * object_count + b;
            const bool on = tets && object_tet_begin[b + 1] != object_tet_begin[b] && pair_enabled[k] &&
                            (a == b || boxes_overlap(object_boxes[a], object_boxes[b]));
            pair_active[k] = on ? 1 : 0;
            if (on) checked |= object_bit(b);
            involved = involved || on;
        }
        // Checked against every object, a tet filters none: any_object spares its scans the blocks' objects.
        checked_objects[a] = checked == all_object_bits(object_count) ? any_object : checked;
        if (!involved) return;
        const Aabb& box = object_boxes[a];
        for (int axis = 0; axis < 3; ++axis) {
            atomic_min(&region->lo[axis], float_to_ordered(component(box.lo, axis)));
            atomic_max(&region->hi[axis], float_to_ordered(component(box.hi, axis)));
        }
        atomic_fetch_add(involved_tets, static_cast<unsigned long long>(tets));
    }
};

/// @brief Every how many tets TetSizeKernel samples the spacing.
constexpr std::uint64_t spacing_sample = 8;

/// @brief How far apart two tets lie, for the grid's spacing: the largest coordinate difference of
/// their boxes' centres.
KDET_HD inline float tet_spacing(const Aabb& a, const Aabb& b) {
    const vec3 d = (a.lo + a.hi) - (b.lo + b.hi);
    return 0.5f * max_f(max_f(fabsf(d.x), fabsf(d.y)), fabsf(d.z));
}

/// @brief The median of the spacings counted in `octaves` (float_octave bins), as its bin's upper
/// end; 0 when none was counted or the median lies past 2^127 (no float ends its bin).
KDET_HD inline float median_spacing(const std::uint32_t* octaves) {
    unsigned long long total = 0;
    for (int e = 0; e < float_octaves; ++e) total += octaves[e];
    unsigned long long below = 0;
    for (int e = 0; e < float_octaves - 2; ++e) {
        below += octaves[e];
        if (total && 2 * below >= total) return float_octave_end(static_cast<std::uint32_t>(e));
    }
    return 0.0f;
}

/// @brief Stage 1, grid methods only: sizes the relevant tets and keeps the range of their sizes.
/// A tet is relevant when its object's self-collision is on, or when its box overlaps another object
/// it is checked against (inter-object culling: only tets in the overlap region are sized and gridded).
/// A relevant tet gets layer 0 until populate picks its layer; the others keep -1.
///
/// The minimum enclosing sphere (about as costly as the tet's face planes) is computed here only for
/// the tets that may be the smallest or the largest, which the grid's geometry needs exactly: those
/// whose longest-edge bounds (sphere_diameter_bounds) reach below every upper bound seen so far, or
/// above every lower bound. The smallest tet always does, since its sphere is below every tet's upper
/// bound, and likewise the largest. The others keep their longest edge, and GridPlanKernel computes
/// the sphere only when the bounds fall on two layers (tet_layer).
///
/// It also counts, by binary exponent, how far every spacing_sample-th relevant tet lies from the one
/// stored before it (tet_spacing), which GridParamsKernel takes as the spacing of the tets: a sample
/// gives the same median, and the GPU's threads then seldom add to one bin at once.
struct TetSizeKernel {
    SceneView scene;
    std::uint32_t* min_size; ///< float_to_ordered, of the spheres computed
    std::uint32_t* max_size;
    std::uint32_t* min_upper_size; ///< float_to_ordered, of the relevant tets' upper bounds
    std::uint32_t* max_lower_size;  ///< and of their lower bounds
    std::uint32_t* spacing_octaves; ///< [float_octaves] the sampled relevant tets by float_octave(tet_spacing)

    KDET_HD bool relevant(std::uint32_t object, const Aabb& box) const {
        if (pair_is_active(scene, object, object)) return true;
        for (std::uint32_t other = 0; other < scene.object_count; ++other)
            if (other != object && pair_is_active(scene, object, other) && boxes_overlap(box, scene.object_boxes[other]))
                return true;
        return false;
    }

    KDET_HD void operator()(std::uint64_t t) const {
        TetInfo& info = scene.info[t];
        if (!relevant(scene.tet_object[t], info.box)) return;
        vec3 v[4];
        load_tet(scene, static_cast<std::uint32_t>(t), v);
        info.layer = 0;
        // A scene fills a few of the bins: on a GPU a warp's adds to one bin take one atomic.
        if (t % spacing_sample == 1 && scene.tet_object[t - 1] == scene.tet_object[t])
            atomic_fetch_add_gathered(&spacing_octaves[float_octave(tet_spacing(info.box, scene.info[t - 1].box))], 1u);
        scene.planes[t] = tet_planes(v);
        if (scene.slabs) scene.slabs[t] = tet_slabs(v, scene.planes[t].longest);
        const float longest = longest_edge(v);
        const SphereDiameterBounds bounds = sphere_diameter_bounds(longest);
        const std::uint32_t lower = float_to_ordered(bounds.lower), upper = float_to_ordered(bounds.upper);
        atomic_lower_to(min_upper_size, upper);
        atomic_raise_to(max_lower_size, lower);
        if (lower > atomic_load_acquire(min_upper_size) && upper < atomic_load_acquire(max_lower_size)) {
            info.diameter = -longest;
            return;
        }
        info.diameter = enclosing_sphere_diameter(v);
        atomic_lower_to(min_size, float_to_ordered(info.diameter));
        atomic_raise_to(max_size, float_to_ordered(info.diameter));
    }
};

/// @brief Stage 1, grid methods only, one work item: the grid's geometry from the relevant tets' sizes
/// and spacings (TetSizeKernel) and the region (ObjectCullingKernel), written where the later kernels
/// read it. c0 is the smallest size, so the smallest tets sit on layer 0, unless the tets lie closer
/// together than that: then c0 is `cell_spacings` (Tuning::grid_cell_spacings) times their median
/// spacing, rounded up to a power of two, and every smaller tet shares layer 0. Cells about the
/// spacing's size each hold about one tet (a sparse soup of small tets), and every such tet costs
/// inserts into cells of its own and lookups on each of the many layers above it; in a mesh, whose
/// tets touch, the spacing is about the typical tet's size, so most of its tets share layer 0, each in
/// one or two cells per axis. The spacing is measured along the storage order, which is spatial
/// (SceneTopology): a tet's predecessor is one of its neighbours. Enough layers to hold the largest,
/// capped at max_grid_layers. No relevant tet: no layer, nothing is gridded.
struct GridParamsKernel {
    const std::uint32_t* min_size; ///< float_to_ordered
    const std::uint32_t* max_size;
    const std::uint32_t* spacing_octaves; ///< TetSizeKernel's
    const OrderedBox* region;
    GridParams* params;
    float cell_spacings; ///< how many spacings layer 0's cells span at least

    KDET_HD void operator()(std::uint64_t) const {
        if (*min_size == float_to_ordered(INFINITY)) {
            *params = GridParams{{0.0f, 0.0f, 0.0f}, 1.0f, 1.0f, 0};
            return;
        }
        const float dmin = ordered_to_float(*min_size), dmax = ordered_to_float(*max_size);
        // Zero-size tets (allowed only when the caller asked for degenerate input) must not make c0 zero.
        const float floor_size = max_f(dmax * 1e-6f, FLT_MIN * 1e6f);
        const float c0 = max_f(max_f(dmin, floor_size), cell_spacings * median_spacing(spacing_octaves));
        int layers = 1;
        for (float top = c0; layers < max_grid_layers && top < dmax; top *= 2.0f) ++layers;
        const vec3 origin{ordered_to_float(region->lo[0]), ordered_to_float(region->lo[1]),
                          ordered_to_float(region->lo[2])};
        *params = GridParams{origin, c0, 1.0f / c0, layers};
    }
};

/// @brief The layer of relevant tet t, whose TetInfo::diameter is `size`: from its sphere where
/// TetSizeKernel computed it; else from its longest-edge bounds where both fall on one layer (layers
/// grow with the size, so the sphere's does too, up to rounding); else from its sphere, computed now.
KDET_HD inline int tet_layer(const SceneView& scene, const GridParams& params, std::uint32_t t, float size) {
    if (!(size < 0.0f)) return layer_of(params, size);
    const SphereDiameterBounds bounds = sphere_diameter_bounds(-size);
    const int low = layer_of(params, bounds.lower), high = layer_of(params, bounds.upper);
    if (low == high) return low;
    vec3 v[4];
    load_tet(scene, t, v);
    return layer_of(params, enclosing_sphere_diameter(v));
}

/// @brief Cells in a range.
KDET_HD inline unsigned long long cell_count(const CellRange& r) {
    return static_cast<unsigned long long>(r.hi[0] - r.lo[0] + 1) * (r.hi[1] - r.lo[1] + 1) * (r.hi[2] - r.lo[2] + 1);
}

/// @brief Cells in both ranges.
KDET_HD inline unsigned long long shared_cell_count(const CellRange& a, const CellRange& b) {
    unsigned long long n = 1;
    for (int axis = 0; axis < 3; ++axis) {
        const std::uint32_t lo = a.lo[axis] > b.lo[axis] ? a.lo[axis] : b.lo[axis];
        const std::uint32_t hi = a.hi[axis] < b.hi[axis] ? a.hi[axis] : b.hi[axis];
        if (hi < lo) return 0;
        n *= hi - lo + 1;
    }
    return n;
}

/// @brief Stage 2, before populating: picks each relevant tet's layer and counts, per layer, the
/// cell entries the tets there will be inserted into, and a bound on the cells they occupy, so that
/// the host can size the table before filling it. One work item per chunk of tets; neighbouring tets
/// (spatial order) mostly share a layer, so the counts are added atomically only when the layer
/// changes along the chunk. The bound counts the cells of each tet that the chunk's previous tet did
/// not cover: an occupied cell is counted at least once, in every chunk where it first appears, and
/// neighbours in the spatial order share most of their cells, so the bound stays close to the truth
/// where the entries overestimate the cells many times (every cell holds tens of tets).
struct GridPlanKernel {
    SceneView scene;
    const GridParams* grid_params; ///< GridParamsKernel's
    std::uint32_t chunk;
    unsigned long long* layer_entries; ///< [max_grid_layers]
    unsigned long long* layer_cells;   ///< [max_grid_layers]
    std::uint32_t* layer_mask;

    KDET_HD void operator()(std::uint64_t c) const {
        const std::uint64_t begin = c * chunk;
        const std::uint64_t end = begin + chunk < scene.tet_count ? begin + chunk : scene.tet_count;
        const GridParams params = *grid_params;
        int run_layer = -1;
        unsigned long long run_entries = 0, run_cells = 0;
        CellRange previous{};
        std::uint32_t mask = 0;
        for (std::uint64_t t = begin; t < end; ++t) {
            TetInfo& info = scene.info[t];
            if (info.layer < 0) continue;
            const int layer = tet_layer(scene, params, static_cast<std::uint32_t>(t), info.diameter);
            info.layer = layer;
            const CellRange r = cell_range(params, info.box, layer);
            const unsigned long long cells = cell_count(r);
            if (layer != run_layer) {
                if (run_entries) {
                    atomic_fetch_add(&layer_entries[run_layer], run_entries);
                    atomic_fetch_add(&layer_cells[run_layer], run_cells);
                }
                run_layer = layer;
                run_entries = run_cells = 0;
                previous = CellRange{{1, 1, 1}, {0, 0, 0}}; // empty: shares no cell
            }
            run_entries += cells;
            run_cells += cells - shared_cell_count(r, previous);
            previous = r;
            mask |= 1u << layer;
        }
        if (run_entries) {
            atomic_fetch_add(&layer_entries[run_layer], run_entries);
            atomic_fetch_add(&layer_cells[run_layer], run_cells);
        }
        if (mask) atomic_fetch_or(layer_mask, mask);
    }
};

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

/// @brief A buffer slot that holds no pair: a batch that did not fit leaves it in the slots it got
/// below the capacity, so every slot below the count is defined. (t, t) is never a pair.
constexpr std::uint64_t no_pair_key = ~0ull;

/// @brief Appends to a buffer of `capacity` keys; the counter keeps counting past it, so the host
/// learns the size a rerun needs from the writers that go on appending. A batch is stored whole or
/// not at all.
struct KeyAppender {
    std::uint64_t* keys;
    std::uint64_t capacity;
    unsigned long long* count;
    /// Slots filled with no_pair_key by a batch that straddled the capacity; null where every batch
    /// is a single key, which fits or not, or where a buffer that overflows is never read (the
    /// narrow phase's pairs: the frame runs again).
    unsigned long long* padding;
    KDET_HD bool push(std::uint64_t key) const { return write(&key, 1); }
    KDET_HD bool write(const std::uint64_t* batch, std::uint32_t n) const {
        const unsigned long long first = atomic_fetch_add_gathered(count, static_cast<unsigned long long>(n));
        if (first + n <= capacity) {
            for (std::uint32_t k = 0; k < n; ++k) keys[first + k] = batch[k];
            return true;
        }
        if (first < capacity && padding) {
            for (unsigned long long k = first; k < capacity; ++k) keys[k] = no_pair_key;
            atomic_fetch_add(padding, static_cast<unsigned long long>(capacity - first));
        }
        return false;
    }
};

/// @brief Where a work item stopped when the buffer it appends to was full: after growing, the
/// stage reruns only such items, each skipping the keys it had already stored.
struct ResumePoint {
    std::uint32_t item;
    std::uint32_t stored;
};

/// @brief One work item's keys, handed to a KeyAppender a batch at a time: one atomic per batch
/// instead of one per key, which matters when many threads append at once. Once a batch has not
/// fit, the item is `stopped`: if it goes on (to count the room a rerun needs), later batches only
/// count (every later slot is past the capacity); in a first frame it stops searching at once
/// (FindCandidatesKernel::stop_when_full).
struct KeyBatch {
    static constexpr std::uint32_t size = 16;
    const KeyAppender* out;
    std::uint32_t skip;   ///< keys an earlier run of this item stored: not written again
    std::uint32_t stored; ///< keys of this item in the buffer, the skipped ones included
    bool stopped = false;
    std::uint64_t keys[size];
    std::uint32_t n = 0;
    KDET_HD explicit KeyBatch(const KeyAppender* appender, std::uint32_t already_stored = 0)
        : out(appender), skip(already_stored), stored(already_stored) {}
    KDET_HD void push(std::uint64_t key) {
        if (skip) {
            --skip;
            return;
        }
        keys[n++] = key;
        if (n == size) flush();
    }
    KDET_HD void flush() {
        if (!n) return;
        // Once a batch has not fit, none does: the count only grows.
        if (out->write(keys, n))
            stored += n;
        else
            stopped = true;
        n = 0;
    }
};

/// @brief The runs of consecutive tets that the grid's searches take per work item
/// (Tuning::search_tets_per_item): how many there are for `tets` tets, and the tets [first, end) of run r
/// (the last run may be shorter).
template <std::uint32_t TetsPerItem>
struct TetRuns {
    KDET_HD static std::uint32_t count(std::uint32_t tets) { return tets / TetsPerItem + (tets % TetsPerItem ? 1u : 0u); }
    KDET_HD static std::uint32_t first(std::uint32_t r) { return r * TetsPerItem; }
    KDET_HD static std::uint32_t end(std::uint32_t r, std::uint32_t tets) {
        return tets - first(r) < TetsPerItem ? tets : first(r) + TetsPerItem;
    }
    /// @brief Calls f(t) for the tets t of run r in order while f returns true; a run of one tet (the
    /// GPU's) without a loop, which cost the GPU's search kernel about 30 registers.
    template <class F>
    KDET_HD static void for_each_tet(std::uint32_t r, std::uint32_t tets, F&& f) {
        if constexpr (TetsPerItem == 1) {
            f(r);
        } else {
            for (std::uint32_t t = first(r), e = end(r, tets); t < e && f(t); ++t) {
            }
        }
    }
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
        KDET_HD void operator()(const GridEntry& e) {
            const std::uint32_t u = e.id();
            // Tets of one object that share a vertex are skipped first: they touch, so the slabs would
            // never separate them, and a self-colliding mesh's box-overlapping pairs hold many (its
            // neighbours); u's indices are loaded only for a pair within one object. Then the slabs,
            // whose 64 bytes separate about half of the rest (slabs.hpp), before the face planes.
            if (e.object == object && share_vertex(tet, scene->tets[u])) return;
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
            const PlaneVerdict verdict = face_plane_pretest(planes, planes.vertex, other, other.vertex, false);
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
                  FacePlanesInSearch ? scene.planes[t] : TetPlanes{}, scene.slabs ? scene.slabs[t] : TetSlabs{}, 0};
        const GridParams grid_params = *params;
        for_each_larger_neighbour(scene, grid, grid_params, *layer_mask, t, emit, part);
        return emit.rejected;
    }

    KDET_HD void record_stop(const ResumePoint& point) const {
        const std::uint32_t slot = atomic_fetch_add(stopped_count, 1u);
        if (slot < stopped_capacity) stopped[slot] = point;
    }
};

/// @brief The thesis's old method (algorithm 4.2): test inline and only flag colliding tets,
/// skipping a pair when both tets are already flagged. An item searches a run of TetsPerItem tets
/// (TetRuns) and adds its counts once.
template <NarrowPhase Test, std::uint32_t TetsPerItem>
struct NoPairsKernel {
    SceneView scene;
    GridView grid;
    const GridParams* params;        ///< GridParamsKernel's
    const std::uint32_t* layer_mask; ///< GridPlanKernel's
    std::uint32_t* colliding;
    unsigned long long* tests_run;
    unsigned long long* exact_stage_pairs;

    struct TestAndFlag {
        const NoPairsKernel* kernel;
        std::uint32_t t;
        unsigned long long tests;
        unsigned long long exact_stage;
        KDET_HD void operator()(const GridEntry& e) {
            const std::uint32_t u = e.id();
            std::uint32_t* flags = kernel->colliding;
            if (atomic_load_acquire(&flags[t]) && atomic_load_acquire(&flags[u])) return;
            ++tests;
            const std::uint32_t first = t < u ? t : u, second = t < u ? u : t;
            bool reached_exact = false;
            if (may_collide(kernel->scene, first, second) &&
                candidate_collides<Test>(kernel->scene, first, second, reached_exact)) {
                atomic_store_relaxed(&flags[t], 1u);
                atomic_store_relaxed(&flags[u], 1u);
            }
            exact_stage += reached_exact;
        }
        KDET_HD bool finished() const { return false; }
    };

    KDET_HD void operator()(std::uint64_t i) const {
        TestAndFlag visit{this, 0, 0, 0};
        TetRuns<TetsPerItem>::for_each_tet(static_cast<std::uint32_t>(i), scene.tet_count, [&](std::uint32_t t) {
            visit.t = t;
            search(visit);
            return true;
        });
        if (visit.tests) atomic_fetch_add(tests_run, visit.tests);
        if (visit.exact_stage) atomic_fetch_add(exact_stage_pairs, visit.exact_stage);
    }

    /// @brief The search of tet visit.t, its tests and exact stages added to visit's counts.
    KDET_HD void search(TestAndFlag& visit) const {
        const GridParams grid_params = *params;
        for_each_larger_neighbour(scene, grid, grid_params, *layer_mask, visit.t, visit);
    }
};

/// @brief Brute force, one work item per tet: tests it against every later tet it may collide with.
template <NarrowPhase Test>
struct BruteForceLoopKernel {
    SceneView scene;
    const std::uint32_t* object_tet_begin; ///< [object_count + 1]
    KeyAppender out;
    unsigned long long* exact_stage_pairs;

    KDET_HD void operator()(std::uint64_t i) const {
        const auto t = static_cast<std::uint32_t>(i);
        const std::uint32_t object = scene.tet_object[t];
        KeyBatch batch(&out);
        unsigned long long exact_stage = 0;
        for (std::uint32_t other = object; other < scene.object_count; ++other) {
            if (!pair_is_active(scene, object, other)) continue;
            const std::uint32_t begin = other == object ? t + 1 : object_tet_begin[other];
            for (std::uint32_t u = begin; u < object_tet_begin[other + 1]; ++u) {
                bool reached_exact = false;
                if (tets_collide_tested<Test>(scene, t, u, reached_exact)) batch.push(pair_key(t, u));
                exact_stage += reached_exact;
            }
        }
        batch.flush();
        if (exact_stage) atomic_fetch_add(exact_stage_pairs, exact_stage);
    }
};

/// @brief Brute force, one work item per pair. Work is laid out in blocks, one per active object
/// pair; a self block enumerates i < j row by row.
template <NarrowPhase Test>
struct BruteForcePairsKernel {
    SceneView scene;
    const std::uint32_t* object_tet_begin; ///< [object_count + 1]
    const std::uint64_t* block_begin;      ///< [block_count + 1] work offsets
    const std::uint32_t* block_objects;    ///< [2 * block_count]
    std::uint32_t block_count;
    KeyAppender out;
    unsigned long long* exact_stage_pairs;

    KDET_HD void operator()(std::uint64_t work) const {
        std::uint32_t b = 0;
        while (b + 1 < block_count && block_begin[b + 1] <= work) ++b;
        const std::uint64_t r = work - block_begin[b];
        const std::uint32_t oa = block_objects[2 * b], ob = block_objects[2 * b + 1];
        std::uint64_t i, j;
        if (oa == ob) {
            const std::uint64_t n = object_tet_begin[oa + 1] - object_tet_begin[oa];
            // Row i holds n-1-i pairs; invert the row offsets with a square root, then fix rounding.
            const double m = 2.0 * static_cast<double>(n) - 1.0;
            double guess = (m - sqrt(m * m - 8.0 * static_cast<double>(r))) * 0.5;
            i = guess > 0.0 ? static_cast<std::uint64_t>(guess) : 0;
            auto row_start = [n](std::uint64_t row) { return row * (2 * n - row - 1) / 2; };
            while (i > 0 && row_start(i) > r) --i;
            while (row_start(i + 1) <= r) ++i;
            j = i + 1 + (r - row_start(i));
        } else {
            const std::uint64_t nb = object_tet_begin[ob + 1] - object_tet_begin[ob];
            i = r / nb;
            j = r % nb;
        }
        const auto t = static_cast<std::uint32_t>(object_tet_begin[oa] + i);
        const auto u = static_cast<std::uint32_t>(object_tet_begin[ob] + j);
        bool reached_exact = false;
        if (tets_collide_tested<Test>(scene, t, u, reached_exact)) out.push(pair_key(t, u));
        if (reached_exact) atomic_fetch_add(exact_stage_pairs, 1ull);
    }
};

/// @brief Stage 5: decides each candidate once (a no_pair_key slot is none), flags colliding tets and
/// appends each colliding pair under the caller's tet ids (lower id first; sorted afterwards, so
/// the order of appends does not matter). A proven_pair_key collides (the candidate search's pre-test
/// proved it); every other pair, which the pre-test left undecided or never saw (brute force), gets
/// the test, after the face planes with FacePlanesHere (the search did not run them: rejections are
/// counted in `rejected`). Work item i decides keys [i KeysPerItem, (i + 1) KeysPerItem) of the first
/// min(*key_count, key_capacity): with more than one, its pairs are appended a batch at a time (one
/// atomic per batch where every pair would take one, all on the same counter).
template <NarrowPhase Test, std::uint32_t KeysPerItem, bool FacePlanesHere>
struct NarrowPhaseKernel {
    SceneView scene;
    const std::uint64_t* keys;
    const unsigned long long* key_count;
    std::uint64_t key_capacity;
    std::uint32_t* colliding;
    const std::uint32_t* user_id; ///< [tets] stored id -> caller's global id
    KeyAppender out;
    unsigned long long* exact_stage_pairs;
    unsigned long long* rejected; ///< with FacePlanesHere: the pairs the face planes proved separated

    /// @brief Decides key k; true, with the pair under the caller's ids, when it collides. Counts a
    /// pair the face planes proved separated in `planes_rejected`.
    KDET_HD bool decide(std::uint64_t k, std::uint64_t& pair, unsigned long long& planes_rejected) const {
        if (keys[k] == no_pair_key) return false;
        const std::uint32_t a = key_first(keys[k]), b = key_second(keys[k]);
        const std::uint32_t t = a < b ? a : b, u = a < b ? b : a;
        bool reached_exact = false;
        bool collides = a > b;
        if (!collides) {
            // Edge axes first: the pre-test left this pair undecided, or brute force found it colliding
            // (every axis runs then anyway).
            if constexpr (FacePlanesHere) {
                bool planes_separate = false;
                collides = planes_or_test_collide<Test>(scene, t, u, reached_exact, planes_separate);
                planes_rejected += planes_separate ? 1u : 0u;
            } else {
                collides = test_pair<Test>(scene, t, u, reached_exact, true);
            }
        }
        if (reached_exact) atomic_fetch_add(exact_stage_pairs, 1ull); // rare: one atomic per such pair
        if (!collides) return false;
        atomic_store_relaxed(&colliding[t], 1u);
        atomic_store_relaxed(&colliding[u], 1u);
        pair = pair_key(user_id[t], user_id[u]);
        return true;
    }

    KDET_HD void operator()(std::uint64_t item) const {
        std::uint64_t pair = 0;
        unsigned long long planes_rejected = 0;
        if constexpr (KeysPerItem == 1) {
            if (decide(item, pair, planes_rejected)) out.push(pair);
        } else {
            const std::uint64_t count = *key_count < key_capacity ? *key_count : key_capacity;
            const std::uint64_t begin = item * KeysPerItem;
            const std::uint64_t end = count - begin < KeysPerItem ? count : begin + KeysPerItem;
            KeyBatch batch(&out);
            for (std::uint64_t k = begin; k < end; ++k)
                if (decide(k, pair, planes_rejected)) batch.push(pair);
            batch.flush();
        }
        if (FacePlanesHere && planes_rejected) atomic_fetch_add_gathered(rejected, planes_rejected);
    }
};

/// @brief Stage 6: contact of each colliding pair given in the caller's ids; tet b is the pair's second.
/// Nothing when the pairs outgrew their window: a batch that did not fit left its slots unwritten
/// (they hold no pair, maybe no valid id), and the narrow phase runs again with a larger window.
struct ContactKernel {
    SceneView scene;
    const std::uint32_t* stored_id; ///< [tets] caller's global id -> stored id
    const std::uint64_t* keys;
    const unsigned long long* key_count; ///< the pairs appended, counted past the window's end
    std::uint64_t window;
    Contact* contacts;
    KDET_HD void operator()(std::uint64_t k) const {
        if (*key_count > window) return;
        vec3 a[4], b[4];
        load_tet(scene, stored_id[key_first(keys[k])], a);
        load_tet(scene, stored_id[key_second(keys[k])], b);
        float depth = 0.0f;
        vec3 direction{0.0f, 0.0f, 0.0f};
        tets_intersect_sat_mtv(a, b, depth, direction);
        contacts[k] = Contact{depth, {direction.x, direction.y, direction.z}};
    }
};

/// @brief Stage 6: per-tet colliding flags in the caller's numbering.
struct UserFlagsKernel {
    const std::uint32_t* stored_id; ///< [tets] caller's global id -> stored id
    const std::uint32_t* colliding; ///< per stored tet
    std::uint32_t* user_colliding;
    KDET_HD void operator()(std::uint64_t i) const { user_colliding[i] = colliding[stored_id[i]]; }
};

/// @brief No vertex: FrameCounters::first_non_finite_vertex while every staged position is finite.
constexpr std::uint32_t no_vertex = 0xffffffffu;

/// @brief Finds the lowest vertex with a non-finite coordinate among positions handed over in the
/// backend's memory (staged from vertex `first` on); `found` is global and starts at no_vertex.
struct FiniteCheckKernel {
    const vec3* staged; ///< indexed by the caller's global vertex id
    std::uint32_t first;
    std::uint32_t* found;
    KDET_HD void operator()(std::uint64_t i) const {
        const std::uint32_t v = first + static_cast<std::uint32_t>(i);
        const vec3 p = staged[v];
        // x - x is 0 for finite x and NaN for NaN and infinities.
        if (!(p.x - p.x == 0.0f && p.y - p.y == 0.0f && p.z - p.z == 0.0f)) atomic_min(found, v);
    }
};

/// @brief Makes staged positions current, once FiniteCheckKernel found none of them bad; otherwise
/// the previous positions stay and the frame's end reports the bad vertex.
struct AdoptPositionsKernel {
    const vec3* staged;                  ///< indexed by the caller's global vertex id
    const std::uint32_t* vertex_user_id; ///< [vertices] SceneTopology's
    vec3* positions;                     ///< indexed by stored vertex
    std::uint32_t first;
    const std::uint32_t* non_finite_vertex;
    KDET_HD void operator()(std::uint64_t i) const {
        if (*non_finite_vertex != no_vertex) return;
        const std::uint32_t v = first + static_cast<std::uint32_t>(i);
        positions[v] = staged[vertex_user_id[v]];
    }
};

/// @brief Sets every element of a buffer to one value.
template <class T>
struct FillKernel {
    T* data;
    T value;
    KDET_HD void operator()(std::uint64_t i) const { data[i] = value; }
};

} // namespace kdet
