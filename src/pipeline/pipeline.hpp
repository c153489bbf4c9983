#pragma once
/// @file pipeline.hpp
/// @brief The per-frame pipeline, written once over an execution layer (CpuExec or CudaExec).
/// A frame is enqueued whole: each stage finds the sizes and the grid's geometry that the stages
/// before it computed in the backend's memory (FrameCounters), so the host reads nothing in between.
/// It reads the counters (and the results, when they go to the host) once at the end, and grows a
/// buffer only when a counter says that the buffer was too small, running the frame again from the
/// stage that lacked room.

#include "pipeline/baseline_kernels.hpp"
#include "pipeline/bounding_boxes.hpp"
#include "pipeline/candidate_search.hpp"
#include "pipeline/capacity.hpp"
#include "pipeline/grid_populate.hpp"
#include "pipeline/grid_sizing.hpp"
#include "pipeline/narrow_phase.hpp"
#include "pipeline/pipeline_base.hpp"
#include "pipeline/positions_check.hpp"
#include "pipeline/scene_view.hpp"

#include <kdet/error.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>

namespace kdet {

/// @brief What the kernels of a frame count and compute for the stages after them, in the backend's
/// memory; the host reads it once, when the frame is done. The counters that work items add to as
/// they go (appends, claimed cells, rejections) each have a cache line of their own, apart from the
/// values every item reads (the grid's failure bits, its geometry): sharing one, the CPU's threads
/// passed the line back and forth on every add and read.
struct FrameCounters {
    alignas(64) unsigned long long candidates; ///< appended (counts past the buffer's end)
    unsigned long long candidate_padding; ///< of which slots hold no_pair_key (see KeyAppender)
    alignas(64) unsigned long long tests_run;
    alignas(64) unsigned long long rejected; ///< candidate pairs the pre-test (slabs, face planes) proved separated
    /// Of the candidates written, those the face planes proved separated in the narrow phase (where the
    /// search does not run them: Exec::face_planes_in_search)
    alignas(64) unsigned long long rejected_after_search;
    alignas(64) unsigned long long colliding_pairs; ///< appended (counts past the window's end)
    alignas(64) std::uint32_t cells_claimed;
    alignas(64) std::uint32_t grid_entries; ///< entries of the compacted cells
    alignas(64) std::uint32_t overflow_used;
    alignas(64) unsigned long long exact_stage_pairs; ///< pairs that reached the exact stage of NarrowPhase::exact
    /// Brute force's own count of those; the narrow phase tests its colliding pairs again, and that
    /// count (exact_stage_pairs) is the one reported, as for the other methods.
    unsigned long long brute_force_exact_stage;
    unsigned long long colliding_tets;
    unsigned long long involved_tets; ///< tets of the objects in a pair checked this frame
    std::uint32_t stopped_items; ///< ResumePoints the candidate search left (items, not tets): its buffer was full
    std::uint32_t grid_failure;
    std::uint32_t layer_mask;
    std::uint32_t first_non_finite_vertex; ///< lowest staged vertex found non-finite, or no_vertex
    std::uint32_t object_runs; ///< runs of tets of one object, i.e. non-empty objects
    std::uint32_t min_size; ///< float_to_ordered, over the relevant tets
    std::uint32_t max_size;
    std::uint32_t min_upper_size; ///< float_to_ordered, of the relevant tets' upper bounds on their size (TetSizeKernel)
    std::uint32_t max_lower_size; ///< and of their lower bounds
    OrderedBox region; ///< the gridded region: the boxes of the objects in a checked pair
    GridParams params; ///< GridParamsKernel's
    std::uint32_t spacing_octaves[float_octaves]; ///< TetSizeKernel's histogram of the tets' spacings
    unsigned long long layer_entries[max_grid_layers]; ///< cell entries the relevant tets need, per layer
    unsigned long long layer_cells[max_grid_layers];   ///< bound on the cells they occupy, per layer

    /// The values a frame starts from: empty size range and region.
    static FrameCounters fresh() {
        FrameCounters c{};
        c.min_size = float_to_ordered(std::numeric_limits<float>::infinity());
        c.max_size = float_to_ordered(0.0f);
        c.min_upper_size = float_to_ordered(std::numeric_limits<float>::infinity());
        c.max_lower_size = float_to_ordered(0.0f);
        c.first_non_finite_vertex = no_vertex;
        for (int a = 0; a < 3; ++a) {
            c.region.lo[a] = float_to_ordered(std::numeric_limits<float>::infinity());
            c.region.hi[a] = float_to_ordered(-std::numeric_limits<float>::infinity());
        }
        return c;
    }
};

template <class Exec>
class Pipeline final : public PipelineBase {
    template <class T>
    using buffer = typename Exec::template buffer<T>;

public:
    explicit Pipeline(const DetectorOptions& options)
        : exec_(options), clock_(exec_.make_stage_clock()), options_(options) {}

    void set_topology(const SceneTopology& topology) override {
        topology_ = topology;
        const std::size_t tets = topology.tets.size();
        tets_.resize_discard(tets);
        exec_.upload(tets_.data(), topology.tets.data(), tets);
        tet_object_.resize_discard(tets);
        exec_.upload(tet_object_.data(), topology.tet_object.data(), tets);
        user_id_.resize_discard(tets);
        exec_.upload(user_id_.data(), topology.tet_user_id.data(), tets);
        std::vector<std::uint32_t> stored_id(tets);
        for (std::uint32_t t = 0; t < tets; ++t) stored_id[topology.tet_user_id[t]] = t;
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
        // An empty object has no run of tets, so the reduction never writes its box: empty once here.
        const float inf = std::numeric_limits<float>::infinity();
        fill(object_boxes_, Aabb{{inf, inf, inf}, {-inf, -inf, -inf}});
        pair_enabled_.resize_discard(objects * objects);
        pair_active_.resize_discard(objects * objects);
        checked_objects_.resize_discard(objects);
        counters_.resize_discard(1);
        // New geometry: the first frame plans the grid and sizes the pairs from what it finds; the bucket
        // size is chosen again from that plan (and only grows with later ones).
        grid_planned_ = pairs_sized_ = false;
        bucket_capacity_ = 0;
        colliding_count_ = 0;
    }

    void stage_positions(std::uint32_t first, const vec3* positions, std::uint32_t count) override {
        // Allocated on first use: only simulations that hand positions over on the device need it.
        if (staged_positions_.size() != positions_.size()) staged_positions_.resize_discard(positions_.size());
        exec_.copy(staged_positions_.data() + first, positions, count);
    }

    void get_positions(std::uint32_t first, vec3* positions, std::uint32_t count, bool staged) override {
        exec_.download(positions, (staged ? staged_positions_ : positions_).data() + first, count);
    }

    DeviceResults device_results() override {
        return DeviceResults{out_keys_.data(), colliding_count_, user_colliding_.data(), user_colliding_.size(),
                             options_.contacts ? out_contacts_.data() : nullptr};
    }

    std::size_t memory_bytes() const override {
        return tets_.capacity_bytes() + tet_object_.capacity_bytes() + object_tet_begin_.capacity_bytes() +
               user_id_.capacity_bytes() + stored_id_.capacity_bytes() + positions_.capacity_bytes() + vertex_user_id_.capacity_bytes() +
               staged_positions_.capacity_bytes() +
               info_.capacity_bytes() + planes_.capacity_bytes() + slabs_.capacity_bytes() + colliding_.capacity_bytes() + user_colliding_.capacity_bytes() +
               run_objects_.capacity_bytes() + run_boxes_.capacity_bytes() + object_boxes_.capacity_bytes() +
               pair_enabled_.capacity_bytes() + pair_active_.capacity_bytes() + checked_objects_.capacity_bytes() +
               grid_bytes() + counters_.capacity_bytes() +
               candidates_.capacity_bytes() + candidates_grown_.capacity_bytes() +
               resume_points_[0].capacity_bytes() + resume_points_[1].capacity_bytes() + out_keys_.capacity_bytes() + out_contacts_.capacity_bytes() +
               blocks_begin_.capacity_bytes() + block_objects_.capacity_bytes() + exec_.scratch_bytes();
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
               const std::vector<std::uint8_t>& pair_enabled) override;
    std::uint32_t finish(FrameResult& result) override;

private:
    SceneView scene_view() {
        // sat_no_edges calls pairs intersecting that only an edge axis separates, however far apart.
        TetSlabs* slabs = options_.narrow_phase == NarrowPhase::sat_no_edges ? nullptr : slabs_.data();
        return SceneView{positions_.data(), tets_.data(), tet_object_.data(), info_.data(), planes_.data(), slabs, pair_active_.data(),
                         checked_objects_.data(), object_boxes_.data(), static_cast<std::uint32_t>(tets_.size()),
                         static_cast<std::uint32_t>(object_boxes_.size())};
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
    bool grid_method() const { return options_.method == Method::kdet || options_.method == Method::kdet_no_pairs; }

    void enqueue_frame();
    void adopt_staged_positions();
    void bounds_and_culling();
    void grid_geometry();
    void size_grid(const FrameCounters& plan);
    GridView populate();
    std::optional<FrameCounters> find_candidates(const GridView& grid);
    void brute_force();
    void narrow_phase_and_results();

    /// Where an attempt at a frame starts again once a buffer has grown: from the first stage whose
    /// buffer was too small, since what the stages before it computed is still in place (or nowhere,
    /// when everything fitted).
    enum class Rerun { none, results, candidates, grid };
    Rerun grow_for(const FrameCounters& c);
    std::size_t pairs_window_within_memory(std::size_t wanted, std::size_t needed);
    void enqueue_from(Rerun stage);
    void enqueue_results();
    void enqueue_again(const FrameCounters& c, Rerun stage);

    /// Marks between the stages of a frame, for StageTimes.
    enum StageMark { frame_start, boxes_done, grid_done, candidates_done, narrow_phase_done, sorted, results_done, frame_end };

    Exec exec_;
    typename Exec::stage_clock clock_; // kept between frames: on the GPU it holds CUDA events, created once
    DetectorOptions options_;
    SceneTopology topology_;
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
    buffer<std::uint8_t> pair_enabled_; ///< the caller's switches, [objects * objects]
    buffer<std::uint8_t> pair_active_;  ///< enabled and the boxes overlap, this frame
    buffer<std::uint32_t> checked_objects_; ///< per object, the bits of the objects it is checked against this frame
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
    buffer<ResumePoint> resume_points_[2];  ///< where search items stopped (one per tet), read by one run and written by the next
    buffer<std::uint64_t> out_keys_;  ///< the colliding pairs; its size is the window they are appended to
    buffer<Contact> out_contacts_;
    buffer<std::uint64_t> blocks_begin_;
    buffer<std::uint32_t> block_objects_;
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

    // The frame in flight: the staged ranges it adopts, and what it copies back at its end, read by
    // finish(): the counters, and the results where they land (Exec::landed).
    std::vector<VertexRange> staged_;
    FrameCounters last_{};
    std::size_t keys_view_ = 0, flags_view_ = 0, contacts_view_ = 0;
    std::uint64_t waits_before_ = 0;
    std::uint32_t regrows_ = 0;
};

/// @brief Stage 1: tet boxes, object boxes, and which pairs of objects are checked (pair_active_),
/// all in the backend's memory.
template <class Exec>
void Pipeline<Exec>::bounds_and_culling() {
    const std::size_t objects = object_boxes_.size();
    const std::uint32_t tets = static_cast<std::uint32_t>(tets_.size());
    FrameCounters* c = counters_.data();
    exec_.for_each(tets, TetBoundsKernel{scene_view()});
    // Tets of one object are contiguous: their boxes reduce run by run, in parallel over all tets.
    exec_.reduce_runs(tet_object_.data(), TetBoxOf{info_.data()}, tets, BoxUnion{}, run_objects_.data(),
                      run_boxes_.data(), &c->object_runs);
    exec_.for_each(objects, ObjectBoxesKernel{run_objects_.data(), run_boxes_.data(), &c->object_runs,
                                              object_boxes_.data()});
    exec_.for_each(objects, ObjectCullingKernel{pair_enabled_.data(), pair_active_.data(), checked_objects_.data(), object_boxes_.data(),
                                                object_tet_begin_.data(), static_cast<std::uint32_t>(objects),
                                                &c->region, &c->involved_tets});
}

/// @brief Stage 1, grid methods only: sizes the relevant tets, picks the grid's geometry from them
/// and each relevant tet's layer, and counts the cells they need per layer (the plan).
template <class Exec>
void Pipeline<Exec>::grid_geometry() {
    FrameCounters* c = counters_.data();
    exec_.for_each(tets_.size(), TetSizeKernel{scene_view(), &c->min_size, &c->max_size, &c->min_upper_size, &c->max_lower_size,
                                                 c->spacing_octaves});
    exec_.for_each(1, GridParamsKernel{&c->min_size, &c->max_size, c->spacing_octaves, &c->region, &c->params,
                                       Exec::grid_cell_spacings});
    constexpr std::uint32_t chunk = Exec::plan_chunk;
    exec_.for_each((tets_.size() + chunk - 1) / chunk,
                   GridPlanKernel{scene_view(), &c->params, chunk, c->layer_entries, c->layer_cells, &c->layer_mask}, chunk);
}

/// @brief Overflow buckets the grid's pool holds at most.
constexpr std::uint64_t max_overflow_buckets = std::uint64_t{1} << 30;

/// @brief Sizes the table for a plan: per layer the occupied cells are at most the plan's bound
/// (GridPlanKernel) and at most the region's cells; the table gets a quarter more slots than that
/// bound (probing stays short), and the overflow pool one bucket per bucket_capacity entries, which
/// holds every chain whatever the cells' fill, plus room for the buckets that racing threads waste;
/// the compacted lists get room for the entries, which the plan counts exactly. All only grow, by a
/// quarter at least (grown_capacity), so a scene that keeps its size sizes them once and a growing
/// one a few times.
template <class Exec>
void Pipeline<Exec>::size_grid(const FrameCounters& plan) {
    const GridParams& params = plan.params;
    double cells = 0.0, entries = 0.0;
    for (int layer = 0; layer < params.layer_count; ++layer) {
        const double n = static_cast<double>(plan.layer_entries[layer]);
        if (n == 0.0) continue;
        const double occupied = static_cast<double>(plan.layer_cells[layer]);
        const double cell = std::ldexp(static_cast<double>(params.cell_size0), layer);
        double region = 1.0;
        for (int a = 0; a < 3; ++a) {
            const double extent = static_cast<double>(ordered_to_float(plan.region.hi[a])) -
                                  static_cast<double>(ordered_to_float(plan.region.lo[a]));
            region *= std::floor(extent / cell) + 2.0;
        }
        cells += std::min(occupied, region);
        entries += n;
    }
    // Chosen anew from each plan but never smaller: a scene whose objects first meet in a later frame
    // has few or no gridded tets in its first plans.
    bucket_capacity_ = options_.bucket_capacity ? options_.bucket_capacity
                                                : std::max(bucket_capacity_, automatic_bucket_capacity(entries, cells));
    const std::uint32_t capacity = bucket_capacity_;
    std::uint32_t wanted_slots = 1024;
    while (wanted_slots < 1.25 * cells && wanted_slots < (1u << 30)) wanted_slots *= 2;
    // A thread that loses the race to chain a full bucket leaves the bucket it took unused for the
    // frame: an eighth more (and 64) keeps such losses from failing the pass and running it again.
    const double wanted_pool = std::min(std::ceil(1.125 * entries / capacity) + 64.0, static_cast<double>(max_overflow_buckets));
    slot_count_ = std::max(slot_count_, wanted_slots);
    overflow_capacity_ = static_cast<std::uint32_t>(
        grown_capacity(overflow_capacity_, static_cast<std::uint64_t>(wanted_pool), max_overflow_buckets));
    // An eighth more than the plan's count: a deforming scene's cells gain entries from frame to frame,
    // and each time the lists outgrew their room the frame would run twice.
    const double wanted_entries = std::min(std::ceil(1.125 * entries), 4294967295.0);
    entry_capacity_ = static_cast<std::uint32_t>(
        grown_capacity(entry_capacity_, static_cast<std::uint64_t>(wanted_entries), 4294967295u));
}

/// @brief Stage 2: fills the hash table as sized so far, then compacts each cell's ids into one list
/// (what the queries read); a failed insert or a list that does not fit sets grid_failure and the
/// frame reruns with more room (grow_for).
template <class Exec>
GridView Pipeline<Exec>::populate() {
    const std::uint32_t capacity = bucket_capacity_;
    const std::size_t buckets = static_cast<std::size_t>(slot_count_) + overflow_capacity_;
    if (headers_.size() != buckets || ids_.size() != buckets * capacity) {
        headers_.resize_discard(buckets);
        ids_.resize_discard(buckets * capacity);
        fill(headers_, BucketHeader{}); // stamp 0 is never current, so this empties the table
        stamp_ = 0;
    }
    if (++stamp_ >= 0x7fffffffu) { // the stamp is about to wrap: clear once instead
        fill(headers_, BucketHeader{});
        stamp_ = 1;
    }
    FrameCounters* c = counters_.data();
    std::uint32_t slot_bits = 0;
    while ((1u << slot_bits) < slot_count_) ++slot_bits;
    const std::uint32_t blocks = (entry_capacity_ + entry_block - 1) / entry_block;
    // The lanes of the last block past the lists are read (and masked out) by every query there.
    resize_filled(entry_blocks_, blocks, EntryBlock{});
    // Likewise the bounds of the last group's blocks past the lists.
    resize_filled(block_bounds_, (blocks + bound_group - 1) / bound_group, BlockBoundGroup{});
    own_cells_.resize_discard(tets_.size());
    claimed_slots_.resize_discard(slot_count_);
    list_keys_.resize_discard(entry_capacity_);
    sorted_keys_.resize_discard(entry_capacity_);
    list_begin_.resize_discard(slot_count_);
    list_end_.resize_discard(slot_count_);
    const GridView grid{headers_.data(), ids_.data(), entry_blocks_.data(), list_keys_.data(), list_begin_.data(), list_end_.data(),
                        block_bounds_.data(), own_cells_.data(), &c->grid_entries, entry_capacity_,
                        &c->overflow_used, &c->grid_failure, &c->cells_claimed, claimed_slots_.data(), slot_count_, slot_bits, capacity,
                        overflow_capacity_, stamp_, 64u, options_.hash};
    exec_.for_each_in_runs(tets_.size(), PopulateKernel{scene_view(), grid, &c->params});
    exec_.for_each(slot_count_, GatherCellsKernel{scene_view(), grid});
    exec_.sort_lists(list_keys_.data(), sorted_keys_.data(), entry_capacity_, list_begin_.data(), list_end_.data(), slot_count_);
    exec_.for_each(entry_capacity_, PlaceEntriesKernel{scene_view(), grid, sorted_keys_.data()});
    exec_.for_each(blocks, BoundEntryBlocksKernel{grid});
    return grid;
}

/// @brief Stage 3 (kdet): candidate pairs, each written once. A frame that reads its counters back
/// here (a first frame, to size the pairs' window) does not rerun when the buffer overflows: the
/// buffer grows keeping what was stored and only the search items (tets, or parts of their searches:
/// SearchPart) that did not fit search again, each resuming after the keys it had
/// stored (they stopped searching when they did not fit). There is room to resume one item per tet;
/// when more stop (a first buffer far too small for a split search), every item searches again into
/// the grown buffer. Later frames read nothing here; an overflow shows in the frame's counters and the
/// frame reruns (grow_for). Returns the counters when it read them.
template <class Exec>
std::optional<FrameCounters> Pipeline<Exec>::find_candidates(const GridView& grid) {
    // Items are numbered in 32 bits (ResumePoint): a scene too large for that searches its tets whole.
    const std::uint32_t layer_parts_wanted = Exec::search_layer_parts(self_collision_, tets_.size());
    const std::uint32_t block_parts_wanted = Exec::search_block_parts(self_collision_, tets_.size());
    const bool split = tets_.size() * layer_parts_wanted * block_parts_wanted <= 0xffffffffu;
    const std::uint32_t layer_parts = split ? layer_parts_wanted : 1u;
    const std::uint32_t block_parts = split ? block_parts_wanted : 1u;
    const std::size_t parts = std::size_t{layer_parts} * block_parts;
    constexpr std::uint32_t tets_per_item = Exec::search_tets_per_item;
    using Search = FindCandidatesKernel<tets_per_item, Exec::face_planes_in_search>;
    const std::size_t runs = TetRuns<tets_per_item>::count(static_cast<std::uint32_t>(tets_.size()));
    const std::size_t all_items = runs * parts, resume_room = tets_.size();
    for (auto& points : resume_points_) points.resize_discard(resume_room);
    std::size_t items = all_items;
    std::size_t first_slot = 0; ///< where this run's keys start in the buffer
    const ResumePoint* resume_from = nullptr;
    for (int run = 0;; ++run) {
        FrameCounters* c = counters_.data();
        ResumePoint* stopped = resume_points_[run % 2].data();
        const KeyAppender out{candidates_.data(), candidates_.size(), &c->candidates, &c->candidate_padding};
        exec_.for_each(items, Search{scene_view(), grid, &c->params, &c->layer_mask, out, &c->rejected, resume_from, stopped,
                                     &c->stopped_items, static_cast<std::uint32_t>(resume_room), layer_parts, block_parts,
                                     !pairs_sized_},
                       tets_per_item);
        if (pairs_sized_) return std::nullopt;
        FrameCounters after = read_counters_now();
        if (!after.stopped_items) return after;
        // The items that stopped quit searching when they did not fit, so their need is estimated from
        // the keys per item of the ones that finished in this run, with a quarter more (room for the
        // next frames, whose overflow would rerun the whole frame); the buffer grows by half at
        // least, so a poor estimate costs few rounds; where the memory does not hold that much beside
        // the kept keys, half as much, and so on down to a batch more (each round stores some).
        const std::size_t kept = candidates_.size();
        const double finished = static_cast<double>(items - after.stopped_items);
        const double stored_now = static_cast<double>(kept - std::min(kept, first_slot));
        const double estimate = finished > 0.0 ? 1.25 * stored_now / finished * after.stopped_items : 0.0;
        std::size_t more = std::max(static_cast<std::size_t>(estimate), kept / 2);
        const bool resume = after.stopped_items <= resume_room;
        while (more > 0 && !candidates_grown_.try_resize_discard(kept + more + KeyBatch::size)) more /= 2;
        if (more == 0) candidates_grown_.resize_discard(kept + KeyBatch::size); // throws if not even that fits
        if (resume) exec_.copy(candidates_grown_.data(), candidates_.data(), kept);
        candidates_.swap(candidates_grown_);
        ++regrows_;
        if (resume) {
            after.candidates = kept;
            first_slot = kept;
            items = after.stopped_items;
            resume_from = stopped;
        } else {
            after.candidates = after.candidate_padding = after.rejected = 0;
            first_slot = 0;
            items = all_items;
            resume_from = nullptr;
        }
        after.stopped_items = 0;
        exec_.upload(counters_.data(), &after, 1);
    }
}

/// @brief Both brute-force methods: every pair of enabled objects is tested, colliding pairs appended.
/// brute_force_pairs lays its work out per pair of objects on the host, so it reads pair_active_ (one
/// wait more per frame).
template <class Exec>
void Pipeline<Exec>::brute_force() {
    FrameCounters* c = counters_.data();
    const KeyAppender out{candidates_.data(), candidates_.size(), &c->candidates, &c->candidate_padding};
    unsigned long long* exact_stage = &counters_.data()->brute_force_exact_stage;
    if (options_.method == Method::brute_force_loop) {
        with_narrow_phase(options_.narrow_phase, [&](auto test) {
            exec_.for_each(tets_.size(), BruteForceLoopKernel<decltype(test)::value>{scene_view(), object_tet_begin_.data(), out,
                                                                          exact_stage});
        });
        return;
    }
    const std::size_t objects = object_boxes_.size();
    std::vector<std::uint8_t> active(objects * objects);
    exec_.download(active.data(), pair_active_.data(), active.size());
    std::vector<std::uint64_t> block_begin{0};
    std::vector<std::uint32_t> block_objects;
    for (std::uint32_t a = 0; a < objects; ++a)
        for (std::uint32_t b = a; b < objects; ++b) {
            if (!active[a * objects + b]) continue;
            const std::uint64_t na = topology_.object_tet_begin[a + 1] - topology_.object_tet_begin[a];
            const std::uint64_t nb = topology_.object_tet_begin[b + 1] - topology_.object_tet_begin[b];
            block_begin.push_back(block_begin.back() + (a == b ? na * (na - 1) / 2 : na * nb));
            block_objects.push_back(a);
            block_objects.push_back(b);
        }
    blocks_begin_.resize_discard(block_begin.size());
    exec_.upload(blocks_begin_.data(), block_begin.data(), block_begin.size());
    block_objects_.resize_discard(block_objects.size());
    exec_.upload(block_objects_.data(), block_objects.data(), block_objects.size());
    with_narrow_phase(options_.narrow_phase, [&](auto test) {
        exec_.for_each(block_begin.back(),
                       BruteForcePairsKernel<decltype(test)::value>{scene_view(), object_tet_begin_.data(), blocks_begin_.data(),
                                                         block_objects_.data(),
                                                         static_cast<std::uint32_t>(block_objects.size() / 2), out,
                                                         exact_stage});
    });
}

/// @brief Stages 5 and 6: the narrow phase once per candidate (they are unique, see
/// for_each_larger_neighbour), over the count the candidate stage left in the backend's memory; the
/// colliding pairs, appended under the caller's ids into the window, sorted into the output order,
/// and their contacts.
template <class Exec>
void Pipeline<Exec>::narrow_phase_and_results() {
    FrameCounters* c = counters_.data();
    // The whole window is copied out (the count is not known when the copy is enqueued): a new one is
    // filled once, so that no byte copied is undefined.
    resize_filled(out_keys_, pairs_window_, no_pair_key);
    const KeyAppender out{out_keys_.data(), out_keys_.size(), &c->colliding_pairs, nullptr};
    with_narrow_phase(options_.narrow_phase, [&](auto test) {
        constexpr std::uint32_t per_item = Exec::keys_per_appending_item;
        const auto decide = [&](auto planes_here) {
            exec_.for_each_counted(&c->candidates, candidates_.size(),
                                   NarrowPhaseKernel<decltype(test)::value, per_item, decltype(planes_here)::value>{
                                       scene_view(), candidates_.data(), &c->candidates, candidates_.size(), colliding_.data(),
                                       user_id_.data(), out, &c->exact_stage_pairs, &c->rejected_after_search},
                                   per_item);
        };
        // The search's candidates still need their face planes where it did not run them; brute force's
        // pairs need none (and have no planes).
        if constexpr (!Exec::face_planes_in_search) {
            if (options_.method == Method::kdet) return decide(std::true_type{});
        }
        decide(std::false_type{});
    });
    clock_.mark(narrow_phase_done);
    // The keys hold the caller's ids, which are below the tet count.
    const auto tet_count = static_cast<std::uint32_t>(tets_.size());
    exec_.sort(out_keys_.data(), out_keys_.size(), &c->colliding_pairs, pair_key_bits(tet_count),
               pair_key_low_word_bits(tet_count));
    clock_.mark(sorted);
    if (options_.contacts) {
        resize_filled(out_contacts_, pairs_window_, Contact{});
        exec_.for_each_counted(&c->colliding_pairs, out_contacts_.size(),
                               ContactKernel{scene_view(), stored_id_.data(), out_keys_.data(), &c->colliding_pairs,
                                             out_keys_.size(), out_contacts_.data()});
    }
    clock_.mark(results_done);
}

/// @brief Enqueues one attempt at the frame, down to the copies of its counters and results. Only a
/// first frame reads anything before the end: the grid's plan, to size the table (so that one-off
/// queries grow nothing), and the candidate count, to size the window for the colliding pairs.
template <class Exec>
void Pipeline<Exec>::enqueue_frame() {
    reset_counters();
    adopt_staged_positions();
    fill(colliding_, 0u);
    bounds_and_culling();
    if (grid_method()) grid_geometry();
    clock_.mark(boxes_done);
    if (grid_method() && !grid_planned_) {
        const FrameCounters plan = read_counters_now();
        size_grid(plan);
        // Linear in the tets (thesis 7.3): k-freeness bounds the larger neighbours of each tet.
        const std::size_t estimate = options_.initial_candidate_capacity
                                         ? options_.initial_candidate_capacity
                                         : std::max<std::size_t>(4096, 16 * plan.involved_tets);
        // A guess: where the memory does not hold it, the search starts from less and grows as it
        // goes (stop and resume, below).
        if (candidates_.size() < estimate) resize_within_memory(candidates_, estimate, std::min<std::size_t>(estimate, 4096));
        grid_planned_ = true;
    }
    enqueue_from(Rerun::grid);
}

/// @brief The stages of an attempt from `stage` on (grid: populating, candidates: the candidate
/// stage, results: the narrow phase and after), once those before it have run.
template <class Exec>
void Pipeline<Exec>::enqueue_from(Rerun stage) {
    const Method method = options_.method;
    FrameCounters* c = counters_.data();
    if (stage == Rerun::grid && grid_method()) {
        grid_ = populate();
        clock_.mark(grid_done);
    }
    if (stage != Rerun::results) {
        std::optional<FrameCounters> found; ///< the counters after the candidate stage, when read back
        if (method == Method::kdet) {
            found = find_candidates(grid_);
        } else if (method == Method::kdet_no_pairs) {
            with_narrow_phase(options_.narrow_phase, [&](auto test) {
                using Search = NoPairsKernel<decltype(test)::value, Exec::search_tets_per_item>;
                exec_.for_each(TetRuns<Exec::search_tets_per_item>::count(static_cast<std::uint32_t>(tets_.size())),
                               Search{scene_view(), grid_, &c->params, &c->layer_mask, colliding_.data(), &c->tests_run,
                                      &c->exact_stage_pairs},
                               Exec::search_tets_per_item);
            });
        } else {
            if (candidates_.size() == 0)
                candidates_.resize_discard(options_.initial_candidate_capacity ? options_.initial_candidate_capacity : 4096);
            brute_force();
        }
        clock_.mark(candidates_done);
        if (method != Method::kdet_no_pairs && !pairs_sized_) {
            // The colliding pairs are at most the candidates.
            if (!found) found = read_counters_now();
            pairs_window_ = std::max<std::size_t>(pairs_window_, std::min<std::size_t>(found->candidates, candidates_.size()));
            pairs_sized_ = true;
        }
    }
    enqueue_results();
}

/// @brief The end of a frame's attempt, from the candidates on: the narrow phase and the colliding
/// pairs (not for kdet_no_pairs), the per-tet flags, and the copies of the counters and results.
template <class Exec>
void Pipeline<Exec>::enqueue_results() {
    const Method method = options_.method;
    FrameCounters* c = counters_.data();
    if (method != Method::kdet_no_pairs) narrow_phase_and_results();

    const std::size_t tets = tets_.size();
    exec_.for_each(tets, UserFlagsKernel{stored_id_.data(), colliding_.data(), user_colliding_.data()});
    exec_.sum(user_colliding_.data(), tets, &c->colliding_tets);

    exec_.download_later(&last_, counters_.data(), 1);
    if (!options_.results_to_host) return;
    // The whole window: the count is not known when the copy is enqueued.
    const std::size_t window = method == Method::kdet_no_pairs ? 0 : pairs_window_;
    keys_view_ = exec_.download_view_later(out_keys_.data(), window);
    flags_view_ = exec_.download_view_later(user_colliding_.data(), tets);
    contacts_view_ = exec_.download_view_later(out_contacts_.data(), options_.contacts ? window : 0);
}

/// @brief Runs an attempt again from `stage` (grow_for has grown what it needs): the counters of the
/// stages before it are kept as the attempt left them (`c`, read back at its end), those from it on
/// start anew, and so do the per-tet flags.
template <class Exec>
void Pipeline<Exec>::enqueue_again(const FrameCounters& c, Rerun stage) {
    FrameCounters kept = c;
    if (stage == Rerun::grid) {
        kept.grid_failure = 0;
        kept.overflow_used = 0;
        kept.cells_claimed = 0;
        kept.grid_entries = 0;
    }
    if (stage != Rerun::results) {
        kept.candidates = 0;
        kept.candidate_padding = 0;
        kept.tests_run = 0;
        kept.rejected = 0;
        kept.stopped_items = 0;
        kept.brute_force_exact_stage = 0;
    }
    kept.exact_stage_pairs = 0;
    kept.rejected_after_search = 0;
    kept.colliding_pairs = 0;
    kept.colliding_tets = 0;
    exec_.upload(counters_.data(), &kept, 1);
    fill(colliding_, 0u);
    enqueue_from(stage);
}

/// @brief Checks the positions staged on the device and makes them current if every one is finite,
/// without a wait: the frame's counters carry the verdict to finish(). A rerun of the frame does it
/// again, to the same effect.
template <class Exec>
void Pipeline<Exec>::adopt_staged_positions() {
    std::uint32_t* verdict = &counters_.data()->first_non_finite_vertex;
    for (const VertexRange& r : staged_)
        exec_.for_each(r.count, FiniteCheckKernel{staged_positions_.data(), r.first, verdict});
    for (const VertexRange& r : staged_)
        exec_.for_each(r.count, AdoptPositionsKernel{staged_positions_.data(), vertex_user_id_.data(), positions_.data(), r.first, verdict});
}

/// @brief After a frame: grows what was too small for it and says from which stage it must run
/// again, if at all.
/// The grid also grows for its plan, so the next frame of a growing scene fits at once.
template <class Exec>
typename Pipeline<Exec>::Rerun Pipeline<Exec>::grow_for(const FrameCounters& c) {
    bool grid_again = false, candidates_again = false;
    if (grid_method() && c.params.layer_count > 0) {
        if (c.grid_failure & grid_table_full) slot_count_ *= 2;
        // The pool's count runs past its capacity when it fails, so it says what the frame needed.
        if (c.grid_failure & grid_overflow_pool_full)
            overflow_capacity_ = static_cast<std::uint32_t>(
                std::min(rerun_capacity(overflow_capacity_, c.overflow_used), max_overflow_buckets));
        size_grid(c);
        grid_again = c.grid_failure != 0;
    }
    const std::size_t candidates_fitted = candidates_.size();
    if (c.candidates > candidates_fitted) {
        grow_for_rerun(candidates_, c.candidates);
        candidates_again = true;
    }
    bool pairs_again = false;
    if (options_.method != Method::kdet_no_pairs) {
        if (candidates_again) {
            // The rerun decides every candidate again: the window grows with them, in it (where the
            // memory allows; else a rerun of its own grows it to what it needs).
            pairs_window_ = pairs_window_within_memory(
                pairs_window_for_candidates(pairs_window_, candidates_fitted, candidates_.size()), pairs_window_);
        } else if (c.colliding_pairs > pairs_window_) {
            pairs_window_ = pairs_window_within_memory(rerun_capacity(pairs_window_, c.colliding_pairs), c.colliding_pairs);
            pairs_again = true;
        } else if (c.colliding_pairs * 4 < pairs_window_ && pairs_window_ > 4096) {
            // Far fewer pairs than room: the GPU sorts the whole window, so it shrinks (memory stays).
            pairs_window_ = std::max<std::size_t>(4096, 2 * c.colliding_pairs);
        }
    }
    // A scene whose overlap grows outgrows these as collisions set in, frame after frame: the boxes,
    // sizes and plan (and the grid, and the candidates) are still in place, so the frame runs again
    // from the first stage that lacked room.
    if (grid_again) return Rerun::grid;
    if (candidates_again) return Rerun::candidates;
    return pairs_again ? Rerun::results : Rerun::none;
}

/// @brief Allocates the buffers of a pairs' window of `wanted` pairs and returns `wanted`, or, where the
/// memory does not allow it, of the `needed` pairs alone (resize_within_memory for both buffers that
/// hold the window); throws only when the need does not fit either.
template <class Exec>
std::size_t Pipeline<Exec>::pairs_window_within_memory(std::size_t wanted, std::size_t needed) {
    const std::size_t keys = resize_within_memory(out_keys_, wanted, needed);
    return options_.contacts ? resize_within_memory(out_contacts_, keys, needed) : keys;
}

template <class Exec>
void Pipeline<Exec>::start(const std::vector<PositionUpload>& uploads, const std::vector<VertexRange>& staged,
                           const std::vector<std::uint8_t>& pair_enabled) {
    staged_ = staged;
    waits_before_ = exec_.host_waits();
    regrows_ = 0;
    clock_.begin_frame();
    clock_.mark(frame_start);
    for (const PositionUpload& u : uploads) exec_.upload(positions_.data() + u.first, u.positions, u.count);
    exec_.upload(pair_enabled_.data(), pair_enabled.data(), pair_enabled.size());
    self_collision_ = false;
    for (std::size_t o = 0, objects = object_boxes_.size(); o < objects; ++o) self_collision_ |= pair_enabled[o * objects + o] != 0;
    enqueue_frame();
}

template <class Exec>
std::uint32_t Pipeline<Exec>::finish(FrameResult& result) {
    for (;;) {
        exec_.finish_downloads(); // the frame's one wait
        const Rerun rerun = grow_for(last_);
        if (rerun == Rerun::none) break;
        ++regrows_;
        enqueue_again(last_, rerun);
    }
    clock_.mark(frame_end);
    clock_.wait(frame_end); // recorded after the frame's wait, on an idle stream: no wait more
    staged_.clear();
    const FrameCounters& c = last_;
    if (c.first_non_finite_vertex != no_vertex) {
        // The frame ran on the previous positions: none of its results is handed out.
        colliding_count_ = 0;
        fill(user_colliding_, 0u);
        return c.first_non_finite_vertex;
    }
    const Method method = options_.method;
    colliding_count_ = method == Method::kdet_no_pairs ? 0 : c.colliding_pairs;

    result.pairs.clear();
    result.contacts.clear();
    result.counts = FrameCounts{};
    FrameCounts& counts = result.counts;
    if (method == Method::kdet_no_pairs) {
        counts.candidates = counts.narrow_phase_candidates = c.tests_run;
    } else {
        counts.narrow_phase_candidates = c.candidates - c.candidate_padding - c.rejected_after_search;
        counts.candidates = counts.narrow_phase_candidates + c.rejected + c.rejected_after_search;
    }
    counts.exact_stage_pairs = c.exact_stage_pairs;
    counts.colliding_pairs = colliding_count_;
    counts.colliding_tets = c.colliding_tets;
    counts.buffer_regrows = regrows_;
    if (grid_method() && c.params.layer_count > 0) {
        counts.grid_cells = c.cells_claimed;
        counts.grid_slots = slot_count_;
        counts.grid_overflow_buckets = c.overflow_used;
        counts.grid_bucket_capacity = bucket_capacity_;
    }

    const std::size_t objects = object_boxes_.size();
    result.colliding.resize(options_.results_to_host ? objects : 0);
    if (options_.results_to_host) {
        const std::uint64_t* keys = exec_.template landed<std::uint64_t>(keys_view_);
        const std::uint32_t* flags = exec_.template landed<std::uint32_t>(flags_view_);
        const Contact* contacts = exec_.template landed<Contact>(contacts_view_);
        const auto& begin = topology_.object_tet_begin;
        result.pairs.resize(colliding_count_);
        pairs_from_keys(begin, keys, colliding_count_, result.pairs.data(), options_.threads);
        if (options_.contacts) result.contacts.assign(contacts, contacts + colliding_count_);
        flags_by_object(begin, flags, result.colliding, options_.threads);
    }
    result.memory_bytes = memory_bytes();
    result.grid_bytes = grid_bytes();
    result.candidate_bytes = candidates_.capacity_bytes();
    StageTimes& t = result.times;
    t = StageTimes{};
    t.bounding_boxes = clock_.between_ms(frame_start, boxes_done);
    t.populate_grid = clock_.between_ms(boxes_done, grid_done);
    t.find_candidates = clock_.between_ms(grid_method() ? grid_done : boxes_done, candidates_done);
    t.sort_pairs = clock_.between_ms(narrow_phase_done, sorted);
    t.narrow_phase = clock_.between_ms(candidates_done, narrow_phase_done) + clock_.between_ms(sorted, results_done);
    t.total = clock_.between_ms(frame_start, frame_end);
    counts.host_waits = static_cast<std::uint32_t>(exec_.host_waits() - waits_before_);
    return no_vertex;
}

} // namespace kdet
