#pragma once
/// @file pipeline.hpp
/// @brief The per-frame pipeline, written once over an execution layer (CpuExec or CudaExec).
/// The host part only sizes buffers, reads back a few counters and decides when to grow and rerun.

#include "pipeline/pipeline_base.hpp"

#include <kdet/error.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace kdet {

/// @brief Frame-to-frame state kept on the host side of a pipeline.
struct FrameCounters {
    unsigned long long candidates;
    unsigned long long tests_run;
    unsigned long long rejected; ///< candidate pairs the face-plane pre-test proved separated
    unsigned long long exact_stage_pairs; ///< pairs that reached the exact stage of NarrowPhase::exact
    std::uint32_t grid_failure;
    std::uint32_t overflow_used;
    std::uint32_t layer_mask;
    std::uint32_t non_finite;
    std::uint32_t object_runs; ///< runs of tets of one object, i.e. non-empty objects
    std::uint32_t cells_claimed;
    std::uint32_t min_size; ///< float_to_ordered, over the relevant tets
    std::uint32_t max_size;
    unsigned long long layer_entries[max_grid_layers]; ///< cell entries the relevant tets need, per layer
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
        info_.resize_discard(tets);
        planes_.resize_discard(tets);
        colliding_.resize_discard(tets);
        user_colliding_.resize_discard(tets);
        user_flags_set_ = true; // new memory: unknown until cleared
        const std::size_t objects = topology.object_tet_begin.size() - 1;
        run_objects_.resize_discard(objects);
        run_boxes_.resize_discard(objects);
        object_boxes_.resize_discard(objects);
        // An empty object has no run of tets, so the reduction never writes its box: empty once here.
        const float inf = std::numeric_limits<float>::infinity();
        fill(object_boxes_, Aabb{{inf, inf, inf}, {-inf, -inf, -inf}});
        counters_.resize_discard(1);
        pair_active_.resize_discard(objects * objects);
    }

    void set_positions_on_device(std::uint32_t first, const vec3* positions, std::uint32_t count) override {
        // Checked where they are, before they replace anything: rejected positions never become current.
        reset_counters();
        exec_.for_each(count, FiniteCheckKernel{positions, &counters_.data()->non_finite});
        if (read_counters().non_finite) throw Error("positions given on the device hold a non-finite coordinate");
        exec_.copy(positions_.data() + first, positions, count);
    }

    void get_positions(std::uint32_t first, vec3* positions, std::uint32_t count) override {
        exec_.download(positions, positions_.data() + first, count);
    }

    DeviceResults device_results() override {
        return DeviceResults{out_keys_.data(), colliding_count_, user_colliding_.data(), user_colliding_.size(),
                             options_.contacts ? out_contacts_.data() : nullptr};
    }

    std::size_t memory_bytes() const override {
        return tets_.capacity_bytes() + tet_object_.capacity_bytes() + object_tet_begin_.capacity_bytes() +
               user_id_.capacity_bytes() + stored_id_.capacity_bytes() + positions_.capacity_bytes() +
               info_.capacity_bytes() + planes_.capacity_bytes() + colliding_.capacity_bytes() + user_colliding_.capacity_bytes() +
               run_objects_.capacity_bytes() + run_boxes_.capacity_bytes() + object_boxes_.capacity_bytes() + pair_active_.capacity_bytes() +
               headers_.capacity_bytes() + ids_.capacity_bytes() + counters_.capacity_bytes() +
               candidates_.capacity_bytes() + hit_.capacity_bytes() + position_.capacity_bytes() +
               out_keys_.capacity_bytes() + out_contacts_.capacity_bytes() +
               blocks_begin_.capacity_bytes() + block_objects_.capacity_bytes() + exec_.scratch_bytes();
    }

    std::string device_name() const override { return exec_.device_name(); }

    void detect(const std::vector<PositionUpload>& uploads, const std::vector<std::uint8_t>& pair_enabled,
                FrameResult& result) override;

private:
    SceneView scene_view() {
        return SceneView{positions_.data(), tets_.data(), tet_object_.data(), info_.data(), planes_.data(), pair_active_.data(),
                         object_boxes_.data(), static_cast<std::uint32_t>(tets_.size()),
                         static_cast<std::uint32_t>(object_boxes_.size())};
    }
    template <class T>
    void fill(buffer<T>& b, T value) {
        exec_.for_each(b.size(), FillKernel<T>{b.data(), value});
    }
    FrameCounters read_counters() {
        FrameCounters c;
        exec_.download(&c, counters_.data(), 1);
        return c;
    }
    void reset_counters() {
        const FrameCounters zero{};
        counters_.resize_discard(1);
        exec_.upload(counters_.data(), &zero, 1);
    }

    bool compute_bounds_and_culling(const std::vector<std::uint8_t>& pair_enabled);
    bool size_relevant_tets();
    void plan_grid();
    GridView populate(FrameCounts& counts);
    template <class Launch>
    FrameCounters append_candidates_growing(const Launch& launch, FrameCounts& counts);
    void find_candidates(const GridView& grid, FrameCounts& counts);
    void brute_force(FrameCounts& counts);
    std::size_t narrow_phase(std::size_t candidates, FrameCounts& counts);
    void contacts_and_pairs(std::size_t colliding, FrameResult& result);
    void count_and_copy_flags(bool any, FrameResult& result);
    KeyAppender candidate_appender() {
        return KeyAppender{candidates_.data(), candidates_.size(), &counters_.data()->candidates};
    }
    void ensure_candidate_capacity(std::size_t relevant_tets);

    /// Marks between the stages of a frame, for StageTimes.
    enum StageMark { frame_start, boxes_done, grid_done, candidates_done, narrow_phase_done, sorted, results_done, frame_end };

    Exec exec_;
    typename Exec::stage_clock clock_; // kept between frames: on the GPU it holds CUDA events, created once
    DetectorOptions options_;
    SceneTopology topology_;
    GridParams params_{};
    std::uint32_t stamp_ = 0;
    std::size_t relevant_estimate_ = 0;
    vec3 grid_origin_{};
    vec3 grid_extent_{}; ///< of the region that is gridded (the boxes of the objects that can collide)

    buffer<TetIndices> tets_;
    buffer<std::uint32_t> tet_object_;
    buffer<std::uint32_t> object_tet_begin_;
    buffer<std::uint32_t> user_id_;   ///< stored tet -> caller's global id
    buffer<std::uint32_t> stored_id_; ///< caller's global id -> stored tet
    buffer<vec3> positions_;
    buffer<TetInfo> info_;
    buffer<TetPlanes> planes_;
    buffer<std::uint32_t> colliding_;      ///< per stored tet
    buffer<std::uint32_t> user_colliding_; ///< per tet in the caller's numbering
    buffer<std::uint32_t> run_objects_; ///< per run of tets of one object (stage 1's reduction)
    buffer<Aabb> run_boxes_;
    buffer<Aabb> object_boxes_;
    buffer<std::uint8_t> pair_active_;
    buffer<BucketHeader> headers_;
    buffer<std::uint32_t> ids_;
    buffer<FrameCounters> counters_;
    buffer<std::uint64_t> candidates_;
    buffer<std::uint32_t> hit_;
    buffer<std::uint32_t> position_;
    buffer<std::uint64_t> out_keys_;
    buffer<Contact> out_contacts_;
    buffer<std::uint64_t> blocks_begin_;
    buffer<std::uint32_t> block_objects_;
    std::uint32_t slot_count_ = 0;
    std::uint32_t overflow_capacity_ = 0;
    std::uint32_t layer_mask_ = 0;
    std::size_t colliding_count_ = 0; ///< pairs in out_keys_ after the last detection
    bool user_flags_set_ = true;      ///< user_colliding_ may hold a nonzero flag
};

/// @brief Stage 1. Returns false when no enabled pair of objects can collide this frame.
template <class Exec>
bool Pipeline<Exec>::compute_bounds_and_culling(const std::vector<std::uint8_t>& pair_enabled) {
    const std::size_t objects = object_boxes_.size();
    const std::uint32_t tets = static_cast<std::uint32_t>(tets_.size());
    SceneView scene = scene_view();
    exec_.for_each(tets, TetBoundsKernel{scene});
    // Tets of one object are contiguous: their boxes reduce run by run, in parallel over all tets.
    std::uint32_t* runs = &counters_.data()->object_runs;
    exec_.reduce_runs(tet_object_.data(), TetBoxOf{info_.data()}, tets, BoxUnion{}, run_objects_.data(),
                      run_boxes_.data(), runs);
    exec_.for_each(objects, ObjectBoxesKernel{run_objects_.data(), run_boxes_.data(), runs, object_boxes_.data()});
    std::vector<Aabb> boxes(objects);
    exec_.download(boxes.data(), object_boxes_.data(), objects);

    // Object-level culling: a pair of objects is only checked when their boxes overlap.
    std::vector<std::uint8_t> active(objects * objects, 0);
    std::vector<bool> involved(objects, false);
    bool any = false;
    for (std::size_t a = 0; a < objects; ++a)
        for (std::size_t b = 0; b < objects; ++b) {
            const bool empty = topology_.object_tet_begin[a] == topology_.object_tet_begin[a + 1] ||
                               topology_.object_tet_begin[b] == topology_.object_tet_begin[b + 1];
            const bool on = !empty && pair_enabled[a * objects + b] && (a == b || boxes_overlap(boxes[a], boxes[b]));
            active[a * objects + b] = on ? 1 : 0;
            if (on) involved[a] = involved[b] = any = true;
        }
    exec_.upload(pair_active_.data(), active.data(), active.size());
    if (!any) return false;

    const float inf = std::numeric_limits<float>::infinity();
    grid_origin_ = vec3{inf, inf, inf};
    vec3 grid_top{-inf, -inf, -inf};
    relevant_estimate_ = 0;
    for (std::size_t o = 0; o < objects; ++o) {
        if (!involved[o]) continue;
        grid_origin_ = min_v(grid_origin_, boxes[o].lo);
        grid_top = max_v(grid_top, boxes[o].hi);
        relevant_estimate_ += topology_.object_tet_begin[o + 1] - topology_.object_tet_begin[o];
    }
    grid_extent_ = grid_top - grid_origin_;
    return true;
}

/// @brief Stage 1, grid methods only: sizes the relevant tets and picks the grid's geometry from
/// them. Returns false when no tet is relevant (the objects' boxes overlap, but no tet reaches
/// into the other object's box).
template <class Exec>
bool Pipeline<Exec>::size_relevant_tets() {
    FrameCounters start{};
    start.min_size = float_to_ordered(std::numeric_limits<float>::infinity());
    start.max_size = float_to_ordered(0.0f);
    counters_.resize_discard(1);
    exec_.upload(counters_.data(), &start, 1);
    FrameCounters* c = counters_.data();
    exec_.for_each(tets_.size(), TetSizeKernel{scene_view(), &c->min_size, &c->max_size});
    const FrameCounters sizes = read_counters();
    if (sizes.min_size == start.min_size) return false;

    // c0 is the smallest size among the gridded tets, so the smallest sit on layer 0; enough layers
    // to hold the largest, capped at max_grid_layers.
    const float dmin = ordered_to_float(sizes.min_size), dmax = ordered_to_float(sizes.max_size);
    // Zero-size tets (allowed only when the caller asked for degenerate input) must not make c0 zero.
    const float floor_size = std::max(dmax * 1e-6f, std::numeric_limits<float>::min() * 1e6f);
    const float c0 = std::max(dmin, floor_size);
    int layers = 1;
    while (layers < max_grid_layers && std::ldexp(c0, layers - 1) < dmax) ++layers;
    params_ = GridParams{grid_origin_, c0, 1.0f / c0, layers};
    return true;
}

/// @brief Stage 2: each relevant tet's layer, and a table large enough for the cells they need.
/// A cell holds at least one entry and lies in the gridded region, so per layer the occupied cells
/// are at most the entries and at most the region's cells; the table gets a quarter more slots than
/// that bound (probing stays short), and the overflow pool one bucket per bucket_capacity entries,
/// which holds every chain whatever the cells' fill. Both only grow, so a scene that keeps its size
/// sizes them once.
template <class Exec>
void Pipeline<Exec>::plan_grid() {
    reset_counters();
    FrameCounters* c = counters_.data();
    constexpr std::uint32_t chunk = 256;
    exec_.for_each((tets_.size() + chunk - 1) / chunk,
                   GridPlanKernel{scene_view(), params_, chunk, c->layer_entries, &c->layer_mask});
    const FrameCounters plan = read_counters();
    layer_mask_ = plan.layer_mask;

    double cells = 0.0, entries = 0.0;
    for (int layer = 0; layer < params_.layer_count; ++layer) {
        const double n = static_cast<double>(plan.layer_entries[layer]);
        if (n == 0.0) continue;
        const double cell = std::ldexp(static_cast<double>(params_.cell_size0), layer);
        double region = 1.0;
        for (int a = 0; a < 3; ++a) region *= std::floor(static_cast<double>(component(grid_extent_, a)) / cell) + 2.0;
        cells += std::min(n, region);
        entries += n;
    }
    const std::uint32_t capacity = std::max<std::uint32_t>(1, options_.bucket_capacity);
    std::uint32_t wanted_slots = 1024;
    while (wanted_slots < 1.25 * cells && wanted_slots < (1u << 30)) wanted_slots *= 2;
    const double wanted_pool = std::min(std::ceil(entries / capacity) + 1.0, static_cast<double>(1u << 30));
    slot_count_ = std::max(slot_count_, wanted_slots);
    overflow_capacity_ = std::max(overflow_capacity_, static_cast<std::uint32_t>(wanted_pool));
}

/// @brief Stage 2: fills the hash table; grows it and reruns when probing or the overflow pool fails.
template <class Exec>
GridView Pipeline<Exec>::populate(FrameCounts& counts) {
    plan_grid();
    const std::uint32_t capacity = std::max<std::uint32_t>(1, options_.bucket_capacity);
    for (;;) {
        const std::size_t buckets = static_cast<std::size_t>(slot_count_) + overflow_capacity_;
        if (headers_.size() != buckets) {
            headers_.resize_discard(buckets);
            ids_.resize_discard(buckets * capacity);
            fill(headers_, BucketHeader{}); // stamp 0 is never current, so this empties the table
            stamp_ = 0;
        }
        if (++stamp_ >= 0x7fffffffu) { // the stamp is about to wrap: clear once instead
            fill(headers_, BucketHeader{});
            stamp_ = 1;
        }
        reset_counters();
        FrameCounters* c = counters_.data();
        std::uint32_t slot_bits = 0;
        while ((1u << slot_bits) < slot_count_) ++slot_bits;
        GridView grid{headers_.data(), ids_.data(), &c->overflow_used, &c->grid_failure, &c->cells_claimed,
                      slot_count_, slot_bits, capacity, overflow_capacity_, stamp_, 64u, options_.hash};
        exec_.for_each(tets_.size(), PopulateKernel{scene_view(), grid, params_});
        const FrameCounters after = read_counters();
        if (!after.grid_failure) {
            counts.grid_cells = after.cells_claimed;
            counts.grid_slots = slot_count_;
            counts.grid_overflow_buckets = after.overflow_used;
            return grid;
        }
        if (after.grid_failure & grid_table_full) slot_count_ *= 2;
        if (after.grid_failure & grid_overflow_pool_full) overflow_capacity_ = std::max(overflow_capacity_ * 2, after.overflow_used);
        ++counts.buffer_regrows;
    }
}

template <class Exec>
void Pipeline<Exec>::ensure_candidate_capacity(std::size_t relevant_tets) {
    // Linear in the tets (thesis 7.3): k-freeness bounds the larger neighbours of each tet.
    const std::size_t estimate = options_.initial_candidate_capacity
                                     ? options_.initial_candidate_capacity
                                     : std::max<std::size_t>(4096, 16 * relevant_tets);
    if (candidates_.size() < estimate) candidates_.resize_discard(estimate);
}

/// @brief Runs a stage that appends to the candidate buffer until the buffer held everything: an
/// overflowing run still counts what it needed, so the buffer grows to that size and the stage reruns.
/// Returns the counters of the last run.
template <class Exec>
template <class Launch>
FrameCounters Pipeline<Exec>::append_candidates_growing(const Launch& launch, FrameCounts& counts) {
    for (;;) {
        reset_counters();
        launch(candidate_appender());
        const FrameCounters after = read_counters();
        counts.candidates = after.candidates;
        counts.exact_stage_pairs = after.exact_stage_pairs; // brute force tests while it appends
        if (after.candidates <= candidates_.size()) return after;
        candidates_.resize_discard(after.candidates + after.candidates / 4);
        ++counts.buffer_regrows;
    }
}

/// @brief Stage 3: candidate pairs, each written once.
template <class Exec>
void Pipeline<Exec>::find_candidates(const GridView& grid, FrameCounts& counts) {
    ensure_candidate_capacity(relevant_estimate_);
    const FrameCounters after = append_candidates_growing(
        [&](const KeyAppender& out) {
            exec_.for_each(tets_.size(), FindCandidatesKernel{scene_view(), grid, params_, layer_mask_, out,
                                                              &counters_.data()->rejected});
        },
        counts);
    counts.unique_candidates = counts.candidates;
    counts.candidates += after.rejected;
}

/// @brief Both brute-force methods: every pair of enabled objects is tested, colliding pairs appended.
template <class Exec>
void Pipeline<Exec>::brute_force(FrameCounts& counts) {
    const std::size_t objects = object_boxes_.size();
    std::vector<std::uint8_t> active(objects * objects);
    exec_.download(active.data(), pair_active_.data(), active.size());
    std::vector<std::uint64_t> block_begin{0};
    std::vector<std::uint32_t> block_objects;
    if (options_.method == Method::brute_force_pairs) {
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
    }
    if (candidates_.size() == 0) candidates_.resize_discard(4096);
    append_candidates_growing(
        [&](const KeyAppender& out) {
            if (options_.method == Method::brute_force_pairs)
                exec_.for_each(block_begin.back(),
                               BruteForcePairsKernel{scene_view(), options_.narrow_phase, object_tet_begin_.data(),
                                                     blocks_begin_.data(), block_objects_.data(),
                                                     static_cast<std::uint32_t>(block_objects.size() / 2), out,
                                                     &counters_.data()->exact_stage_pairs});
            else
                exec_.for_each(tets_.size(), BruteForceLoopKernel{scene_view(), options_.narrow_phase,
                                                                  object_tet_begin_.data(), out,
                                                                  &counters_.data()->exact_stage_pairs});
        },
        counts);
}

/// @brief Stage 5: the narrow phase once per candidate (they are unique, see LargerNeighbourFilter, so
/// they need no sorting); the colliding pairs are compacted and renamed to the caller's tet ids.
/// Returns their number.
template <class Exec>
std::size_t Pipeline<Exec>::narrow_phase(std::size_t candidates, FrameCounts& counts) {
    hit_.resize_discard(candidates);
    position_.resize_discard(candidates);
    const bool grid_method = options_.method == Method::kdet || options_.method == Method::kdet_no_pairs;
    const bool exact = options_.narrow_phase == NarrowPhase::exact;
    if (exact) reset_counters();
    exec_.for_each(candidates, NarrowPhaseKernel{scene_view(), options_.narrow_phase, grid_method, candidates_.data(),
                                                 hit_.data(), colliding_.data(), &counters_.data()->exact_stage_pairs});
    if (exact) counts.exact_stage_pairs = read_counters().exact_stage_pairs;
    const std::size_t colliding = exec_.exclusive_scan(hit_.data(), position_.data(), candidates);
    out_keys_.resize_discard(colliding);
    exec_.for_each(candidates, CompactKernel{candidates_.data(), hit_.data(), position_.data(), out_keys_.data()});
    exec_.for_each(colliding, UserPairKernel{user_id_.data(), out_keys_.data()});
    colliding_count_ = colliding;
    return colliding;
}

/// @brief Stage 6: contacts of the sorted colliding pairs, and the pairs copied out when results go
/// to the host.
template <class Exec>
void Pipeline<Exec>::contacts_and_pairs(std::size_t colliding, FrameResult& result) {
    if (options_.contacts) {
        out_contacts_.resize_discard(colliding);
        exec_.for_each(colliding, ContactKernel{scene_view(), stored_id_.data(), out_keys_.data(), out_contacts_.data()});
    }
    result.counts.colliding_pairs = colliding;
    if (!options_.results_to_host) return;
    std::vector<std::uint64_t> keys(colliding);
    exec_.download(keys.data(), out_keys_.data(), colliding);
    const auto& begin = topology_.object_tet_begin;
    auto locate = [&](std::uint32_t global, std::uint32_t& object, std::uint32_t& local) {
        object = static_cast<std::uint32_t>(std::upper_bound(begin.begin(), begin.end(), global) - begin.begin() - 1);
        local = global - begin[object];
    };
    result.pairs.resize(colliding);
    for (std::size_t k = 0; k < colliding; ++k) {
        TetPair& p = result.pairs[k];
        locate(key_first(keys[k]), p.object_a, p.tet_a);
        locate(key_second(keys[k]), p.object_b, p.tet_b);
    }
    result.contacts.resize(options_.contacts ? colliding : 0);
    if (options_.contacts) exec_.download(result.contacts.data(), out_contacts_.data(), colliding);
}

/// @brief Stage 6: the per-tet flags in the caller's numbering, counted (a scan of the 0/1 flags)
/// and, when results go to the host, copied. A frame where nothing can collide (`any` false) needs
/// no pass over the tets: its flags are all zero, and the backend's are cleared only if they were set.
template <class Exec>
void Pipeline<Exec>::count_and_copy_flags(bool any, FrameResult& result) {
    const std::size_t tets = tets_.size();
    const std::size_t objects = object_boxes_.size();
    result.colliding.resize(options_.results_to_host ? objects : 0);
    if (!any) {
        if (user_flags_set_) fill(user_colliding_, 0u);
        user_flags_set_ = false;
        result.counts.colliding_tets = 0;
        for (std::size_t o = 0; o < result.colliding.size(); ++o)
            result.colliding[o].assign(topology_.object_tet_begin[o + 1] - topology_.object_tet_begin[o], 0);
        return;
    }
    exec_.for_each(tets, UserFlagsKernel{stored_id_.data(), colliding_.data(), user_colliding_.data()});
    position_.resize_discard(tets);
    result.counts.colliding_tets = exec_.exclusive_scan(user_colliding_.data(), position_.data(), tets);
    user_flags_set_ = result.counts.colliding_tets > 0;
    if (!options_.results_to_host) return;
    std::vector<std::uint32_t> flags(tets);
    exec_.download(flags.data(), user_colliding_.data(), tets);
    for (std::size_t o = 0; o < objects; ++o) {
        const std::uint32_t b = topology_.object_tet_begin[o], e = topology_.object_tet_begin[o + 1];
        result.colliding[o].resize(e - b);
        for (std::uint32_t t = b; t < e; ++t) result.colliding[o][t - b] = flags[t] ? 1 : 0;
    }
}

template <class Exec>
void Pipeline<Exec>::detect(const std::vector<PositionUpload>& uploads, const std::vector<std::uint8_t>& pair_enabled,
                            FrameResult& result) {
    const std::uint64_t waits_before = exec_.host_waits();
    clock_.begin_frame();
    clock_.mark(frame_start);
    for (const PositionUpload& u : uploads) exec_.upload(positions_.data() + u.first, u.positions, u.count);
    result.pairs.clear();
    result.contacts.clear();
    result.counts = FrameCounts{};
    result.times = StageTimes{};
    FrameCounts& counts = result.counts;
    colliding_count_ = 0;

    const Method method = options_.method;
    const bool grid_method = method == Method::kdet || method == Method::kdet_no_pairs;
    const bool any =
        tets_.size() > 0 && compute_bounds_and_culling(pair_enabled) && (!grid_method || size_relevant_tets());
    if (any) fill(colliding_, 0u);
    clock_.mark(boxes_done);

    if (any) {
        if (grid_method) {
            const GridView grid = populate(counts);
            clock_.mark(grid_done);
            if (method == Method::kdet) {
                find_candidates(grid, counts);
            } else {
                reset_counters();
                exec_.for_each(tets_.size(), NoPairsKernel{scene_view(), grid, params_, layer_mask_,
                                                           options_.narrow_phase, colliding_.data(),
                                                           &counters_.data()->tests_run,
                                                           &counters_.data()->exact_stage_pairs});
                const FrameCounters after = read_counters();
                counts.candidates = counts.unique_candidates = after.tests_run;
                counts.exact_stage_pairs = after.exact_stage_pairs;
            }
        } else {
            brute_force(counts);
        }
        clock_.mark(candidates_done);
        if (method != Method::kdet_no_pairs) {
            if (!grid_method) counts.unique_candidates = counts.candidates;
            const std::size_t colliding = narrow_phase(counts.unique_candidates, counts);
            clock_.mark(narrow_phase_done);
            // The deterministic output order; the keys hold the caller's ids, which are below the tet count.
            exec_.sort(out_keys_.data(), colliding, pair_key_bits(static_cast<std::uint32_t>(tets_.size())));
            clock_.mark(sorted);
            contacts_and_pairs(colliding, result);
            clock_.mark(results_done);
        }
    }

    count_and_copy_flags(any, result);
    result.memory_bytes = memory_bytes();
    result.grid_bytes = headers_.capacity_bytes() + ids_.capacity_bytes();
    result.candidate_bytes = candidates_.capacity_bytes();
    clock_.mark(frame_end);
    clock_.wait(frame_end);
    StageTimes& t = result.times;
    t.bounding_boxes = clock_.between_ms(frame_start, boxes_done);
    t.populate_grid = clock_.between_ms(boxes_done, grid_done);
    t.find_candidates = clock_.between_ms(grid_method ? grid_done : boxes_done, candidates_done);
    t.sort_unique = clock_.between_ms(narrow_phase_done, sorted);
    t.narrow_phase = clock_.between_ms(candidates_done, narrow_phase_done) + clock_.between_ms(sorted, results_done);
    t.total = clock_.between_ms(frame_start, frame_end);
    counts.host_waits = static_cast<std::uint32_t>(exec_.host_waits() - waits_before);
}

} // namespace kdet
