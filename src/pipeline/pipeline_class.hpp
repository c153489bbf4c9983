#pragma once
/// @file pipeline_class.hpp
/// @brief The per-frame pipeline, written once over an execution layer (CpuExec or CudaExec).
/// A frame is enqueued whole: each stage finds the sizes and the grid's geometry that the stages
/// before it computed in the backend's memory (FrameCounters), so the host reads nothing in between.
/// It reads the counters (and the results, when they go to the host) once at the end, and grows a
/// buffer only when a counter says that the buffer was too small, running the frame again from the
/// stage that lacked room.
/// Pipeline runs Method::kdet; the thesis's baselines run its frame with a candidate stage of their
/// own (BaselinePipeline, baselines.hpp). The stages' drivers are in pipeline_stages.hpp, the frame's
/// control in pipeline.hpp, and each stage's kernels in a header of its own.

#include "pipeline/bounding_boxes.hpp"
#include "pipeline/capacity.hpp"
#include "pipeline/candidate_bound.hpp"
#include "pipeline/candidate_search.hpp"
#include "pipeline/exclusion_rings.hpp"
#include "pipeline/frame_counters.hpp"
#include "pipeline/grid_populate.hpp"
#include "pipeline/grid_sizing.hpp"
#include "pipeline/narrow_phase.hpp"
#include "pipeline/near_pairs.hpp"
#include "pipeline/pair_distances.hpp"
#include "pipeline/pipeline_base.hpp"
#include "pipeline/positions_check.hpp"
#include "pipeline/scene_view.hpp"
#include "pipeline/static_grid.hpp"

#include <kdet/options.hpp>
#include <kdet/results.hpp>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

namespace kdet {

template <class Exec>
class Pipeline : public PipelineBase {
    template <class T>
    using buffer = typename Exec::template buffer<T>;

protected:
    /// How the stages divide their work on this backend (exec/tuning.hpp).
    using Tuning = typename Exec::tuning;

public:
    explicit Pipeline(const DetectorOptions& options)
        : exec_(options), clock_(exec_.make_stage_clock()), options_(options) {}

    void set_topology(const SceneTopology& given) override {
        // The static objects' tets go last (a copy of the topology reordered); without any, the
        // buffers are filled from the detector's own.
        const bool reorder = keeps_static_grid() && std::any_of(given.object_static.begin(), given.object_static.end(),
                                                                [](std::uint8_t s) { return s != 0; });
        SceneTopology reordered;
        if (reorder) reordered = static_last(given, frame_tets_);
        const SceneTopology& topology = reorder ? reordered : given;
        const std::size_t tets = topology.tets.size();
        if (!reorder) frame_tets_ = static_cast<std::uint32_t>(tets);
        topology_.object_tet_begin = topology.object_tet_begin;
        topology_.object_static = topology.object_static;
        topology_.vertex_count = topology.vertex_count;
        object_first_.assign(topology.object_tet_begin.size(), static_cast<std::uint32_t>(tets));
        for (std::uint32_t t = static_cast<std::uint32_t>(tets); t-- > 0;) object_first_[topology.tet_object[t]] = t;
        statics_.placed = statics_.search.active = false;
        tets_.resize_discard(tets);
        exec_.upload(tets_.data(), topology.tets.data(), tets);
        tet_object_.resize_discard(tets);
        exec_.upload(tet_object_.data(), topology.tet_object.data(), tets);
        user_id_.resize_discard(tets);
        exec_.upload(user_id_.data(), topology.tet_user_id.data(), tets);
        std::vector<std::uint32_t> stored_id(tets);
        const auto count = static_cast<std::ptrdiff_t>(tets);
#pragma omp parallel for num_threads(host_threads(options_.threads)) schedule(static) if (count > host_parallel_elements)
        for (std::ptrdiff_t t = 0; t < count; ++t) stored_id[topology.tet_user_id[t]] = static_cast<std::uint32_t>(t);
        stored_id_.resize_discard(tets);
        exec_.upload(stored_id_.data(), stored_id.data(), tets);
        object_tet_begin_.resize_discard(topology.object_tet_begin.size());
        exec_.upload(object_tet_begin_.data(), topology.object_tet_begin.data(), topology.object_tet_begin.size());
        positions_.resize_discard(topology.vertex_count);
        vertex_user_id_.resize_discard(topology.vertex_count);
        exec_.upload(vertex_user_id_.data(), topology.vertex_user_id.data(), topology.vertex_count);
        info_.resize_discard(tets);
        planes_.resize_discard(tets);
        slabs_.resize_discard(tets);
        colliding_.resize_discard(tets);
        user_colliding_.resize_discard(tets);
        const std::size_t objects = topology.object_tet_begin.size() - 1;
        run_objects_.resize_discard(objects);
        run_boxes_.resize_discard(objects);
        object_boxes_.resize_discard(objects);
        meeting_boxes_.resize_discard(objects);
        // An empty object has no run of tets, so the reduction never writes its box: empty once here.
        const float inf = std::numeric_limits<float>::infinity();
        fill(object_boxes_, Aabb{{inf, inf, inf}, {-inf, -inf, -inf}});
        pair_enabled_.resize_discard(objects * objects);
        pair_active_.resize_discard(objects * objects);
        checked_objects_.resize_discard(objects);
        // Exclusions name stored tets: the detector sets them again for the new topology.
        exclusion_begin_.resize_discard(0);
        excluded_.resize_discard(0);
        counters_.resize_discard(2); // the frame's, and find_candidates' count of what its buffer lacked
        // New geometry: the first frame plans the grid and sizes the pairs from what it finds; the bucket
        // size is chosen again from that plan (and only grows with later ones).
        grid_planned_ = pairs_sized_ = false;
        bucket_capacity_ = 0;
        colliding_count_ = 0;
    }

    void set_exclusions(const ExclusionLists& lists) override {
        exclusion_begin_.resize_discard(lists.partners.empty() ? 0 : lists.begin.size());
        exec_.upload(exclusion_begin_.data(), lists.begin.data(), exclusion_begin_.size());
        excluded_.resize_discard(lists.partners.size());
        exec_.upload(excluded_.data(), lists.partners.data(), lists.partners.size());
    }

    ExclusionLists ring_exclusions(const TetIndices* tets, std::uint32_t tet_count, std::uint32_t first_vertex,
                                   std::uint32_t vertex_count, int rings, std::uint32_t object) const override {
        return build_ring_exclusions(exec_, tets, tet_count, first_vertex, vertex_count, rings, object);
    }

    const std::vector<std::uint32_t>& object_first_tets() const override { return object_first_; }

    void static_moved() override { statics_.placed = false; }

    void stage_positions(std::uint32_t first, const PositionsView& positions) override {
        exec_.check_readable(positions.data, "set_positions_on_device: the positions");
        // Allocated on first use: only simulations that hand positions over on the device need it.
        if (staged_positions_.size() != positions_.size()) staged_positions_.resize_discard(positions_.size());
        vec3* staged = staged_positions_.data() + first;
        if (is_xyz_float(positions)) {
            exec_.copy(staged, static_cast<const vec3*>(positions.data), positions.vertex_count);
            return;
        }
        with_positions(positions, [&](const auto& source) {
            exec_.for_each(positions.vertex_count, GatherPositionsKernel<std::decay_t<decltype(source)>>{source, staged});
        });
    }

    void get_positions(std::uint32_t first, vec3* positions, std::uint32_t count, bool staged) override {
        exec_.download(positions, (staged ? staged_positions_ : positions_).data() + first, count);
    }

    DeviceResults device_results() override {
        return DeviceResults{out_keys_.data(), colliding_count_, user_colliding_.data(), user_colliding_.size(),
                             options_.contacts ? out_contacts_.data() : nullptr,
                             options_.distances ? out_distances_.data() : nullptr,
                             options_.distances ? out_closest_.data() : nullptr};
    }

    void upload_positions(const std::vector<PositionUpload>& uploads) override {
        for (const PositionUpload& u : uploads) exec_.upload(positions_.data() + u.first, u.positions, u.count);
    }

    void locate(const LocateRequest& request, LocateResult& result) override {
        const LocateScene scene{positions_.data(), tets_.data(), tet_object_.data(), user_id_.data(), stored_id_.data(),
                                object_tet_begin_.data(), static_cast<std::uint32_t>(tets_.size())};
        locator_.run(exec_, scene, request, options_.hash, result);
    }

    DeviceLocateResults device_locate_results() const override { return locator_.device_results(); }

    std::size_t memory_bytes() const override {
        return tets_.capacity_bytes() + tet_object_.capacity_bytes() + object_tet_begin_.capacity_bytes() +
               user_id_.capacity_bytes() + stored_id_.capacity_bytes() + positions_.capacity_bytes() + vertex_user_id_.capacity_bytes() +
               staged_positions_.capacity_bytes() +
               info_.capacity_bytes() + planes_.capacity_bytes() + slabs_.capacity_bytes() + colliding_.capacity_bytes() + user_colliding_.capacity_bytes() +
               run_objects_.capacity_bytes() + run_boxes_.capacity_bytes() + object_boxes_.capacity_bytes() + meeting_boxes_.capacity_bytes() +
               pair_enabled_.capacity_bytes() + pair_active_.capacity_bytes() + checked_objects_.capacity_bytes() +
               exclusion_begin_.capacity_bytes() + excluded_.capacity_bytes() + grid_bytes() + statics_.bytes() + counters_.capacity_bytes() +
               candidates_.capacity_bytes() + candidates_grown_.capacity_bytes() + near_.capacity_bytes() +
               resume_points_[0].capacity_bytes() + resume_points_[1].capacity_bytes() + out_keys_.capacity_bytes() + out_contacts_.capacity_bytes() +
               out_distances_.capacity_bytes() + out_closest_.capacity_bytes() + exec_.scratch_bytes() +
               locator_.memory_bytes();
    }

    /// The grid's buffers: the table, the compacted lists and their bounds, the own-layer rows, the claim
    /// order, the lists' keys while compacting.
    std::size_t grid_bytes() const {
        return headers_.capacity_bytes() + ids_.capacity_bytes() + entry_blocks_.capacity_bytes() +
               block_bounds_.capacity_bytes() + own_cells_.capacity_bytes() + claimed_slots_.capacity_bytes() +
               list_keys_.capacity_bytes() + sorted_keys_.capacity_bytes() + list_begin_.capacity_bytes() +
               list_end_.capacity_bytes();
    }

    std::string device_name() const override { return exec_.device_name(); }

    void start(const std::vector<PositionUpload>& uploads, const std::vector<VertexRange>& staged,
               std::vector<std::uint8_t> pair_enabled) override;
    std::uint32_t finish(FrameResult& result) override;

protected:
    // What a baseline's frame changes of kdet's (BaselinePipeline): the rest of the frame is the same.
    /// Whether static objects are placed once into a grid of their own (static_grid.hpp); a baseline
    /// instead runs every tet each frame, and the static flags only switch off static-static pairs.
    virtual bool keeps_static_grid() const { return true; }
    /// Whether the frame grids the relevant tets (stage 1's sizes and plan, stage 2).
    virtual bool grids() const { return true; }
    /// Whether the frame appends colliding pairs (the narrow phase runs on its candidates).
    virtual bool makes_pairs() const { return true; }
    /// Stage 3: the candidates (kdet's: the grid's search), or the flags of a method without pairs.
    /// Returns the frame's counters where it read them back.
    virtual std::optional<FrameCounters> candidate_stage() { return find_candidates(grid_); }
    /// Whether the candidates passed the search's pre-test, which the narrow phase completes with the
    /// face planes where the search does not run them (Tuning::face_planes_in_search).
    virtual bool candidates_pretested() const { return true; }
    /// The frame's counts of candidates from its counters.
    virtual void count_candidates(const FrameCounters& c, FrameCounts& counts) const {
        counts.narrow_phase_candidates = c.candidates - c.candidate_padding - c.rejected_after_search;
        counts.candidates = counts.narrow_phase_candidates + c.rejected + c.rejected_after_search;
    }

    SceneView scene_view() {
        // sat_no_edges calls pairs intersecting that only an edge axis separates, however far apart.
        TetSlabs* slabs = options_.narrow_phase == NarrowPhase::sat_no_edges ? nullptr : slabs_.data();
        return SceneView{positions_.data(), tets_.data(), tet_object_.data(), info_.data(), planes_.data(), slabs, pair_active_.data(),
                         checked_objects_.data(), meeting_boxes_.data(), frame_tets_,
                         static_cast<std::uint32_t>(object_boxes_.size()),
                         exclusion_begin_.size() ? exclusion_begin_.data() : nullptr, excluded_.data(), options_.margin};
    }
    template <class T>
    void fill(buffer<T>& b, const T& value) {
        exec_.for_each(b.size(), FillKernel<T>{b.data(), value});
    }
    /// Makes `b` hold n elements, all `value` when it had to change size (kept as they are otherwise).
    template <class T>
    void resize_filled(buffer<T>& b, std::size_t n, const T& value) {
        if (b.size() == n) return;
        b.resize_discard(n);
        fill(b, value);
    }
    /// Reads the counters now: a host wait, paid only by a first frame (see start()).
    FrameCounters read_counters_now() {
        FrameCounters c;
        exec_.download(&c, counters_.data(), 1);
        return c;
    }
    void reset_counters() {
        const FrameCounters fresh = FrameCounters::fresh();
        exec_.upload(counters_.data(), &fresh, 1);
    }

    void enqueue_frame();
    void place_static();
    void adopt_staged_positions();
    void bounds_and_culling();
    void grid_geometry();
    void size_grid(const FrameCounters& plan);
    GridView populate();
    std::optional<FrameCounters> find_candidates(const GridView& grid);
    void narrow_phase_and_results();

    /// Where an attempt at a frame starts again once a buffer has grown: from the first stage whose
    /// buffer was too small, since what the stages before it computed is still in place (or nowhere,
    /// when everything fitted).
    enum class Rerun { none, results, candidates, grid };
    Rerun grow_for(const FrameCounters& c);
    bool pairs_window_within_memory(std::size_t wanted, std::size_t needed);
    void reserve_pairs_window(std::uint64_t candidates, bool at_least = false);
    void refuse_beyond_candidate_bound(const GridView& grid, std::uint32_t cells);
    [[noreturn]] void refuse_frame(const std::string& need, std::uint64_t bytes);
    [[noreturn]] void refuse_first_frame(std::uint64_t candidates, bool at_least = false);
    /// Bytes of the pairs' window per pair: its key, its sort's spare key, its contact and its distance
    /// and closest points where asked for.
    std::size_t pair_bytes() const {
        return 2 * sizeof(std::uint64_t) + (options_.contacts ? sizeof(Contact) : 0) +
               (options_.distances ? sizeof(float) + sizeof(ClosestPoints) : 0);
    }
    /// Elements of `bytes_each` bytes that buffers now holding `own_bytes` may grow to under
    /// DetectorOptions::memory_limit (room_for).
    std::size_t room(std::size_t own_bytes, std::size_t bytes_each) const {
        return room_for(options_.memory_limit, memory_bytes() - own_bytes, bytes_each);
    }
    void enqueue_from(Rerun stage);
    void enqueue_results();
    void enqueue_again(const FrameCounters& c, Rerun stage);

    /// Marks between the stages of a frame, for StageTimes.
    enum StageMark { frame_start, boxes_done, grid_done, candidates_done, narrow_phase_done, sorted, results_done, frame_end };

    Exec exec_;
    typename Exec::stage_clock clock_; // kept between frames: on the GPU it holds CUDA events, created once
    DetectorOptions options_;
    SceneTopology topology_; ///< the per-object parts (the per-tet and per-vertex ones are in the buffers)
    std::vector<std::uint32_t> object_first_; ///< object_first_tets()
    std::uint32_t stamp_ = 0;

    buffer<TetIndices> tets_;
    buffer<std::uint32_t> tet_object_;
    buffer<std::uint32_t> object_tet_begin_;
    buffer<std::uint32_t> user_id_;   ///< stored tet -> caller's global id
    buffer<std::uint32_t> stored_id_; ///< caller's global id -> stored tet
    buffer<vec3> positions_;          ///< in stored order (SceneTopology::vertex_user_id)
    buffer<std::uint32_t> vertex_user_id_;
    buffer<vec3> staged_positions_; ///< handed over on the device, current once a frame found them finite
    buffer<TetInfo> info_;
    buffer<TetPlanes> planes_;
    buffer<TetSlabs> slabs_;
    buffer<std::uint32_t> colliding_;      ///< per stored tet
    buffer<std::uint32_t> user_colliding_; ///< per tet in the caller's numbering
    buffer<std::uint32_t> run_objects_;    ///< per run of tets of one object (stage 1's reduction)
    buffer<Aabb> run_boxes_;
    buffer<Aabb> object_boxes_;
    buffer<Aabb> meeting_boxes_;
    buffer<std::uint8_t> pair_enabled_; ///< the caller's switches, [objects * objects]
    buffer<std::uint8_t> pair_active_;  ///< enabled and the boxes overlap, this frame
    buffer<std::uint32_t> checked_objects_; ///< per object, the bits of the objects it is checked against this frame
    buffer<std::uint32_t> exclusion_begin_; ///< SceneView::exclusion_begin; empty when nothing is excluded
    buffer<std::uint32_t> excluded_;
    buffer<BucketHeader> headers_;
    buffer<std::uint32_t> ids_;
    buffer<EntryBlock> entry_blocks_; ///< the compacted cells' lists
    buffer<BlockBoundGroup> block_bounds_; ///< the bound of each block of entry_block entries
    buffer<OwnCells> own_cells_; ///< per stored tet, where it sits in its own layer's cells
    buffer<std::uint32_t> claimed_slots_; ///< the main buckets in the order they were claimed
    buffer<std::uint32_t> list_keys_;     ///< the lists' keys as gathered, then sorted into sorted_keys_
    buffer<std::uint32_t> sorted_keys_;
    buffer<std::uint32_t> list_begin_;    ///< the range of each claimed cell's list, for sorting
    buffer<std::uint32_t> list_end_;
    buffer<FrameCounters> counters_;
    buffer<std::uint64_t> candidates_;
    buffer<std::uint64_t> candidates_grown_; ///< the next candidate buffer while one grows keeping its contents
    buffer<std::uint64_t> near_; ///< with a margin, parallel to candidates_: NarrowPhaseKernel::near
    buffer<ResumePoint> resume_points_[2];  ///< where search items stopped (one per tet), read by one run and written by the next
    buffer<std::uint64_t> out_keys_;  ///< the colliding pairs; its size is the window they are appended to
    buffer<Contact> out_contacts_;
    buffer<float> out_distances_;       ///< DetectorOptions::distances, parallel to out_keys_
    buffer<ClosestPoints> out_closest_;
    std::uint32_t slot_count_ = 0;
    std::uint32_t overflow_capacity_ = 0;
    std::uint32_t entry_capacity_ = 0;
    std::uint32_t bucket_capacity_ = 0; ///< ids per bucket: the option, or the largest automatic choice of a topology's plans
    std::size_t pairs_window_ = 0;   ///< room for colliding pairs this frame
    bool grid_planned_ = false;      ///< the grid has been sized from a plan read back once
    bool pairs_sized_ = false;       ///< the pairs' window has been sized from a count read back once
    bool self_collision_ = false;    ///< some object is checked against itself this frame
    std::size_t colliding_count_ = 0; ///< pairs in out_keys_ after the last detection
    GridView grid_{}; ///< the frame's grid, once populated
    Locator<Exec> locator_; ///< point location's buffers
    /// The tets a frame runs: the moving ones, stored first (static_last); all of them for a baseline.
    std::uint32_t frame_tets_ = 0;
    StaticGridStore<Exec> statics_;

    // The frame in flight: the staged ranges it adopts, and what it copies back at its end, read by
    // finish(): the counters, and the results where they land (Exec::landed).
    std::vector<VertexRange> staged_;
    FrameCounters last_{};
    std::size_t keys_view_ = 0, flags_view_ = 0, contacts_view_ = 0, distances_view_ = 0, closest_view_ = 0;
    std::uint64_t waits_before_ = 0;
    std::uint32_t regrows_ = 0;
};

} // namespace kdet
