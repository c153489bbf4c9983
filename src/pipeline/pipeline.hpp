#pragma once
/// @file pipeline.hpp
/// @brief The control of Pipeline's frames: a frame enqueued whole, finished with one wait, and run
/// again from the stage whose buffer was too small. Include this header for a whole Pipeline<Exec>.

#include "pipeline/capacity.hpp"
#include "pipeline/pipeline_stages.hpp"
#include "pipeline/static_placing.hpp"

#include <kdet/error.hpp>

#include <algorithm>
#include <new>
#include <optional>

namespace kdet {

/// @brief Enqueues one attempt at the frame, down to the copies of its counters and results. Only a
/// first frame reads anything before the end: the grid's plan, to size the table (so that one-off
/// queries grow nothing), and the candidate count, to size the window for the colliding pairs.
template <class Exec>
void Pipeline<Exec>::enqueue_frame() {
    reset_counters();
    adopt_staged_positions();
    if (frame_tets_ < tets_.size() && !statics_.placed) place_static();
    fill(colliding_, 0u);
    bounds_and_culling();
    if (grids()) grid_geometry();
    clock_.mark(boxes_done);
    if (grids() && !grid_planned_) {
        const FrameCounters plan = read_counters_now();
        size_grid(plan);
        // Linear in the tets (thesis 7.3): k-freeness bounds the larger neighbours of each tet.
        const std::size_t estimate = options_.initial_candidate_capacity
                                         ? options_.initial_candidate_capacity
                                         : std::max<std::size_t>(4096, 16 * plan.involved_tets);
        // A guess: where the memory (or memory_limit) does not hold it, the search starts from less,
        // down to nothing, and the buffer grows to what the search counts (find_candidates).
        if (candidates_.size() < estimate)
            resize_within_memory(candidates_, estimate, 0, room(candidates_.capacity_bytes(), sizeof(std::uint64_t)));
        grid_planned_ = true;
    }
    enqueue_from(Rerun::grid);
}

/// @brief The stages of an attempt from `stage` on (grid: populating, candidates: the candidate
/// stage, results: the narrow phase and after), once those before it have run.
template <class Exec>
void Pipeline<Exec>::enqueue_from(Rerun stage) {
    if (stage == Rerun::grid && grids()) {
        grid_ = populate();
        clock_.mark(grid_done);
    }
    if (stage != Rerun::results) {
        // The counters after the candidate stage, when it read them back.
        std::optional<FrameCounters> found = candidate_stage();
        clock_.mark(candidates_done);
        if (makes_pairs() && !pairs_sized_) {
            if (!found) found = read_counters_now();
            // A grid that did not fill has left candidates to find again: its rerun counts them as a
            // first frame does, so that a need the memory cannot hold still fails before it is stored.
            if (!found->grid_failure) {
                reserve_pairs_window(std::min<std::size_t>(found->candidates - found->candidate_padding, candidates_.size()));
                pairs_sized_ = true;
            }
        }
    }
    enqueue_results();
}

/// @brief The end of a frame's attempt, from the candidates on: the narrow phase and the colliding
/// pairs (where the frame makes pairs), the per-tet flags, and the copies of the counters and results.
template <class Exec>
void Pipeline<Exec>::enqueue_results() {
    FrameCounters* c = counters_.data();
    if (makes_pairs()) narrow_phase_and_results();

    const std::size_t tets = tets_.size();
    exec_.for_each(tets, UserFlagsKernel{stored_id_.data(), colliding_.data(), user_colliding_.data()});
    exec_.sum(user_colliding_.data(), tets, &c->colliding_tets);

    exec_.download_later(&last_, counters_.data(), 1);
    if (!options_.results_to_host) return;
    // The whole window: the count is not known when the copy is enqueued.
    const std::size_t window = makes_pairs() ? pairs_window_ : 0;
    keys_view_ = exec_.download_view_later(out_keys_.data(), window);
    flags_view_ = exec_.download_view_later(user_colliding_.data(), tets);
    contacts_view_ = exec_.download_view_later(out_contacts_.data(), options_.contacts ? window : 0);
    distances_view_ = exec_.download_view_later(out_distances_.data(), options_.distances ? window : 0);
    closest_view_ = exec_.download_view_later(out_closest_.data(), options_.distances ? window : 0);
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
        kept.rejected = 0;
        kept.stopped_items = 0;
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
    if (grids() && c.params.layer_count > 0) {
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
        // The search counted every key, past the buffer's end: the need is known before anything grows.
        if (!grow_for_rerun(candidates_, c.candidates, room(candidates_.capacity_bytes(), sizeof(std::uint64_t))))
            refuse_frame("the frame has " + std::to_string(c.candidates - c.candidate_padding) + " candidate pairs, which take",
                         c.candidates * sizeof(std::uint64_t));
        candidates_again = true;
    }
    bool pairs_again = false;
    if (makes_pairs()) {
        if (candidates_again) {
            // The rerun decides every candidate again: the window grows with them, in it (where the
            // memory allows; else a rerun of its own grows it to what it needs).
            const std::size_t held = pairs_window_;
            if (!pairs_window_within_memory(pairs_window_for_candidates(held, candidates_fitted, candidates_.size()), held))
                refuse_frame("the frame's window of " + std::to_string(held) + " colliding pairs takes", held * pair_bytes());
        } else if (c.colliding_pairs > pairs_window_) {
            if (!pairs_window_within_memory(rerun_capacity(pairs_window_, c.colliding_pairs), c.colliding_pairs))
                refuse_frame("the frame has " + std::to_string(c.colliding_pairs) + " colliding pairs, which take",
                             c.colliding_pairs * pair_bytes());
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

/// @brief Makes the pairs' window hold `wanted` pairs, or, where the memory (or memory_limit) does not
/// allow it, the `needed` pairs alone (resize_within_memory for every buffer that holds it), and sets
/// pairs_window_; false when not even the need fits. The sort's spare keys for the window are held
/// with it (Exec::reserve_sort), so that a window the memory cannot sort fails here too.
template <class Exec>
bool Pipeline<Exec>::pairs_window_within_memory(std::size_t wanted, std::size_t needed) {
    const std::size_t own = out_keys_.capacity_bytes() + out_contacts_.capacity_bytes() + out_distances_.capacity_bytes() +
                            out_closest_.capacity_bytes() + exec_.sort_spare_bytes();
    const std::size_t pairs_room = room(own, pair_bytes());
    if (!resize_within_memory(out_keys_, wanted, needed, pairs_room)) return false;
    std::size_t window = out_keys_.size();
    const auto narrow_to = [&](auto& per_pair) {
        if (!resize_within_memory(per_pair, window, needed, pairs_room)) return false;
        window = per_pair.size();
        return true;
    };
    if (options_.contacts && !narrow_to(out_contacts_)) return false;
    if (options_.distances && !(narrow_to(out_distances_) && narrow_to(out_closest_))) return false;
    if (!exec_.reserve_sort(window)) {
        window = needed; // the headroom goes first
        if (!exec_.reserve_sort(window)) return false;
    }
    pairs_window_ = window;
    return true;
}

/// @brief A first frame's window for its colliding pairs, which are at most its `candidates`: room for
/// all of them, filled once (every byte of it is copied out), or the frame is refused before the
/// narrow phase runs. find_candidates reserves it as soon as it has counted a candidate buffer's
/// overflow, before the search stores them (`at_least`: a lower bound on them, refuse_first_frame).
template <class Exec>
void Pipeline<Exec>::reserve_pairs_window(std::uint64_t candidates, bool at_least) {
    if (candidates <= pairs_window_) return;
    if (!pairs_window_within_memory(candidates, candidates)) refuse_first_frame(candidates, at_least);
    fill(out_keys_, no_pair_key);
    if (options_.contacts) fill(out_contacts_, Contact{});
    if (options_.distances) {
        fill(out_distances_, 0.0f);
        fill(out_closest_, ClosestPoints{});
    }
}

/// @brief A first frame whose candidate buffer overflowed: refuses it at once (refuse_first_frame) where
/// its candidates' lower bound (candidate_lower_bound, over the grid's `cells` lists) with room for as
/// many colliding pairs already exceeds memory_limit beside what does not grow with the pairs, or the
/// pairs' window for them cannot be allocated. Else the window is reserved for them (it holds at least
/// that many anyway) and the frame counts its candidates.
template <class Exec>
void Pipeline<Exec>::refuse_beyond_candidate_bound(const GridView& grid, std::uint32_t cells) {
    const std::uint64_t least = candidate_lower_bound(exec_, scene_view(), grid, cells,
                                                      static_cast<std::uint32_t>(tets_.size()), positions_.size());
    const std::size_t grows_with_pairs = candidates_.capacity_bytes() + candidates_grown_.capacity_bytes() +
                                         out_keys_.capacity_bytes() + out_contacts_.capacity_bytes() +
                                         out_distances_.capacity_bytes() + out_closest_.capacity_bytes() +
                                         exec_.sort_spare_bytes();
    if (least > room(grows_with_pairs, sizeof(std::uint64_t) + pair_bytes())) refuse_first_frame(least, true);
    reserve_pairs_window(least, true);
}

/// @brief Ends a frame whose pairs the memory (or memory_limit) cannot hold, before anything grows for
/// them: frees the buffers that grow with the pairs (the detector keeps no room for a frame it
/// refused; the next frame grows them again) and throws kdet::Error naming `need` and its `bytes`.
template <class Exec>
void Pipeline<Exec>::refuse_frame(const std::string& need, std::uint64_t bytes) {
    buffer<std::uint64_t>().swap(candidates_);
    buffer<std::uint64_t>().swap(candidates_grown_);
    buffer<std::uint64_t>().swap(near_);
    buffer<std::uint64_t>().swap(out_keys_);
    buffer<Contact>().swap(out_contacts_);
    buffer<float>().swap(out_distances_);
    buffer<ClosestPoints>().swap(out_closest_);
    exec_.release_sort();
    pairs_window_ = 0;
    colliding_count_ = 0;
    throw_frame_too_large(need, bytes, memory_bytes(), options_.memory_limit);
}

/// @brief refuse_frame for a first frame of `candidates` candidate pairs (at least that many where
/// `at_least`: a lower bound), which needs room for them and for as many colliding pairs.
template <class Exec>
void Pipeline<Exec>::refuse_first_frame(std::uint64_t candidates, bool at_least) {
    refuse_frame("the frame has " + std::string(at_least ? "at least " : "") + std::to_string(candidates) +
                     " candidate pairs; with room for all of them to collide, as a first frame keeps, they take",
                 candidates * (sizeof(std::uint64_t) + pair_bytes()));
}

template <class Exec>
void Pipeline<Exec>::start(const std::vector<PositionUpload>& uploads, const std::vector<VertexRange>& staged,
                           std::vector<std::uint8_t> pair_enabled) {
    staged_ = staged;
    waits_before_ = exec_.host_waits();
    regrows_ = 0;
    clock_.begin_frame();
    clock_.mark(frame_start);
    for (const PositionUpload& u : uploads) exec_.upload(positions_.data() + u.first, u.positions, u.count);
    // Two static objects (or one with itself) are never checked: their pairs cannot change.
    std::vector<std::uint8_t>& enabled = pair_enabled;
    const std::size_t objects = object_boxes_.size();
    for (std::size_t a = 0; a < objects; ++a)
        for (std::size_t b = 0; b < objects; ++b)
            if (topology_.object_static[a] && topology_.object_static[b]) enabled[a * objects + b] = 0;
    exec_.upload(pair_enabled_.data(), enabled.data(), enabled.size());
    self_collision_ = false;
    for (std::size_t o = 0; o < objects; ++o) self_collision_ |= enabled[o * objects + o] != 0;
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
    colliding_count_ = makes_pairs() ? c.colliding_pairs : 0;

    result.pairs.clear();
    result.contacts.clear();
    result.distances.clear();
    result.closest_points.clear();
    result.counts = FrameCounts{};
    FrameCounts& counts = result.counts;
    count_candidates(c, counts);
    counts.exact_stage_pairs = c.exact_stage_pairs;
    counts.colliding_pairs = colliding_count_;
    counts.colliding_tets = c.colliding_tets;
    counts.buffer_regrows = regrows_;
    if (grids() && c.params.layer_count > 0) {
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
        try {
            result.pairs.resize(colliding_count_);
        } catch (const std::bad_alloc&) {
            refuse_frame("the frame has " + std::to_string(colliding_count_) + " colliding pairs, whose copy for the caller takes",
                         colliding_count_ * sizeof(TetPair));
        }
        pairs_from_keys(begin, keys, colliding_count_, result.pairs.data(), options_.threads);
        if (options_.contacts) result.contacts.assign(contacts, contacts + colliding_count_);
        if (options_.distances) {
            const float* distances = exec_.template landed<float>(distances_view_);
            const ClosestPoints* closest = exec_.template landed<ClosestPoints>(closest_view_);
            result.distances.assign(distances, distances + colliding_count_);
            result.closest_points.assign(closest, closest + colliding_count_);
        }
        flags_by_object(begin, flags, result.colliding, options_.threads);
    }
    result.memory_bytes = memory_bytes();
    result.grid_bytes = grid_bytes();
    result.candidate_bytes = candidates_.capacity_bytes();
    StageTimes& t = result.times;
    t = StageTimes{};
    t.bounding_boxes = clock_.between_ms(frame_start, boxes_done);
    t.populate_grid = clock_.between_ms(boxes_done, grid_done);
    t.find_candidates = clock_.between_ms(grids() ? grid_done : boxes_done, candidates_done);
    t.sort_pairs = clock_.between_ms(narrow_phase_done, sorted);
    t.narrow_phase = clock_.between_ms(candidates_done, narrow_phase_done) + clock_.between_ms(sorted, results_done);
    t.total = clock_.between_ms(frame_start, frame_end);
    counts.host_waits = static_cast<std::uint32_t>(exec_.host_waits() - waits_before_);
    return no_vertex;
}

} // namespace kdet
