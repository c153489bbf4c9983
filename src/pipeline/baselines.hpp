#pragma once
/// @file baselines.hpp
/// @brief The thesis's baselines, kept beside the production pipeline to compare kdet with: kdet's
/// frame (Pipeline) with a candidate stage of their own. Method::kdet_no_pairs grids the tets as kdet
/// does and only flags the colliding tets (the thesis's old method); brute_force_loop and
/// brute_force_pairs test every pair of tets of the objects checked against each other, and the
/// narrow phase tests their colliding pairs again, as it does kdet's candidates.

#include "pipeline/baseline_kernels.hpp"
#include "pipeline/pipeline.hpp"

#include <kdet/options.hpp>
#include <kdet/results.hpp>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace kdet {

/// @brief What a baseline's candidate stage counts, apart from the frame's counters.
struct BaselineCounters {
    unsigned long long tests_run; ///< kdet_no_pairs: the pairs it tested, its count of candidates
    /// Brute force's own count of the pairs that reached the exact stage; the narrow phase tests its
    /// colliding pairs again, and that count (FrameCounters::exact_stage_pairs) is the one reported, as
    /// for the other methods.
    unsigned long long brute_force_exact_stage;
};

/// @brief A frame of one of the thesis's baselines (any Method but kdet).
template <class Exec>
class BaselinePipeline final : public Pipeline<Exec> {
    using Base = Pipeline<Exec>;
    using typename Base::Tuning;
    template <class T>
    using buffer = typename Exec::template buffer<T>;

public:
    using Base::Base;

    void set_topology(const SceneTopology& topology) override {
        Base::set_topology(topology);
        baseline_counters_.resize_discard(1);
    }

    std::size_t memory_bytes() const override {
        return Base::memory_bytes() + baseline_counters_.capacity_bytes() + blocks_begin_.capacity_bytes() +
               block_objects_.capacity_bytes();
    }

private:
    bool no_pairs() const { return this->options_.method == Method::kdet_no_pairs; }
    bool keeps_static_grid() const override { return false; }
    bool grids() const override { return no_pairs(); }
    bool makes_pairs() const override { return !no_pairs(); }
    bool candidates_pretested() const override { return false; }
    std::optional<FrameCounters> candidate_stage() override;
    void count_candidates(const FrameCounters& c, FrameCounts& counts) const override {
        if (!no_pairs()) return Base::count_candidates(c, counts);
        counts.candidates = counts.narrow_phase_candidates = baseline_last_.tests_run;
    }

    void flag_colliding_tets();
    void brute_force();

    buffer<BaselineCounters> baseline_counters_;
    BaselineCounters baseline_last_{}; ///< baseline_counters_ as the last attempt at a frame left them
    buffer<std::uint64_t> blocks_begin_;   ///< brute_force_pairs: the work offsets of its blocks
    buffer<std::uint32_t> block_objects_;  ///< and the pair of objects of each
};

/// @brief Runs at every attempt at a frame that reaches stage 3; its counters land with the frame's.
template <class Exec>
std::optional<FrameCounters> BaselinePipeline<Exec>::candidate_stage() {
    this->fill(baseline_counters_, BaselineCounters{});
    if (no_pairs()) {
        flag_colliding_tets();
    } else {
        auto& candidates = this->candidates_;
        const DetectorOptions& options = this->options_;
        if (candidates.size() == 0)
            candidates.resize_discard(options.initial_candidate_capacity ? options.initial_candidate_capacity : 4096);
        brute_force();
    }
    this->exec_.download_later(&baseline_last_, baseline_counters_.data(), 1);
    return std::nullopt;
}

/// @brief kdet_no_pairs: the grid's search of each tet, testing the pairs inline and flagging the
/// colliding tets (NoPairsKernel). With a margin the pairs it found apart go to the candidate buffer,
/// which it does not use otherwise (it grows like kdet's when they overflow it), and
/// NearPairsKernel flags the tets of those within the margin.
template <class Exec>
void BaselinePipeline<Exec>::flag_colliding_tets() {
    FrameCounters* c = this->counters_.data();
    const std::uint32_t tets = static_cast<std::uint32_t>(this->tets_.size());
    auto& near = this->candidates_;
    const KeyAppender near_out{near.data(), near.size(), &c->candidates, nullptr};
    with_narrow_phase(this->options_.narrow_phase, [&](auto test) {
        using Search = NoPairsKernel<decltype(test)::value, Tuning::search_tets_per_item>;
        this->exec_.for_each(TetRuns<Tuning::search_tets_per_item>::count(tets),
                             Search{this->scene_view(), this->grid_, &c->params, &c->layer_mask, this->colliding_.data(),
                                    &baseline_counters_.data()->tests_run, &c->exact_stage_pairs, near_out},
                             Tuning::search_tets_per_item);
    });
    if (this->options_.margin > 0.0f)
        this->exec_.for_each_counted(&c->candidates, near.size(),
                                     NearPairsKernel{this->scene_view(), near.data(), this->colliding_.data(), nullptr, KeyAppender{}});
}

/// @brief Both brute-force methods: every pair of enabled objects is tested, colliding pairs appended.
/// brute_force_pairs lays its work out per pair of objects on the host, so it reads pair_active_ (one
/// wait more per frame).
template <class Exec>
void BaselinePipeline<Exec>::brute_force() {
    FrameCounters* c = this->counters_.data();
    auto& exec = this->exec_;
    const KeyAppender out{this->candidates_.data(), this->candidates_.size(), &c->candidates, &c->candidate_padding};
    unsigned long long* exact_stage = &baseline_counters_.data()->brute_force_exact_stage;
    const SceneView scene = this->scene_view();
    const std::uint32_t* object_tet_begin = this->object_tet_begin_.data();
    if (this->options_.method == Method::brute_force_loop) {
        with_narrow_phase(this->options_.narrow_phase, [&](auto test) {
            exec.for_each(this->tets_.size(), BruteForceLoopKernel<decltype(test)::value>{scene, object_tet_begin, out, exact_stage});
        });
        return;
    }
    const std::size_t objects = this->object_boxes_.size();
    std::vector<std::uint8_t> active(objects * objects);
    exec.download(active.data(), this->pair_active_.data(), active.size());
    std::vector<std::uint64_t> block_begin{0};
    std::vector<std::uint32_t> block_objects;
    const std::vector<std::uint32_t>& tet_begin = this->topology_.object_tet_begin;
    for (std::uint32_t a = 0; a < objects; ++a)
        for (std::uint32_t b = a; b < objects; ++b) {
            if (!active[a * objects + b]) continue;
            const std::uint64_t na = tet_begin[a + 1] - tet_begin[a];
            const std::uint64_t nb = tet_begin[b + 1] - tet_begin[b];
            block_begin.push_back(block_begin.back() + (a == b ? na * (na - 1) / 2 : na * nb));
            block_objects.push_back(a);
            block_objects.push_back(b);
        }
    blocks_begin_.resize_discard(block_begin.size());
    exec.upload(blocks_begin_.data(), block_begin.data(), block_begin.size());
    block_objects_.resize_discard(block_objects.size());
    exec.upload(block_objects_.data(), block_objects.data(), block_objects.size());
    with_narrow_phase(this->options_.narrow_phase, [&](auto test) {
        exec.for_each(block_begin.back(),
                      BruteForcePairsKernel<decltype(test)::value>{scene, object_tet_begin, blocks_begin_.data(),
                                                                   block_objects_.data(),
                                                                   static_cast<std::uint32_t>(block_objects.size() / 2), out,
                                                                   exact_stage});
    });
}

/// @brief The pipeline that runs options.method: Pipeline for kdet, BaselinePipeline for the others.
template <class Exec>
std::unique_ptr<PipelineBase> make_pipeline(const DetectorOptions& options) {
    if (options.method == Method::kdet) return std::make_unique<Pipeline<Exec>>(options);
    return std::make_unique<BaselinePipeline<Exec>>(options);
}

} // namespace kdet
