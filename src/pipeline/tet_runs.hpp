#pragma once
/// @file tet_runs.hpp
/// @brief Runs of consecutive tets per work item, for the stages that search the grid tet by tet.

#include "geometry/vec3.hpp"

#include <cstdint>

namespace kdet {

/// @brief The runs of consecutive tets that the grid's searches (and point location's scans) take per
/// work item (Tuning::search_tets_per_item): how many there are for `tets` tets, and the tets [first, end) of run r
/// (the last run may be shorter).
template <std::uint32_t TetsPerItem>
struct TetRuns {
    KDET_HD static std::uint32_t count(std::uint32_t tets) { return tets / TetsPerItem + (tets % TetsPerItem ? 1u : 0u); }
    KDET_HD static std::uint32_t first(std::uint32_t r) { return r * TetsPerItem; }
    KDET_HD static std::uint32_t end(std::uint32_t r, std::uint32_t tets) {
        return tets - first(r) < TetsPerItem ? tets : first(r) + TetsPerItem;
    }
    /// @brief Calls f(t) for the tets t of run r in order while f returns true; a run of one tet (the
    /// GPU's) without a loop, whose counter and bounds would take registers from the GPU's search
    /// kernel and lower its occupancy.
    template <class F>
    KDET_HD static void for_each_tet(std::uint32_t r, std::uint32_t tets, F&& f) {
        if constexpr (TetsPerItem == 1) {
            f(r);
        } else {
            for (std::uint32_t t = first(r), e = end(r, tets); t < e && f(t); ++t) {
            }
        }
    }
};

} // namespace kdet
