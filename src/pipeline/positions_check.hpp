#pragma once
/// @file positions_check.hpp
/// @brief Positions handed over in the backend's memory: checked to be finite, then made current.

#include "exec/atomic.hpp"
#include "geometry/vec3.hpp"

#include <cstdint>

namespace kdet {

/// @brief No vertex: FrameCounters::first_non_finite_vertex while every staged position is finite.
constexpr std::uint32_t no_vertex = 0xffffffffu;

/// @brief Finds the lowest vertex with a non-finite coordinate among positions handed over in the
/// backend's memory (staged from vertex `first` on); `found` is global and starts at no_vertex.
struct FiniteCheckKernel {
    const vec3* staged; ///< indexed by the caller's global vertex id
    std::uint32_t first;
    std::uint32_t* found;
    KDET_HD void operator()(std::uint64_t i) const {
        const std::uint32_t v = first + static_cast<std::uint32_t>(i);
        const vec3 p = staged[v];
        // x - x is 0 for finite x and NaN for NaN and infinities.
        if (!(p.x - p.x == 0.0f && p.y - p.y == 0.0f && p.z - p.z == 0.0f)) atomic_min(found, v);
    }
};

/// @brief Makes staged positions current, once FiniteCheckKernel found none of them bad; otherwise
/// the previous positions stay and the frame's end reports the bad vertex.
struct AdoptPositionsKernel {
    const vec3* staged;                  ///< indexed by the caller's global vertex id
    const std::uint32_t* vertex_user_id; ///< [vertices] SceneTopology's
    vec3* positions;                     ///< indexed by stored vertex
    std::uint32_t first;
    const std::uint32_t* non_finite_vertex;
    KDET_HD void operator()(std::uint64_t i) const {
        if (*non_finite_vertex != no_vertex) return;
        const std::uint32_t v = first + static_cast<std::uint32_t>(i);
        positions[v] = staged[vertex_user_id[v]];
    }
};

} // namespace kdet
