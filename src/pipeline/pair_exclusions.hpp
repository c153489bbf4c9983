#pragma once
/// @file pair_exclusions.hpp
/// @brief Pairs of tets left out beyond shared vertices (Detector::set_self_exclusion_rings,
/// Detector::exclude_rest_contacts), as the search and the baselines test them before any geometry.
/// Each stored tet has a sorted list of the stored tets it is never paired with (both directions are
/// listed), in one compressed row array: SceneView::exclusion_begin[t] to [t + 1] index
/// SceneView::excluded. Tets of objects without exclusions have empty lists, which cost one comparison.

#include "pipeline/scene_view.hpp"

#include <cstdint>

namespace kdet {

/// @brief One tet's excluded partners: sorted stored ids.
struct ExcludedPartners {
    const std::uint32_t* first = nullptr;
    const std::uint32_t* last = nullptr;

    /// @brief Whether u is among them (binary search; an empty list answers at once).
    KDET_HD bool holds(std::uint32_t u) const {
        const std::uint32_t* lo = first;
        std::uint32_t n = static_cast<std::uint32_t>(last - first);
        while (n > 0) {
            const std::uint32_t half = n / 2;
            if (lo[half] < u) {
                lo += half + 1;
                n -= half + 1;
            } else {
                n = half;
            }
        }
        return lo != last && *lo == u;
    }
};

/// @brief Tet t's excluded partners in scene `s` (none when the scene excludes nothing).
KDET_HD inline ExcludedPartners excluded_partners(const SceneView& s, std::uint32_t t) {
    if (!s.exclusion_begin) return ExcludedPartners{};
    return ExcludedPartners{s.excluded + s.exclusion_begin[t], s.excluded + s.exclusion_begin[t + 1]};
}

/// @brief Whether the pair of stored tets (t, u) is excluded (either order: the lists are symmetric).
KDET_HD inline bool excluded_pair(const SceneView& s, std::uint32_t t, std::uint32_t u) {
    return excluded_partners(s, t).holds(u);
}

} // namespace kdet
