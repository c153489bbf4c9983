#pragma once
/// @file options.hpp
/// @brief Enumerations and options that select how a Detector works.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace kdet {

/// @brief Where the pipeline runs.
enum class Backend { cpu, cuda };

/// @brief How candidate pairs are found. All methods report the same pairs.
enum class Method {
    kdet,              ///< hierarchical grid, candidates, narrow phase, sorted pairs: all unique pairs
    kdet_no_pairs,     ///< the thesis's old method: per-tet colliding flags only, no pair list
    brute_force_loop,  ///< every tet against every later tet, one work item per tet
    brute_force_pairs, ///< one work item per tet pair
};

/// @brief The tetrahedron-tetrahedron test run on each unique candidate pair.
enum class NarrowPhase {
    sat,          ///< separating axis test over the 44 axes, float with a relative tolerance
    sat_no_edges, ///< face normals only: conservative, may report extra pairs
    sat_mtv,      ///< decides overlap with the 44-axis SAT as sat does; contacts come from `contacts`
    gjk,          ///< GJK with a signed-volumes distance sub-algorithm
    fast,         ///< Ganovelli-Ponchio-Rocchini face-plane test
    exact,        ///< exact for the float coordinates (filtered: float, then double, then exact sums); default
};

/// @brief Hash function of the hierarchical grid.
enum class HashFunction { djb2, fnv1a, simple, morton };

/// @brief The canonical name of a value: what the command line, the viewer and the Python package
/// show and what benchmark files record.
const char* to_string(Backend value);
const char* to_string(Method value);
const char* to_string(NarrowPhase value);
const char* to_string(HashFunction value);

/// @brief Reads a name into @p out; returns false (leaving @p out unchanged) when it is unknown.
/// Accepted: the canonical names, and the thesis's own spellings of the brute-force methods ("gpu"
/// for brute_force_loop, "gpu_no_loop" for brute_force_pairs). Case is ignored, and '-' and '_' are
/// interchangeable ("SAT-MTV" is sat_mtv, "fnv_1a" is fnv-1a).
bool parse(const std::string& name, Backend& out);
bool parse(const std::string& name, Method& out);
bool parse(const std::string& name, NarrowPhase& out);
bool parse(const std::string& name, HashFunction& out);

/// @brief Canonical names of every value of an option type (Backend, Method, NarrowPhase or
/// HashFunction) in declaration order, for help texts, error messages, menus and bindings.
template <class Option>
const std::vector<std::string>& option_names();
template <>
const std::vector<std::string>& option_names<Backend>();
template <>
const std::vector<std::string>& option_names<Method>();
template <>
const std::vector<std::string>& option_names<NarrowPhase>();
template <>
const std::vector<std::string>& option_names<HashFunction>();

/// @brief The other names parse() accepts for @p value besides its canonical one (the thesis's
/// "gpu" and "gpu_no_loop"); empty for most values.
std::vector<std::string> aliases(Method value);

/// @brief The largest DetectorOptions::bucket_capacity accepted.
constexpr std::uint32_t max_bucket_capacity = 4096;

/// @brief Settings of a Detector; all have working defaults.
struct DetectorOptions {
    Backend backend = Backend::cpu;
    Method method = Method::kdet;
    NarrowPhase narrow_phase = NarrowPhase::exact;
    HashFunction hash = HashFunction::djb2;
    /// CPU threads; 0 leaves OpenMP's default.
    int threads = 0;
    /// CUDA block size (threads per block), 1-1024; capped per kernel at what the kernel can launch with.
    int block_size = 128;
    /// Tet ids per grid bucket before an overflow bucket is chained, 1-4096; 0 chooses it from each
    /// frame's grid plan, never smaller than before for the same objects: four times the mean ids per
    /// occupied cell rounded up to a power of two, from 4 to 32 (sparse scenes get small buckets, and
    /// a much smaller table).
    std::uint32_t bucket_capacity = 0;
    /// Initial capacity of the candidate buffer in pairs; 0 sizes it from the tet count.
    /// It grows (and the stage reruns) whenever a frame needs more, so any value is safe.
    std::size_t initial_candidate_capacity = 0;
    /// Bytes the detector's memory may reach by growing a frame's candidate and colliding-pair
    /// buffers; 0: as much as the memory holds. A frame that needs more (counted before anything
    /// grows) throws kdet::Error at once, naming its pairs and their bytes, and leaves the detector usable.
    std::size_t memory_limit = 0;
    /// Return depth and direction per colliding pair, whatever the narrow-phase test: a stage after
    /// the test computes them with the 44-axis SAT's minimum translation vector. Per pair, so
    /// Method::kdet_no_pairs, which builds none, returns none (as for distances).
    bool contacts = false;
    /// Report every pair whose closed sets lie at most this distance apart (finite, >= 0), decided
    /// exactly for the float coordinates and this float; 0: the pairs that touch or intersect.
    float margin = 0.0f;
    /// Return per pair its distance (0 when the tets intersect) and a closest point on each tet (a
    /// common point when they intersect): FrameResult::distances and closest_points.
    bool distances = false;
    /// CUDA backend: the stream (a cudaStream_t) every kernel, copy and sort of the detector runs on,
    /// so positions that the caller's kernels write on that stream are read after them. Null: the
    /// default stream. Must stay null on the CPU backend.
    void* cuda_stream = nullptr;
    /// Copy pairs, flags and contacts into FrameResult. Off: they stay in the backend's memory
    /// (Detector::device_results()) and FrameResult carries counts, times and memory only.
    bool results_to_host = true;
};

} // namespace kdet
