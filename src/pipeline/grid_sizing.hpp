#pragma once
/// @file grid_sizing.hpp
/// @brief Stage 1 for the grid: the relevant tets' sizes, the grid's geometry from them, each tet's
/// layer, and the plan (entries and cells per layer) that sizes the table before it is filled.

#include "exec/atomic.hpp"
#include "geometry/enclosing_sphere.hpp"
#include "grid/bucket_table.hpp"
#include "grid/grid_math.hpp"
#include "pipeline/bounding_boxes.hpp"
#include "pipeline/scene_view.hpp"

#include <cfloat>
#include <cmath>
#include <cstdint>

namespace kdet {

/// @brief A size grown by the margin, at most the largest float (as the sphere's diameter is): a sum
/// that overflowed would read as no tet at all, and its pairs were lost.
KDET_HD inline float grown_size(float size, float margin) { return fminf(size + margin, FLT_MAX); }

/// @brief The bounds on a size grown by the margin: a tet's size is its sphere's diameter plus the
/// margin, the extent of its grown box, so that the layers and cells keep their sizes' logic and a
/// tet's grown box spans at most two cells per axis on its layer (rounded to nearest: monotone, so the
/// bounds still bound the grown sphere).
KDET_HD inline SphereDiameterBounds grown_bounds(SphereDiameterBounds bounds, float margin) {
    return SphereDiameterBounds{grown_size(bounds.lower, margin), grown_size(bounds.upper, margin)};
}

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

    /// Whether the tet may meet a tet it is checked against; one box test, whatever the objects' count.
    KDET_HD bool relevant(std::uint32_t object, const Aabb& box) const {
        return pair_is_active(scene, object, object) || boxes_overlap(box, scene.meeting_boxes[object]);
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
        if (scene.slabs) scene.slabs[t] = tet_slabs(v, scene.planes[t].longest, scene.margin);
        const float longest = longest_edge(v);
        const SphereDiameterBounds bounds = grown_bounds(sphere_diameter_bounds(longest), scene.margin);
        const std::uint32_t lower = float_to_ordered(bounds.lower), upper = float_to_ordered(bounds.upper);
        atomic_lower_to(min_upper_size, upper);
        atomic_raise_to(max_lower_size, lower);
        if (lower > atomic_load_acquire(min_upper_size) && upper < atomic_load_acquire(max_lower_size)) {
            info.diameter = -longest;
            return;
        }
        info.diameter = grown_size(enclosing_sphere_diameter(v), scene.margin);
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

/// @brief The layer of relevant tet t, whose TetInfo::diameter is `size` (grown by the margin): from its sphere where
/// TetSizeKernel computed it; else from its longest-edge bounds where both fall on one layer (layers
/// grow with the size, so the sphere's does too, up to rounding); else from its sphere, computed now.
KDET_HD inline int tet_layer(const SceneView& scene, const GridParams& params, std::uint32_t t, float size) {
    if (!(size < 0.0f)) return layer_of(params, size);
    const SphereDiameterBounds bounds = grown_bounds(sphere_diameter_bounds(-size), scene.margin);
    const int low = layer_of(params, bounds.lower), high = layer_of(params, bounds.upper);
    if (low == high) return low;
    vec3 v[4];
    load_tet(scene, t, v);
    return layer_of(params, grown_size(enclosing_sphere_diameter(v), scene.margin));
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

} // namespace kdet
