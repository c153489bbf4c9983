#pragma once
/// @file pipeline_base.hpp
/// @brief The interface a Detector drives: per backend Pipeline (pipeline.hpp) for Method::kdet and
/// BaselinePipeline (baselines.hpp) for the thesis's baselines, chosen by make_pipeline.

#include "pipeline/gather_positions.hpp"
#include "pipeline/locate_driver.hpp"
#include "pipeline/positions_check.hpp"
#include "pipeline/scene_view.hpp"

#include <kdet/detector.hpp>
#include <kdet/options.hpp>
#include <kdet/results.hpp>

#include <memory>
#include <vector>

namespace kdet {

/// @brief Elements (tets, vertices, pairs) up to which the host's own loops over them run on one
/// thread: sharing fewer costs more than it saves.
constexpr std::ptrdiff_t host_parallel_elements = 65536;

/// @brief The threads of the host's own loops for DetectorOptions::threads = `requested` (0: OpenMP's
/// default), as the CPU backend uses.
int host_threads(int requested);

/// @brief Objects as the pipeline sees them: concatenated, with per-object tet ranges.
struct SceneTopology {
    std::vector<TetIndices> tets;               ///< stored vertex ids
    std::vector<std::uint32_t> tet_object;
    std::vector<std::uint32_t> object_tet_begin; ///< [objects + 1]
    /// [tets] the caller's global id of each stored tet: tets are stored in spatial order
    /// (spatial_order.hpp) and reported under the caller's numbering.
    std::vector<std::uint32_t> tet_user_id;
    /// [vertex_count] the caller's global id of each stored vertex. An object's vertices keep its range
    /// of ids and are stored in the order its stored tets first use them (vertices no tet uses last), so
    /// that a stage reading the tets one after the other reads their positions one after the other too:
    /// a mesh or soup whose vertices are listed in no spatial order had every tet's first vertex load
    /// miss the caches.
    std::vector<std::uint32_t> vertex_user_id;
    std::uint32_t vertex_count = 0;
    /// [objects] 1 for a static object (Detector::set_static): the pipeline stores its tets after the
    /// moving ones (static_last) and places them once.
    std::vector<std::uint8_t> object_static;

    /// @brief Appends an object: its `vertex_count` vertices at `positions` and its `tet_count` tets (four
    /// vertex indices each, into `positions`), stored in spatial order (computed on `threads` threads),
    /// its vertices numbered on from the vertices stored so far.
    void add_object(const vec3* positions, std::uint32_t vertex_count, const std::uint32_t* tets, std::size_t tet_count,
                    int threads = 1);

    /// @brief The positions of the vertices from global id `first` on (one object's or a range of
    /// them; `caller.vertex_count` of them), given in the caller's order and layout, written in the
    /// order the pipeline stores them as float32 (`stored`, also indexed from `first`), on `threads`
    /// threads when there are many: a simulation hands over every object's positions each frame.
    void to_stored_order(std::uint32_t first, const PositionsView& caller, vec3* stored, int threads = 1) const;
    void to_stored_order(std::uint32_t first, std::uint32_t count, const vec3* caller_order, vec3* stored, int threads = 1) const {
        to_stored_order(first, xyz_view(caller_order, count), stored, threads);
    }

    /// @brief This topology with object `object`'s vertices (from global id `first_vertex`,
    /// `old_vertex_count` of them) and tets replaced by `vertex_count` vertices at `positions` and
    /// `tet_count` tets, stored as add_object() stores them; the other objects keep their stored order,
    /// their ids shifted past it (topology_edit.cpp).
    SceneTopology with_object_replaced(std::uint32_t object, std::uint32_t first_vertex, std::uint32_t old_vertex_count,
                                       const vec3* positions, std::uint32_t vertex_count, const std::uint32_t* tets,
                                       std::size_t tet_count, int threads = 1) const;
};

/// @brief Per stored tet, the sorted stored ids of the later tets it is never paired with beyond
/// shared vertices (pair_exclusions.hpp: each pair under its lower tet): a compressed row array,
/// begin[t] to begin[t + 1] indexing partners; empty when nothing is excluded.
struct ExclusionLists {
    std::vector<std::uint32_t> begin;
    std::vector<std::uint32_t> partners;
};

/// @brief `topology` with the tets of its static objects moved behind all others (each object's tets
/// stay together and in their order), so that a frame runs the first `moving_tets` only.
SceneTopology static_last(const SceneTopology& topology, std::uint32_t& moving_tets);

/// @brief Each of `count` colliding pairs' keys (two global tet ids in the caller's numbering) as the
/// caller's object and tet of each side, on host_threads(`threads`) threads: a frame of a
/// large scene hands out millions of pairs.
void pairs_from_keys(const std::vector<std::uint32_t>& object_tet_begin, const std::uint64_t* keys, std::size_t count,
                     TetPair* pairs, int threads);

/// @brief Each object's per-tet flags (1: the tet collides) from the per-global-tet counts `flags`, on
/// host_threads(`threads`) threads.
void flags_by_object(const std::vector<std::uint32_t>& object_tet_begin, const std::uint32_t* flags,
                     std::vector<std::vector<std::uint8_t>>& colliding, int threads);

/// @brief Positions of `count` vertices from global vertex `first` on, in stored order
/// (SceneTopology::to_stored_order), copied in at the start of a frame.
struct PositionUpload {
    std::uint32_t first;
    const vec3* positions;
    std::uint32_t count;
};

/// @brief `count` vertices from global vertex `first` on.
struct VertexRange {
    std::uint32_t first;
    std::uint32_t count;
};

class PipelineBase {
public:
    virtual ~PipelineBase() = default;
    /// @brief Replaces all geometry; positions must be set again afterwards.
    virtual void set_topology(const SceneTopology& topology) = 0;
    /// @brief Replaces the pairs excluded beyond shared vertices (pair_exclusions.hpp), in the stored
    /// ids object_first_tets() numbers; set again after every set_topology(), which clears them.
    virtual void set_exclusions(const ExclusionLists& lists) = 0;
    /// @brief One object's self-exclusion rings, built on this pipeline's backend
    /// (build_ring_exclusions in exclusion_rings.hpp); uses none of the pipeline's state.
    virtual ExclusionLists ring_exclusions(const TetIndices* tets, std::uint32_t tet_count, std::uint32_t first_vertex,
                                           std::uint32_t vertex_count, int rings, std::uint32_t object) const = 0;
    /// @brief Per object, the id of its first tet as this pipeline stores them, then the tet count:
    /// the given topology's order, or its static objects' tets moved behind (static_last); each
    /// object's tets stay together and in their order either way.
    virtual const std::vector<std::uint32_t>& object_first_tets() const = 0;
    /// @brief A static object's positions changed: the next frame places the static objects again.
    virtual void static_moved() = 0;
    /// @brief Copies positions already in the backend's memory (in stream order), in any layout, as
    /// float32 into a staging buffer from global vertex `first` on, waiting for nothing; a frame
    /// adopts them (start()'s `staged`) once it has checked that they are finite, so rejected
    /// positions never become current. Throws kdet::Error for memory the backend cannot read.
    virtual void stage_positions(std::uint32_t first, const PositionsView& positions) = 0;
    /// @brief Copies `count` positions starting at global vertex `first` back to the host: the current
    /// ones, in stored order, or with `staged` those stage_positions() copied (in the caller's order)
    /// and no frame has adopted yet.
    virtual void get_positions(std::uint32_t first, vec3* positions, std::uint32_t count, bool staged) = 0;
    /// @brief Enqueues one detection, after copying in the positions that changed on the host (counted
    /// in its total time) and adopting the `staged` ranges if all of them are finite; pair_enabled is
    /// [objects * objects], symmetric, diagonal = self-collision. Waits for nothing, except on a first
    /// frame (it sizes the buffers from what it reads).
    virtual void start(const std::vector<PositionUpload>& uploads, const std::vector<VertexRange>& staged,
                       std::vector<std::uint8_t> pair_enabled) = 0;
    /// @brief Completes the detection start() enqueued: reads its counters (and results when they go
    /// to the host) with one wait, and grows a buffer and reruns the frame if one was too small.
    /// Returns no_vertex, or the lowest global vertex of the staged positions with a non-finite
    /// coordinate: then none of them was adopted, `result` is left as it was, and the frame's device
    /// results are empty.
    virtual std::uint32_t finish(FrameResult& result) = 0;
    virtual DeviceResults device_results() = 0;
    /// @brief Copies in positions that changed on the host, as start() does, outside a frame.
    virtual void upload_positions(const std::vector<PositionUpload>& uploads) = 0;
    /// @brief Point location (Locator) over the current positions; waits for its results.
    virtual void locate(const LocateRequest& request, LocateResult& result) = 0;
    virtual DeviceLocateResults device_locate_results() const = 0;
    virtual std::size_t memory_bytes() const = 0;
    virtual std::string device_name() const = 0;
};

std::unique_ptr<PipelineBase> make_cpu_pipeline(const DetectorOptions& options);
/// @brief A test seam: while set, make_cpu_pipeline() returns what `factory` builds (nullptr restores
/// the CPU backend's own), so that the tests can run every Detector over another execution layer.
using PipelineFactory = std::unique_ptr<PipelineBase> (*)(const DetectorOptions&);
void set_cpu_pipeline_factory(PipelineFactory factory);
/// @brief Throws kdet::Error when kdet was built without CUDA or no CUDA device is present.
std::unique_ptr<PipelineBase> make_cuda_pipeline(const DetectorOptions& options);

} // namespace kdet
