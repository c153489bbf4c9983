#pragma once
/// @file pipeline_stages.hpp
/// @brief Pipeline's drivers of kdet's stages: bounding boxes, the grid's geometry, sizing and
/// populating, the candidate search and the narrow phase with its results.

#include "pipeline/capacity.hpp"
#include "pipeline/pipeline_class.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>

namespace kdet {

/// @brief Stage 1: tet boxes, object boxes, and which pairs of objects are checked (pair_active_),
/// all in the backend's memory.
template <class Exec>
void Pipeline<Exec>::bounds_and_culling() {
    const std::size_t objects = object_boxes_.size();
    const std::uint32_t tets = frame_tets_;
    FrameCounters* c = counters_.data();
    exec_.for_each(tets, TetBoundsKernel{scene_view()});
    // Tets of one object are contiguous: their boxes reduce run by run, in parallel over all tets.
    exec_.reduce_runs(tet_object_.data(), TetBoxOf{info_.data()}, tets, BoxUnion{}, run_objects_.data(),
                      run_boxes_.data(), &c->object_runs);
    exec_.for_each(objects, ObjectBoxesKernel{run_objects_.data(), run_boxes_.data(), &c->object_runs,
                                              object_boxes_.data()});
    exec_.for_each(objects, ObjectCullingKernel{pair_enabled_.data(), pair_active_.data(), checked_objects_.data(), object_boxes_.data(),
                                                meeting_boxes_.data(), object_tet_begin_.data(), static_cast<std::uint32_t>(objects),
                                                &c->region, &c->involved_tets});
}

/// @brief Stage 1, grid methods only: sizes the relevant tets, picks the grid's geometry from them
/// and each relevant tet's layer, and counts the cells they need per layer (the plan).
template <class Exec>
void Pipeline<Exec>::grid_geometry() {
    FrameCounters* c = counters_.data();
    exec_.for_each(frame_tets_, TetSizeKernel{scene_view(), &c->min_size, &c->max_size, &c->min_upper_size, &c->max_lower_size,
                                                 c->spacing_octaves});
    exec_.for_each(1, GridParamsKernel{&c->min_size, &c->max_size, c->spacing_octaves, &c->region, &c->params,
                                       Tuning::grid_cell_spacings});
    constexpr std::uint32_t chunk = Tuning::plan_chunk;
    exec_.for_each((frame_tets_ + chunk - 1) / chunk,
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
    exec_.for_each_in_runs(frame_tets_, PopulateKernel<TableCells>{TableCells{scene_view(), grid, &c->params}});
    exec_.for_each(slot_count_, GatherCellsKernel{scene_view(), grid});
    exec_.sort_lists(list_keys_.data(), sorted_keys_.data(), entry_capacity_, list_begin_.data(), list_end_.data(), slot_count_);
    exec_.for_each(entry_capacity_, PlaceEntriesKernel{scene_view(), grid, sorted_keys_.data()});
    exec_.for_each(blocks, BoundEntryBlocksKernel{grid});
    return grid;
}

/// @brief Stage 3 (kdet): candidate pairs, each written once. A frame that reads its counters back
/// here (a first frame, to size the pairs' window) does not rerun when the buffer overflows: the search
/// items (tets, or parts of their searches: SearchPart) that did not fit stopped when they did not, so
/// they search once more storing nothing, only counting the keys they still need; then the buffer
/// grows once to that need, keeping what was stored, and only they search again, each resuming after
/// the keys it had stored. There is room to resume one item per tet; when more stop (a first buffer
/// far too small for a split search), every item counts and then searches again into the grown
/// buffer. A need that the memory (or memory_limit) cannot hold, with room for as many colliding
/// pairs, throws at once, before the search stores it; before the count, where a lower bound on the
/// candidates (candidate_bound.hpp) is already more than that. Later frames read nothing here; an overflow
/// shows in the frame's counters, which count past the buffer's end, and the frame reruns (grow_for).
/// Returns the counters when it read them.
template <class Exec>
std::optional<FrameCounters> Pipeline<Exec>::find_candidates(const GridView& grid) {
    // Items are numbered in 32 bits (ResumePoint): a scene too large for that searches its tets whole.
    const std::uint32_t layer_parts_wanted = Tuning::search_layer_parts(self_collision_, frame_tets_);
    const std::uint32_t block_parts_wanted = Tuning::search_block_parts(self_collision_, frame_tets_);
    const bool split = std::size_t{frame_tets_} * layer_parts_wanted * block_parts_wanted <= 0xffffffffu;
    const std::uint32_t layer_parts = split ? layer_parts_wanted : 1u;
    const std::uint32_t block_parts = split ? block_parts_wanted : 1u;
    const std::size_t parts = std::size_t{layer_parts} * block_parts;
    constexpr std::uint32_t tets_per_item = Tuning::search_tets_per_item;
    using Search = FindCandidatesKernel<tets_per_item, Tuning::face_planes_in_search>;
    const std::size_t runs = TetRuns<tets_per_item>::count(frame_tets_);
    const std::size_t all_items = runs * parts, resume_room = frame_tets_;
    for (auto& points : resume_points_) points.resize_discard(resume_room);
    // `items` items (resuming where `from` says, or from their start) append to `out`, counting into
    // `into`; those that do not fit are recorded in `stopped`, while there is `stopped_room`.
    const auto search = [&](std::size_t items, const ResumePoint* from, const KeyAppender& out, FrameCounters* into,
                            ResumePoint* stopped, std::size_t stopped_room, bool stop_when_full) {
        FrameCounters* c = counters_.data();
        exec_.for_each(items, Search{scene_view(), grid, &c->params, &c->layer_mask, out, &into->rejected, from, stopped,
                                     &into->stopped_items, static_cast<std::uint32_t>(stopped_room), layer_parts,
                                     block_parts, stop_when_full, statics_.search},
                       tets_per_item);
    };
    std::size_t items = all_items;
    const ResumePoint* resume_from = nullptr;
    bool stop_when_full = !pairs_sized_;
    for (int run = 0;; ++run) {
        FrameCounters* c = counters_.data();
        ResumePoint* stopped = resume_points_[run % 2].data();
        search(items, resume_from, KeyAppender{candidates_.data(), candidates_.size(), &c->candidates, &c->candidate_padding},
               c, stopped, resume_room, stop_when_full);
        if (pairs_sized_) return std::nullopt;
        FrameCounters after = read_counters_now();
        if (!after.stopped_items) return after;
        if (run == 0) refuse_beyond_candidate_bound(grid, after.cells_claimed);
        // The count: the items to search again, into a buffer of no room, on counters of their own.
        const bool resume = after.stopped_items <= resume_room;
        items = resume ? after.stopped_items : all_items;
        resume_from = resume ? stopped : nullptr;
        FrameCounters* count = counters_.data() + 1;
        const FrameCounters zero{};
        exec_.upload(count, &zero, 1);
        search(items, resume_from, KeyAppender{candidates_.data(), 0, &count->candidates, nullptr}, count, nullptr, 0, false);
        FrameCounters counted;
        exec_.download(&counted, count, 1);
        const std::size_t kept = candidates_.size();
        const std::uint64_t keys = (resume ? kept - after.candidate_padding : 0) + counted.candidates;
        reserve_pairs_window(keys);
        // Items that stopped at a buffer filled to its last slot (or of no room at all) may have nothing
        // left to store: growing would leave it as it is and stop them again, so they run once more
        // without stopping, into the buffer as it is.
        const bool nothing_left = counted.candidates == 0;
        stop_when_full = !nothing_left;
        bool copied = false;
        if (!nothing_left) {
            // Room for the next frames too where the memory allows (their overflow would rerun the
            // whole frame); where it does not hold the kept keys and the grown buffer at once, every
            // item searches again into a buffer of the keys alone.
            const std::size_t slots = (resume ? kept : 0) + counted.candidates;
            copied = resume && resize_within_memory(candidates_grown_, rerun_capacity(kept, slots), slots,
                                                    room(candidates_grown_.capacity_bytes(), sizeof(std::uint64_t)));
            if (copied) exec_.copy(candidates_grown_.data(), candidates_.data(), kept);
            candidates_.swap(candidates_grown_);
            buffer<std::uint64_t>().swap(candidates_grown_); // frees the old buffer
            if (!copied && !resize_within_memory(candidates_, keys + keys / 4, keys,
                                                 room(candidates_.capacity_bytes(), sizeof(std::uint64_t))))
                refuse_first_frame(keys);
            ++regrows_;
        }
        if (copied || (nothing_left && resume)) {
            after.candidates = kept;
        } else {
            after.candidates = after.candidate_padding = after.rejected = 0;
            items = all_items;
            resume_from = nullptr;
        }
        after.stopped_items = 0;
        exec_.upload(counters_.data(), &after, 1);
    }
}

/// @brief Stages 5 and 6: the narrow phase once per candidate (they are unique, see
/// for_each_larger_neighbour), over the count the candidate stage left in the backend's memory; the
/// colliding pairs, appended under the caller's ids into the window, sorted into the output order,
/// and their contacts and distances. With a margin, the candidates found apart are then decided
/// against it (NearPairsKernel), their pairs appended to the same window.
template <class Exec>
void Pipeline<Exec>::narrow_phase_and_results() {
    FrameCounters* c = counters_.data();
    const bool margin = options_.margin > 0.0f;
    if (margin && near_.size() != candidates_.size() &&
        !resize_within_memory(near_, candidates_.size(), candidates_.size(), room(near_.capacity_bytes(), sizeof(std::uint64_t))))
        refuse_frame("the margin's list of " + std::to_string(candidates_.size()) + " candidate pairs takes",
                     candidates_.size() * sizeof(std::uint64_t));
    // The whole window is copied out (the count is not known when the copy is enqueued): a new one is
    // filled once, so that no byte copied is undefined.
    resize_filled(out_keys_, pairs_window_, no_pair_key);
    const KeyAppender out{out_keys_.data(), out_keys_.size(), &c->colliding_pairs, nullptr};
    with_narrow_phase(options_.narrow_phase, [&](auto test) {
        constexpr std::uint32_t per_item = Tuning::keys_per_appending_item;
        const auto decide = [&](auto planes_here) {
            exec_.for_each_counted(&c->candidates, candidates_.size(),
                                   NarrowPhaseKernel<decltype(test)::value, per_item, decltype(planes_here)::value>{
                                       scene_view(), candidates_.data(), &c->candidates, candidates_.size(), colliding_.data(),
                                       user_id_.data(), out, &c->exact_stage_pairs, &c->rejected_after_search,
                                       margin ? near_.data() : nullptr},
                                   per_item);
        };
        // The search's candidates still need their face planes where it did not run them; brute force's
        // pairs need none (and have no planes).
        if constexpr (!Tuning::face_planes_in_search) {
            if (candidates_pretested()) return decide(std::true_type{});
        }
        decide(std::false_type{});
    });
    if (margin)
        exec_.for_each_counted(&c->candidates, near_.size(),
                               NearPairsKernel{scene_view(), near_.data(), colliding_.data(), user_id_.data(), out});
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
    if (options_.distances) {
        resize_filled(out_distances_, pairs_window_, 0.0f);
        resize_filled(out_closest_, pairs_window_, ClosestPoints{});
        exec_.for_each_counted(&c->colliding_pairs, out_distances_.size(),
                               DistanceKernel{scene_view(), stored_id_.data(), out_keys_.data(), &c->colliding_pairs,
                                              out_keys_.size(), out_distances_.data(), out_closest_.data()});
    }
    clock_.mark(results_done);
}

} // namespace kdet
