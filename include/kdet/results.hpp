#pragma once
/// @file results.hpp
/// @brief What a detection returns: unique pairs, per-tet flags, counts, stage times, memory.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace kdet {

/// @brief One colliding pair; (object_a, tet_a) < (object_b, tet_b) in lexicographic order.
struct TetPair {
    std::uint32_t object_a, tet_a, object_b, tet_b;
    friend bool operator==(const TetPair& x, const TetPair& y) {
        return x.object_a == y.object_a && x.tet_a == y.tet_a && x.object_b == y.object_b && x.tet_b == y.tet_b;
    }
    friend bool operator<(const TetPair& x, const TetPair& y) {
        if (x.object_a != y.object_a) return x.object_a < y.object_a;
        if (x.tet_a != y.tet_a) return x.tet_a < y.tet_a;
        if (x.object_b != y.object_b) return x.object_b < y.object_b;
        return x.tet_b < y.tet_b;
    }
};

/// @brief Contact of a colliding pair from the 44-axis SAT: translating tet b by depth * direction
/// separates the pair (direction is a unit vector).
struct Contact {
    float depth;
    float direction[3];
};

/// @brief A closest point on each tet of a pair (DetectorOptions::distances): on the pair's first tet
/// (object_a, tet_a), then on its second; one common point twice when the tets intersect.
struct ClosestPoints {
    float on_a[3];
    float on_b[3];
};

/// @brief A detection's results where the backend keeps them: GPU memory for Backend::cuda, host
/// memory for Backend::cpu. Valid until the next detect(). Tets are numbered globally: object o's
/// tet i is Detector::first_tet(o) + i, objects following each other in id order (a removed object
/// holds none), as they stood when the detection ran.
struct DeviceResults {
    const std::uint64_t* pair_keys = nullptr; ///< (global_a << 32) | global_b with global_a < global_b, sorted
    std::size_t pair_count = 0;
    const std::uint32_t* colliding = nullptr; ///< per global tet: nonzero when it collides
    std::size_t tet_count = 0;
    const Contact* contacts = nullptr;        ///< parallel to pair_keys when contacts are on, else null
    const float* distances = nullptr;         ///< parallel to pair_keys when distances are on, else null
    const ClosestPoints* closest_points = nullptr; ///< likewise
};

/// @brief Milliseconds spent in each stage of one detection.
struct StageTimes {
    double bounding_boxes = 0;  ///< per-tet boxes and sizes, object boxes and their overlap
    double populate_grid = 0;
    double find_candidates = 0; ///< for kdet_no_pairs this includes its inline narrow phase
    double sort_pairs = 0;      ///< sorting the colliding pairs into the output order (the thesis's CSV: "sort unique time")
    double narrow_phase = 0;    ///< includes compacting the colliding pairs, contacts and copying them out
    double total = 0;           ///< the whole detect() call, positions copied in and results copied out included
};

/// @brief Sizes of one detection.
struct FrameCounts {
    std::uint64_t candidates = 0;        ///< candidate pairs found (boxes overlap, not adjacent nor excluded), each once
    /// Of the candidates, those the pre-test (slabs, face planes) could not reject: the narrow phase runs on
    /// these (the thesis's CSV: "unique candidates").
    std::uint64_t narrow_phase_candidates = 0;
    std::uint64_t colliding_pairs = 0;
    std::uint64_t colliding_tets = 0;    ///< tets flagged as colliding, all objects together
    std::uint64_t exact_stage_pairs = 0; ///< NarrowPhase::exact: pairs its float filter left to the exact stage
    std::uint32_t buffer_regrows = 0;    ///< times a buffer grew and its stage reran this frame
    std::uint64_t grid_cells = 0;        ///< occupied grid cells (main buckets claimed)
    std::uint64_t grid_slots = 0;        ///< main buckets of the hash table
    std::uint64_t grid_overflow_buckets = 0; ///< overflow buckets chained this frame
    /// Ids per grid bucket: DetectorOptions::bucket_capacity, or the automatic choice from the plans so far.
    std::uint32_t grid_bucket_capacity = 0;
    /// Times the host waited for the backend (reads of counters and results); on the GPU each is a
    /// stream synchronisation. Counted identically on the CPU backend.
    std::uint32_t host_waits = 0;
};

/// @brief Result of one detection. For Method::kdet_no_pairs, `pairs` stays empty and only the
/// flags are meaningful (that method never builds pairs).
struct FrameResult {
    std::vector<TetPair> pairs;                  ///< sorted ascending, unique
    std::vector<Contact> contacts;               ///< parallel to pairs when contacts are enabled
    std::vector<float> distances;                ///< parallel to pairs when distances are enabled
    std::vector<ClosestPoints> closest_points;   ///< parallel to pairs when distances are enabled
    std::vector<std::vector<std::uint8_t>> colliding; ///< [object][tet] = 1 if the tet collides
    FrameCounts counts;
    StageTimes times;
    std::size_t memory_bytes = 0;                ///< bytes held by the detector's buffers
    std::size_t grid_bytes = 0;                  ///< of which the grid's hash table
    std::size_t candidate_bytes = 0;             ///< of which the candidate pair buffer
};

} // namespace kdet
