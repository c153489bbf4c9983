#pragma once
/// @file pair_exclusions.hpp
/// @brief Pairs of tets left out beyond shared vertices (Detector::set_self_exclusion_rings,
/// Detector::exclude_rest_contacts), as the search and the baselines test them before any geometry.
/// Each pair is listed once, under its lower stored id: SceneView::exclusion_begin[t] to [t + 1] index
/// SceneView::excluded, the sorted stored ids u > t that tet t is never paired with. A pair met from
/// either side reads the lower tet's list; tets without exclusions have empty lists, which cost one
/// comparison.

#include "pipeline/scene_view.hpp"

#include <cstdint>

namespace kdet {

/// @brief The first of the sorted ids [first, last) that is not below x (last when none is).
KDET_HD inline const std::uint32_t* first_not_below(const std::uint32_t* first, const std::uint32_t* last, std::uint32_t x) {
    std::uint32_t n = static_cast<std::uint32_t>(last - first);
    while (n > 0) {
        const std::uint32_t half = n / 2;
        if (first[half] < x) {
            first += half + 1;
            n -= half + 1;
        } else {
            n = half;
        }
    }
    return first;
}

/// @brief Whether the sorted ids [first, last) hold x.
KDET_HD inline bool sorted_holds(const std::uint32_t* first, const std::uint32_t* last, std::uint32_t x) {
    const std::uint32_t* found = first_not_below(first, last, x);
    return found != last && *found == x;
}

/// @brief The exclusions as one tet meets its partners: holds(u) says whether (t, u) is excluded.
struct ExcludedPartners {
    const std::uint32_t* begin = nullptr; ///< SceneView::exclusion_begin; null when nothing is excluded
    const std::uint32_t* excluded = nullptr;
    std::uint32_t t = 0;

    /// @brief Whether the pair (t, u) is excluded: a binary search for the higher tet in the lower
    /// one's list (an empty list answers at once).
    KDET_HD bool holds(std::uint32_t u) const {
        if (!begin) return false;
        const std::uint32_t low = u < t ? u : t, high = u < t ? t : u;
        return sorted_holds(excluded + begin[low], excluded + begin[low + 1], high);
    }
};

/// @brief The exclusions of tet t in scene `s` (none when the scene excludes nothing).
KDET_HD inline ExcludedPartners excluded_partners(const SceneView& s, std::uint32_t t) {
    return ExcludedPartners{s.exclusion_begin, s.excluded, t};
}

/// @brief Whether the pair of stored tets (t, u) is excluded (either order).
KDET_HD inline bool excluded_pair(const SceneView& s, std::uint32_t t, std::uint32_t u) {
    return excluded_partners(s, t).holds(u);
}

} // namespace kdet
