#pragma once
/// @file locate_driver.hpp
/// @brief Locator: point location over a detector's tets at their current positions, written once over
/// an execution layer (the kernels are in point_location.hpp). Each call grids the located tets anew
/// (their positions may have moved since the last call), then runs the queries; a buffer that was too
/// small grows to what its step counted and the step runs again.

#include "pipeline/capacity.hpp"
#include "pipeline/gather_positions.hpp"
#include "pipeline/point_location.hpp"
#include "pipeline/positions_check.hpp"

#include <kdet/error.hpp>
#include <kdet/locate.hpp>

#include <algorithm>
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
        reset_counters(exec, n);
        stage_points(exec, request);
        const LocateGridView grid = build_grid(exec, scene, request, hash);
        order_points(exec, n);
        find_hits(exec, grid, request.options.within, n, scene.total_tets);
        describe(exec, scene, static_cast<std::uint32_t>(n));

        result = LocateResult{};
        result.point_count = n;
        result.hit_count = hit_count_;
        if (!request.options.results_to_host) return;
        result.offsets.resize(n + 1);
        exec.download(result.offsets.data(), offsets_.data(), n + 1);
        result.objects.resize(hit_count_);
        result.tets.resize(hit_count_);
        result.barycentrics.resize(4 * hit_count_);
        result.closest_points.resize(3 * hit_count_);
        result.distances.resize(hit_count_);
        exec.download(result.objects.data(), objects_.data(), hit_count_);
        exec.download(result.tets.data(), tets_.data(), hit_count_);
        exec.download(result.barycentrics.data(), barycentrics_.data(), 4 * hit_count_);
        exec.download(result.closest_points.data(), closest_points_.data(), 3 * hit_count_);
        exec.download(result.distances.data(), distances_.data(), hit_count_);
    }

    DeviceLocateResults device_results() const {
        return DeviceLocateResults{offsets_.data(),        objects_.data(),   tets_.data(), barycentrics_.data(),
                                   closest_points_.data(), distances_.data(), point_count_, hit_count_};
    }

    std::size_t memory_bytes() const {
        return points_.capacity_bytes() + sorted_points_.capacity_bytes() + order_.capacity_bytes() + held_.capacity_bytes() + boxes_.capacity_bytes() + orientation_.capacity_bytes() + entry_boxes_.capacity_bytes() + keys_.capacity_bytes() +
               slot_begin_.capacity_bytes() + slot_end_.capacity_bytes() + big_.capacity_bytes() + hits_.capacity_bytes() + hits_grown_.capacity_bytes() +
               offsets_.capacity_bytes() + objects_.capacity_bytes() + tets_.capacity_bytes() + barycentrics_.capacity_bytes() +
               closest_points_.capacity_bytes() + distances_.capacity_bytes() + counters_.capacity_bytes();
    }

private:
    LocateCounters read_counters(Exec& exec) {
        LocateCounters c;
        exec.download(&c, counters_.data(), 1);
        return c;
    }
    void reset_counters(Exec& exec, std::size_t points) {
        LocateCounters c{};
        c.points = points;
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

    /// The points as float32 in the backend's memory: uploaded from the host, or gathered there and
    /// checked to be finite.
    void stage_points(Exec& exec, const LocateRequest& request) {
        const PositionsView& view = request.points;
        points_.resize_discard(view.vertex_count);
        held_.resize_discard(view.vertex_count);
        if (!request.points_on_device) {
            exec.upload(points_.data(), static_cast<const vec3*>(view.data), view.vertex_count);
            return;
        }
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

    /// Grids the located tets: c0 is the median of their boxes' extents rounded up to a power of two
    /// (so that most tets sit on layers 0 and 1), with as many layers as the largest needs.
    LocateGridView build_grid(Exec& exec, const LocateScene& scene, const LocateRequest& request, HashFunction hash) {
        const std::uint32_t count = request.tet_count;
        boxes_.resize_discard(count);
        orientation_.resize_discard(count);
        big_.resize_discard(std::max<std::uint32_t>(count, 1));
        LocateCounters* c = counters_.data();
        exec.for_each(count, LocateTetBoxesKernel{scene.positions, scene.tets, request.first_tet, boxes_.data(), orientation_.data(), c});
        const LocateCounters sizes = read_counters(exec);
        GridParams params{};
        std::uint32_t slot_bits = 10;
        while ((std::uint64_t{1} << slot_bits) < 2ull * count && slot_bits < 30) ++slot_bits;
        order_scale_ = vec3{0.0f, 0.0f, 0.0f};
        if (count > 0) {
            std::uint64_t seen = 0;
            std::uint32_t median = 0, largest = 0;
            for (std::uint32_t e = 0; e < float_octaves; ++e) {
                if (!sizes.octaves[e]) continue;
                if (seen < (count + 1) / 2) median = e;
                seen += sizes.octaves[e];
                largest = e;
            }
            // Bins 254 and 255 (extents of 2^127 and up, or infinite) have no float end: the top layer takes them.
            median = std::min<std::uint32_t>(median, 253);
            params.cell_size0 = float_octave_end(median);
            params.inv_cell_size0 = 1.0f / params.cell_size0;
            params.layer_count = static_cast<int>(std::min<std::uint32_t>(largest - std::min(largest, median) + 1, max_grid_layers));
            params.origin = vec3{ordered_to_float(sizes.region.lo[0]), ordered_to_float(sizes.region.lo[1]),
                                 ordered_to_float(sizes.region.lo[2])};
            const float lo[3] = {params.origin.x, params.origin.y, params.origin.z};
            float scale[3];
            for (int a = 0; a < 3; ++a) {
                const float extent = ordered_to_float(sizes.region.hi[a]) - lo[a];
                scale[a] = extent > 0.0f && extent < std::numeric_limits<float>::infinity() ? 1024.0f / extent : 0.0f;
            }
            order_lo_ = params.origin;
            order_scale_ = vec3{scale[0], scale[1], scale[2]};
        }
        if (keys_.size() < std::size_t{4} * count) keys_.resize_discard(std::size_t{4} * count);
        for (;;) {
            const KeyAppender out{keys_.data(), keys_.size(), &c->entries, nullptr};
            exec.for_each(count, PopulateKernel<LocateCells>{LocateCells{boxes_.data(), params, hash, slot_bits, out, big_.data(), c}});
            const LocateCounters inserted = read_counters(exec);
            if (inserted.entries <= keys_.size()) {
                entries_ = inserted.entries;
                big_count_ = inserted.big_count;
                layer_mask_ = inserted.layer_mask;
                break;
            }
            grow_or_refuse(keys_, inserted.entries, "grid entries");
            LocateCounters again = inserted;
            again.entries = again.big_count = again.layer_mask = 0;
            exec.upload(c, &again, 1);
        }
        if (entries_ >= 0xffffffffull) throw Error("locate: too many grid entries for 32-bit offsets");
        exec.sort(keys_.data(), keys_.size(), &c->entries, 32 + static_cast<int>(slot_bits),
                  high_word_key_bits(std::max<std::uint32_t>(count, 1)) - 32);
        const std::size_t slots = std::size_t{1} << slot_bits;
        slot_begin_.resize_discard(slots);
        slot_end_.resize_discard(slots);
        fill(exec, slot_begin_, 0u);
        fill(exec, slot_end_, 0u);
        exec.for_each(entries_, LocateSlotRunsKernel{keys_.data(), entries_, slot_begin_.data(), slot_end_.data()});
        entry_boxes_.resize_discard(std::max<std::uint64_t>(entries_, 1));
        exec.for_each(entries_, LocateEntryBoxesKernel{keys_.data(), boxes_.data(), entry_boxes_.data()});
        return LocateGridView{scene.positions, scene.tets, scene.user_id, request.first_tet, boxes_.data(), orientation_.data(), keys_.data(),
                              entry_boxes_.data(), entries_, slot_begin_.data(), slot_end_.data(), big_.data(), big_count_, params, hash,
                              slot_bits, layer_mask_};
    }

    /// Grows a key buffer for a rerun; a need the memory cannot hold is a one-line error naming it.
    static void grow_or_refuse(buffer<std::uint64_t>& keys, std::uint64_t wanted, const char* what) {
        if (!grow_for_rerun(keys, wanted, std::numeric_limits<std::size_t>::max()))
            throw Error("locate: out of memory: " + std::to_string(wanted) + " " + what + " take " +
                        bytes_text(wanted * sizeof(std::uint64_t)));
    }

    /// The order the queries run in: the points sorted along a Morton curve (LocatePointOrderKernel),
    /// and their coordinates in that order.
    void order_points(Exec& exec, std::size_t n) {
        order_.resize_discard(std::max<std::size_t>(n, 1));
        exec.for_each(n, LocatePointOrderKernel{points_.data(), order_lo_, order_scale_, order_.data()});
        exec.sort(order_.data(), n, &counters_.data()->points, 62,
                  high_word_key_bits(std::max<std::uint64_t>(n, 1)) - 32);
        sorted_points_.resize_discard(n);
        exec.for_each(n, LocateSortedPointsKernel{points_.data(), order_.data(), sorted_points_.data()});
    }

    /// The hits' keys, sorted: the tets that hold each point, then, for `within`, the nearest tet of
    /// each point that none holds.
    void find_hits(Exec& exec, const LocateGridView& grid, double within, std::size_t n, std::uint32_t total_tets) {
        LocateCounters* c = counters_.data();
        if (hits_.size() < n + 1024) hits_.resize_discard(n + 1024);
        for (;;) {
            const KeyAppender out{hits_.data(), hits_.size(), &c->hits, nullptr};
            exec.for_each(n, LocateContainingKernel{grid, sorted_points_.data(), order_.data(), out, held_.data()});
            const LocateCounters found = read_counters(exec);
            hit_count_ = found.hits;
            if (found.hits <= hits_.size()) break;
            grow_or_refuse(hits_, found.hits, "hits");
            LocateCounters again = found;
            again.hits = 0;
            exec.upload(c, &again, 1);
        }
        if (within > 0.0) {
            // At most one hit more per point: room for all of them, keeping the hits found.
            if (hits_.size() < hit_count_ + n) {
                hits_grown_.resize_discard(rerun_capacity(hits_.size(), hit_count_ + n));
                exec.copy(hits_grown_.data(), hits_.data(), hit_count_);
                hits_.swap(hits_grown_);
            }
            const KeyAppender out{hits_.data(), hits_.size(), &c->hits, nullptr};
            exec.for_each(n, LocateNearestKernel{grid, sorted_points_.data(), order_.data(), held_.data(), within, out});
            hit_count_ = read_counters(exec).hits;
        }
        const auto points = static_cast<std::uint32_t>(n);
        exec.sort(hits_.data(), hits_.size(), &c->hits, high_word_key_bits(std::max<std::uint32_t>(points, 1)),
                  high_word_key_bits(std::max<std::uint32_t>(total_tets, 1)) - 32);
    }

    /// Each hit's object, tet, barycentric coordinates, closest point and distance; each point's offset.
    void describe(Exec& exec, const LocateScene& scene, std::uint32_t n) {
        const std::size_t hits = std::max<std::size_t>(hit_count_, 1);
        objects_.resize_discard(hits);
        tets_.resize_discard(hits);
        barycentrics_.resize_discard(4 * hits);
        closest_points_.resize_discard(3 * hits);
        distances_.resize_discard(hits);
        offsets_.resize_discard(std::size_t{n} + 1);
        const LocateHitsView view{scene.positions, scene.tets, scene.stored_id, scene.tet_object, scene.object_tet_begin, points_.data()};
        exec.for_each(hit_count_, LocateDescribeKernel{view, hits_.data(), objects_.data(), tets_.data(), barycentrics_.data(),
                                                       closest_points_.data(), distances_.data()});
        exec.for_each(std::uint64_t{n} + 1, LocateOffsetsKernel{hits_.data(), hit_count_, offsets_.data()});
    }

    buffer<vec3> points_;
    buffer<vec3> sorted_points_; ///< per query
    buffer<std::uint64_t> order_; ///< the points' keys in the order the queries run
    buffer<std::uint8_t> held_;
    buffer<Aabb> boxes_;
    buffer<std::int8_t> orientation_;
    buffer<Aabb> entry_boxes_;
    buffer<std::uint64_t> keys_;
    buffer<std::uint32_t> slot_begin_, slot_end_;
    buffer<std::uint32_t> big_;
    buffer<std::uint64_t> hits_, hits_grown_;
    buffer<std::uint64_t> offsets_;
    buffer<std::uint32_t> objects_, tets_;
    buffer<double> barycentrics_, closest_points_, distances_;
    buffer<LocateCounters> counters_;
    std::uint64_t entries_ = 0, hit_count_ = 0;
    std::size_t point_count_ = 0;
    std::uint32_t big_count_ = 0, layer_mask_ = 0;
    vec3 order_lo_{}, order_scale_{}; ///< LocatePointOrderKernel's grid
};

} // namespace kdet
