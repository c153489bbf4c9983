#pragma once
/// @file locate_driver.hpp
/// @brief Locator: point location over a detector's tets at their current positions, written once over
/// an execution layer (the kernels are in point_location.hpp). Each call grids the points anew, then
/// each located tet at its current position reads the points in its box, and, for `within`, each
/// point that none holds searches a tree of the tets' boxes built anew (nearest_tree.hpp); a buffer
/// that was too small grows to what its step counted and the step runs again.

#include "pipeline/capacity.hpp"
#include "pipeline/gather_positions.hpp"
#include "pipeline/point_location.hpp"
#include "pipeline/scene_view.hpp"
#include "pipeline/positions_check.hpp"

#include <kdet/error.hpp>
#include <kdet/locate.hpp>

#include <algorithm>
#include <exception>
#include <limits>
#include <string>

namespace kdet {

/// @brief One point location as the detector asks it of its pipeline.
struct LocateRequest {
    PositionsView points; ///< float32 x y z per point when on the host (checked finite there)
    bool points_on_device = false; ///< in the backend's memory, any layout: gathered and checked there
    std::uint32_t first_tet = 0;   ///< stored tets [first_tet, first_tet + tet_count) are located
    std::uint32_t tet_count = 0;
    LocateOptions options;
    int threads = 1; ///< the host's threads for its own steps
};

/// @brief The pipeline's buffers that point location reads.
struct LocateScene {
    const vec3* positions;
    const TetIndices* tets;
    const std::uint32_t* tet_object;
    const std::uint32_t* user_id;
    const std::uint32_t* stored_id;
    const std::uint32_t* object_tet_begin;
    std::uint32_t total_tets;
};

template <class Exec>
class Locator {
    template <class T>
    using buffer = typename Exec::template buffer<T>;

public:
    void run(Exec& exec, const LocateScene& scene, const LocateRequest& request, HashFunction hash, LocateResult& result) {
        const std::size_t n = request.points.vertex_count;
        if (n >= 0xffffffffull) throw Error("locate: too many points (" + std::to_string(n) + "), at most 2^32 - 2");
        point_count_ = n;
        hit_count_ = 0;

        counters_.resize_discard(1);
        reset_counters(exec);
        stage_points(exec, request);
        const LocateTetsView tets{scene.positions, scene.tets,  request.first_tet,      scene.user_id,
                                  scene.stored_id, scene.tet_object, scene.object_tet_begin};
        frame_tets_ = request.tet_count;
        const TetSizes sizes = size_tets(exec, tets, request, hash);
        find_hits(exec, tets, sizes, request);
        result.point_count = n;
        result.hit_count = hit_count_;
        if (!request.options.results_to_host) {
            describe(exec, static_cast<std::uint32_t>(n), request.options.within > 0.0, own_outputs());
            for (auto* v : {&result.barycentrics, &result.closest_points, &result.distances}) v->clear();
            result.offsets.clear();
            result.objects.clear();
            result.tets.clear();
            return;
        }
        resize_result(result, request.threads);
        if constexpr (Exec::memory_is_host) {
            // Described where the caller reads them: no second copy of every hit.
            outputs_ = Outputs{result.offsets.data(),      result.objects.data(),        result.tets.data(),
                               result.barycentrics.data(), result.closest_points.data(), result.distances.data()};
            describe(exec, static_cast<std::uint32_t>(n), request.options.within > 0.0, outputs_);
            return;
        }
        describe(exec, static_cast<std::uint32_t>(n), request.options.within > 0.0, own_outputs());
        exec.download(result.offsets.data(), offsets_.data(), n + 1);
        exec.download(result.objects.data(), objects_.data(), hit_count_);
        exec.download(result.tets.data(), tets_.data(), hit_count_);
        exec.download(result.barycentrics.data(), barycentrics_.data(), 4 * hit_count_);
        exec.download(result.closest_points.data(), closest_points_.data(), 3 * hit_count_);
        exec.download(result.distances.data(), distances_.data(), hit_count_);
    }

    DeviceLocateResults device_results() const {
        return DeviceLocateResults{outputs_.offsets,        outputs_.objects,   outputs_.tets, outputs_.barycentrics,
                                   outputs_.closest_points, outputs_.distances, point_count_, hit_count_};
    }

    std::size_t memory_bytes() const {
        return points_.capacity_bytes() + point_keys_.capacity_bytes() + slot_start_.capacity_bytes() + sorted_points_.capacity_bytes() +
               held_.capacity_bytes() + tree_boxes_.capacity_bytes() + nearest_closest_.capacity_bytes() +
               nearest_distance_.capacity_bytes() + hit_keys_.capacity_bytes() +
               hits_.capacity_bytes() + hit_keys_grown_.capacity_bytes() + hits_grown_.capacity_bytes() + offsets_.capacity_bytes() +
               objects_.capacity_bytes() + tets_.capacity_bytes() + barycentrics_.capacity_bytes() + closest_points_.capacity_bytes() +
               distances_.capacity_bytes() + counters_.capacity_bytes();
    }

private:
    LocateCounters read_counters(Exec& exec) {
        LocateCounters c;
        exec.download(&c, counters_.data(), 1);
        return c;
    }
    void reset_counters(Exec& exec) {
        LocateCounters c{};
        c.first_non_finite_point = no_vertex;
        for (int a = 0; a < 3; ++a) {
            c.region.lo[a] = float_to_ordered(std::numeric_limits<float>::infinity());
            c.region.hi[a] = float_to_ordered(-std::numeric_limits<float>::infinity());
        }
        exec.upload(counters_.data(), &c, 1);
    }
    template <class T>
    void fill(Exec& exec, buffer<T>& b, const T& value) {
        exec.for_each(b.size(), FillKernel<T>{b.data(), value});
    }

    /// The points as float32 in the backend's memory: the host's own where that is the backend's,
    /// else uploaded from the host, or gathered there and checked to be finite.
    void stage_points(Exec& exec, const LocateRequest& request) {
        const PositionsView& view = request.points;
        if (!request.points_on_device) {
            points_in_ = static_cast<const vec3*>(view.data);
            if constexpr (Exec::memory_is_host) return;
            points_.resize_discard(view.vertex_count);
            exec.upload(points_.data(), points_in_, view.vertex_count);
            points_in_ = points_.data();
            return;
        }
        points_.resize_discard(view.vertex_count);
        points_in_ = points_.data();
        if (view.vertex_count == 0) return;
        exec.check_readable(view.data, "locate_on_device: the points");
        with_positions(view, [&](const auto& source) {
            exec.for_each(view.vertex_count, GatherPositionsKernel<std::decay_t<decltype(source)>>{source, points_.data()});
        });
        exec.for_each(view.vertex_count, FiniteCheckKernel{points_.data(), 0, &counters_.data()->first_non_finite_point});
        const std::uint32_t bad = read_counters(exec).first_non_finite_point;
        if (bad != no_vertex)
            throw Error("locate_on_device: point " + std::to_string(bad) + " has a non-finite coordinate (or one beyond float range)");
    }

    /// What gridding the points needs from the located tets: their region and the layers their boxes
    /// go to.
    struct TetSizes {
        LocateGrid grid{}; ///< c0 and the layers; hash and slot_bits set, the rest per point grid
        std::uint32_t layers = 0; ///< mask
        Aabb region{{0.0f, 0.0f, 0.0f}, {-1.0f, -1.0f, -1.0f}}; ///< the boxes' (none: holds no point)
    };

    /// c0 is the lower end of the binary octave that holds the median of the located tets' box
    /// extents (of every eighth tet); the layers are those of the octaves present.
    TetSizes size_tets(Exec& exec, const LocateTetsView& tets, const LocateRequest& request, HashFunction hash) {
        const std::uint32_t count = request.tet_count;
        LocateCounters* c = counters_.data();
        exec.for_each(count, LocateTetBoxesKernel{tets.positions, tets.tets, tets.first, c});
        const LocateCounters sizes = read_counters(exec);
        TetSizes out;
        LocateGrid& grid = out.grid;
        grid.hash = hash;
        grid.params.layer_count = 1;
        grid.params.cell_size0 = 1.0f;
        grid.params.inv_cell_size0 = 1.0f;
        // Hashed: at least a slot per point on each layer; a slot's number (up to 32 layers' slots) in 31 bits.
        grid.slot_bits = 10;
        while ((std::uint64_t{1} << grid.slot_bits) < point_count_ && grid.slot_bits < 26) ++grid.slot_bits;
        if (count == 0) return out;
        const auto present = [](const std::uint32_t* bits, std::uint32_t e) { return (bits[e / 32] >> (e % 32)) & 1u; };
        std::uint64_t seen = 0;
        std::uint32_t median = 0, largest = 0;
        const std::uint32_t samples = (count + 7) / 8;
        for (std::uint32_t e = 0; e < float_octaves; ++e) {
            if (sizes.sampled[e]) {
                if (seen < (samples + 1) / 2) median = e;
                seen += sizes.sampled[e];
            }
            if (present(sizes.present, e)) largest = e;
        }
        // c0 must be a normal float; bins 254 and 255 (2^127 and up, or infinite) have no float end.
        grid.base_octave = std::clamp<std::uint32_t>(median, 1, 253);
        grid.params.cell_size0 = float_octave_end(grid.base_octave - 1);
        grid.params.inv_cell_size0 = 1.0f / grid.params.cell_size0;
        grid.params.layer_count =
            static_cast<int>(std::min<std::uint32_t>(largest - std::min(largest, grid.base_octave) + 1, max_grid_layers));
        for (std::uint32_t e = 0; e < float_octaves; ++e)
            if (present(sizes.present, e)) out.layers |= 1u << locate_layer_of_octave(grid, e);
        for (int a = 0; a < 3; ++a) {
            (&out.region.lo.x)[a] = ordered_to_float(sizes.region.lo[a]);
            (&out.region.hi.x)[a] = ordered_to_float(sizes.region.hi[a]);
        }
        return out;
    }

    /// Grids the points in the tets' region, one key on each layer the tets use.
    LocatePointsView grid_points(Exec& exec, const TetSizes& sizes) {
        const std::size_t n = point_count_;
        const Aabb& region = sizes.region;
        const std::uint32_t layer_mask = sizes.layers;
        LocateGrid grid = sizes.grid;
        grid.params.origin = region.lo;
        std::uint32_t layers = 0;
        for (int layer = 0; layer < grid.params.layer_count; ++layer) layers += (layer_mask >> layer) & 1u;
        // Dense where its table is not much larger than a hashed one (a slot per point and per tet),
        // with cells along x a quarter of c_l where those fit: a tet's rows then scan little beyond
        // its box, at no cost per cell.
        const std::uint64_t dense_room = std::min<std::uint64_t>(
            std::max<std::uint64_t>(std::uint64_t{layers} << grid.slot_bits, std::uint64_t{frame_tets_}) * 4, 0x7fffffffull);
        std::uint64_t dense_slots = 0;
        for (const int refine : {2, 0}) {
            grid.refine[0] = refine;
            dense_slots = 0;
            for (int layer = 0; layer < grid.params.layer_count && dense_slots <= dense_room; ++layer) {
                if (!((layer_mask >> layer) & 1u)) continue;
                grid.layer_slots[layer] = static_cast<std::uint32_t>(dense_slots);
                std::uint64_t cells = 1;
                for (int a = 0; a < 3 && cells <= dense_room; ++a) {
                    const std::uint32_t along = locate_cell(grid, (&region.hi.x)[a], a, layer) + 1;
                    if (a < 2) grid.cells[layer][a] = along;
                    cells *= along; // each factor at most 2^30 + 1, the product so far within the room
                }
                dense_slots += cells;
            }
            grid.dense = dense_slots <= dense_room;
            if (grid.dense) break;
        }
        if (!grid.dense) {
            grid.refine[0] = 2;
            // Four slots a point, so that fewer blocks share slots: a shared block adds the other
            // block's points in the same cells to each run that scans them.
            for (int more = 0; more < 2 && (std::uint64_t{layers} << (grid.slot_bits + 1)) <= 0x80000000ull; ++more) ++grid.slot_bits;
            std::uint32_t rank = 0;
            for (int layer = 0; layer < grid.params.layer_count; ++layer)
                if ((layer_mask >> layer) & 1u) grid.layer_slots[layer] = rank++ << grid.slot_bits;
        }
        const std::uint64_t slots = grid.dense ? dense_slots : std::uint64_t{layers} << grid.slot_bits;

        const std::uint64_t keys = std::uint64_t{n} * layers;
        if (keys >= 0xffffffffull) throw Error("locate: too many grid entries for 32-bit offsets");
        point_keys_.resize_discard(std::max<std::uint64_t>(keys, 1));
        exec.for_each(n, LocatePointKeysKernel{points_in_, grid, region, layer_mask, layers, slots << 32, point_keys_.data()});
        LocateCounters* c = counters_.data();
        const unsigned long long sorted = keys;
        exec.upload(&c->point_keys, &sorted, 1);
        // By slot alone: the keys were written in the points' order, which the sort keeps within a slot.
        exec.sort_by_high_word(point_keys_.data(), point_keys_.size(), &c->point_keys, high_word_key_bits(slots + 1));
        slot_start_.resize_discard(slots + 1);
        if (keys == 0) fill(exec, slot_start_, 0u);
        exec.for_each(keys, KeyRunStartsKernel<std::uint32_t>{point_keys_.data(), keys, static_cast<std::uint32_t>(slots), slot_start_.data()});
        sorted_points_.resize_discard(std::max<std::uint64_t>(keys, 1));
        exec.for_each(keys, LocateSortedPointsKernel{point_keys_.data(), static_cast<std::uint32_t>(slots), points_in_, sorted_points_.data()});
        return LocatePointsView{grid, slot_start_.data(), point_keys_.data(), sorted_points_.data(), points_in_, static_cast<std::uint32_t>(n)};
    }

    /// Grows a buffer for a rerun; a need the memory cannot hold is a one-line error naming it.
    template <class T>
    static void grow_or_refuse(buffer<T>& b, std::uint64_t wanted, const char* what) {
        if (!grow_for_rerun(b, wanted, std::numeric_limits<std::size_t>::max()))
            throw Error("locate: out of memory: " + std::to_string(wanted) + " " + what + " take " + bytes_text(wanted * sizeof(T)));
    }
    /// Room for `wanted` hits, keeping the first `kept`.
    void reserve_hits(Exec& exec, std::uint64_t wanted, std::uint64_t kept) {
        if (hit_keys_.size() >= wanted) return;
        if (kept == 0) {
            grow_or_refuse(hit_keys_, wanted, "hits");
            grow_or_refuse(hits_, wanted, "hits");
            return;
        }
        grow_or_refuse(hit_keys_grown_, wanted, "hits");
        grow_or_refuse(hits_grown_, wanted, "hits");
        exec.copy(hit_keys_grown_.data(), hit_keys_.data(), kept);
        exec.copy(hits_grown_.data(), hits_.data(), kept);
        hit_keys_.swap(hit_keys_grown_);
        hits_.swap(hits_grown_);
    }
    HitAppender hit_appender() {
        return HitAppender{hit_keys_.data(), hits_.data(), std::min(hit_keys_.size(), hits_.size()), &counters_.data()->hits};
    }

    /// The tree of the located tets' boxes at their current positions (nearest_tree.hpp).
    NearestTreeView build_tree(Exec& exec, const LocateTetsView& tets, std::uint32_t count) {
        NearestTreeView tree{};
        tree.levels = nearest_tree_shape(count, tree.level_begin);
        tree.first = tets.first;
        tree.count = count;
        tree_boxes_.resize_discard(std::max<std::uint32_t>(tree.level_begin[tree.levels], 1));
        tree.boxes = tree_boxes_.data();
        if (tree.levels == 0) return tree;
        exec.for_each(tree.level_begin[1], NearestLeafBoxesKernel{tets.positions, tets.tets, tets.first, count, tree_boxes_.data()});
        for (int level = 1; level < tree.levels; ++level) {
            const std::uint32_t below = tree.level_begin[level - 1];
            exec.for_each(tree.level_begin[level + 1] - tree.level_begin[level],
                          NearestParentBoxesKernel{tree_boxes_.data() + below, tree.level_begin[level] - below,
                                                   tree_boxes_.data() + tree.level_begin[level]});
        }
        return tree;
    }

    /// The points in the order of their nearest searches (NearestSearchOrderKernel), in the point
    /// keys' buffer (the points' grid is read by then): ordered within the tets' region grown by
    /// `within`, or by the region's extent where `within` is larger.
    const std::uint64_t* nearest_search_order(Exec& exec, const Aabb& region, double within) {
        const std::size_t n = point_count_;
        const float grow = static_cast<float>(std::min<double>(within, box_extent(region)));
        const Aabb box{region.lo - vec3{grow, grow, grow}, region.hi + vec3{grow, grow, grow}};
        point_keys_.resize_discard(std::max<std::size_t>(n, 1));
        exec.for_each(n, NearestSearchOrderKernel{points_in_, held_.data(), box, point_keys_.data()});
        LocateCounters* c = counters_.data();
        const unsigned long long count = n;
        exec.upload(&c->point_keys, &count, 1);
        exec.sort_by_high_word(point_keys_.data(), point_keys_.size(), &c->point_keys, high_word_key_bits(held_point_order + 1));
        return point_keys_.data();
    }

    /// The hits, sorted by point: the tets that hold each point, then, for `within`, the nearest tet of
    /// each point that none holds.
    void find_hits(Exec& exec, const LocateTetsView& tets, const TetSizes& sizes, const LocateRequest& request) {
        const std::size_t n = point_count_;
        const double within = request.options.within;
        unsigned long long* hits = &counters_.data()->hits;
        if (within > 0.0) {
            held_.resize_discard(n);
            fill(exec, held_, 0u);
        }
        reserve_hits(exec, n + 1024, 0);
        const LocatePointsView points = grid_points(exec, sizes);
        for (;;) {
            constexpr std::uint32_t run = Exec::tuning::search_tets_per_item;
            exec.for_each(TetRuns<run>::count(request.tet_count),
                          LocateContainingKernel<run>{tets, points, hit_appender(), within > 0.0 ? held_.data() : nullptr, request.tet_count},
                          run);
            exec.download(&hit_count_, hits, 1);
            if (hit_count_ <= hit_keys_.size()) break;
            reserve_hits(exec, hit_count_, 0);
            const unsigned long long none = 0;
            exec.upload(hits, &none, 1);
        }
        if (within > 0.0) {
            const NearestTreeView tree = build_tree(exec, tets, request.tet_count);
            const float scale = std::max(max_abs(sizes.region.lo), max_abs(sizes.region.hi));
            const std::uint64_t* order = nearest_search_order(exec, sizes.region, within);
            // At most one hit more per point.
            reserve_hits(exec, hit_count_ + n, hit_count_);
            nearest_closest_.resize_discard(3 * n);
            nearest_distance_.resize_discard(n);
            exec.for_each(n, LocateNearestKernel{tets, tree, points_in_, within, scale, order, hit_appender(), nearest_closest_.data(),
                                                 nearest_distance_.data()});
            exec.download(&hit_count_, hits, 1);
        }
        if (hit_count_ >= 0xffffffffull) throw Error("locate: too many hits (" + std::to_string(hit_count_) + ") for 32-bit indices");
        // By point alone (LocateHitOrderKernel orders a point's hits afterwards).
        exec.sort_by_high_word(hit_keys_.data(), hit_keys_.size(), hits, high_word_key_bits(std::max<std::uint64_t>(n, 1)));
    }

    /// The result's arrays at the sizes of this call's hits. A vector's growth fills it with zeros,
    /// the first touch of fresh memory for a large one: the arrays are grown on the host's threads.
    void resize_result(LocateResult& result, int threads) const {
        const std::size_t hits = hit_count_;
        std::exception_ptr failed;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
        for (int a = 0; a < 6; ++a) {
            try {
                switch (a) {
                case 0: result.barycentrics.resize(4 * hits); break;
                case 1: result.closest_points.resize(3 * hits); break;
                case 2: result.offsets.resize(point_count_ + 1); break;
                case 3: result.distances.resize(hits); break;
                case 4: result.objects.resize(hits); break;
                default: result.tets.resize(hits); break;
                }
            } catch (...) {
#pragma omp critical(kdet_locate_result)
                failed = std::current_exception();
            }
        }
        if (failed) std::rethrow_exception(failed);
    }

    /// Where the results are described: the backend's buffers, or the caller's arrays.
    struct Outputs {
        std::uint64_t* offsets;
        std::uint32_t* objects;
        std::uint32_t* tets;
        double* barycentrics;
        double* closest_points;
        double* distances;
    };
    Outputs own_outputs() {
        const std::size_t hits = std::max<std::size_t>(hit_count_, 1);
        objects_.resize_discard(hits);
        tets_.resize_discard(hits);
        barycentrics_.resize_discard(4 * hits);
        closest_points_.resize_discard(3 * hits);
        distances_.resize_discard(hits);
        offsets_.resize_discard(point_count_ + 1);
        outputs_ = Outputs{offsets_.data(), objects_.data(), tets_.data(), barycentrics_.data(), closest_points_.data(), distances_.data()};
        return outputs_;
    }

    /// Each hit's object, tet, barycentric coordinates, closest point and distance, in the points'
    /// order; each point's offset.
    void describe(Exec& exec, std::uint32_t n, bool nearest, const Outputs& out) {
        exec.for_each(hit_count_, LocateDescribeKernel{hit_keys_.data(), hits_.data(), points_in_, nearest ? held_.data() : nullptr,
                                                       nearest_closest_.data(), nearest_distance_.data(), out.objects, out.tets,
                                                       out.barycentrics, out.closest_points, out.distances});
        if (hit_count_ == 0) exec.for_each(std::uint64_t{n} + 1, FillKernel<std::uint64_t>{out.offsets, 0});
        exec.for_each(hit_count_, KeyRunStartsKernel<std::uint64_t>{hit_keys_.data(), hit_count_, n, out.offsets});
        exec.for_each(n, LocateHitOrderKernel{out.offsets, out.objects, out.tets, out.barycentrics, out.closest_points, out.distances});
    }

    buffer<vec3> points_;
    const vec3* points_in_ = nullptr; ///< the points the kernels read: points_, or the host's on a host backend
    buffer<std::uint64_t> point_keys_;
    buffer<std::uint32_t> slot_start_; ///< LocateSlotStartsKernel's
    buffer<vec3> sorted_points_; ///< per sorted point key
    buffer<std::uint32_t> held_;          ///< per point, for `within`
    buffer<Aabb> tree_boxes_;             ///< for `within`: NearestTreeView's
    buffer<double> nearest_closest_, nearest_distance_; ///< per point, for `within`
    buffer<std::uint64_t> hit_keys_, hit_keys_grown_;
    buffer<LocateHit> hits_, hits_grown_;
    buffer<std::uint64_t> offsets_;
    buffer<std::uint32_t> objects_, tets_;
    buffer<double> barycentrics_, closest_points_, distances_;
    buffer<LocateCounters> counters_;
    unsigned long long hit_count_ = 0;
    std::size_t point_count_ = 0;
    std::uint32_t frame_tets_ = 0; ///< the located tets of this call
    Outputs outputs_{}; ///< what device_results() hands out
};

} // namespace kdet
