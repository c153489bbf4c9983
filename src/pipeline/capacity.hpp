#pragma once
/// @file capacity.hpp
/// @brief How the detector's buffers grow when a frame needs more room than they have.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace kdet {

/// @brief The capacity a buffer of `current` elements grows to when a frame needs `wanted`, at most
/// `limit`: unchanged while it suffices, else a quarter more than before when that is more than
/// asked for. A deforming scene's need creeps up by a little most frames; growing to the exact need
/// reallocated (and cleared) the grid's buffers every few frames, where geometric steps do it a
/// logarithmic number of times for at most a quarter more memory.
constexpr std::uint64_t grown_capacity(std::uint64_t current, std::uint64_t wanted, std::uint64_t limit) {
    if (wanted <= current) return current;
    return std::min(limit, std::max(wanted, current + current / 4));
}

/// @brief The capacity a buffer of `current` elements grows to when a frame outgrew it and runs again
/// from the stage that fills it: unchanged while it suffices, else `wanted` and a quarter more, and
/// at least twice `current`. A scene whose overlap deepens needs more every frame (the thesis's
/// pass-through: a fifth more candidates each frame as the objects sink into each other), so a
/// quarter over the need ran out within a frame or two, and each time the frame's search ran again;
/// doubling makes that happen a logarithmic number of times, for at most twice the largest need.
constexpr std::uint64_t rerun_capacity(std::uint64_t current, std::uint64_t wanted) {
    if (wanted <= current) return current;
    return std::max(wanted + wanted / 4, 2 * current);
}

/// @brief Makes `buffer` (an execution layer's buffer) hold `wanted` elements where the memory allows,
/// else `fallback` (fewer), and returns how many it holds: near the memory's limit room with headroom
/// can fail where the need itself still fits. Throws only when `fallback` does not fit either (the
/// buffer is then empty).
template <class Buffer>
std::size_t resize_within_memory(Buffer& buffer, std::size_t wanted, std::size_t fallback) {
    if (buffer.try_resize_discard(wanted)) return wanted;
    buffer.resize_discard(fallback);
    return fallback;
}

/// @brief Makes `buffer` hold at least `wanted` elements for a frame that outgrew it: rerun_capacity's
/// room where the memory allows, else `wanted` exactly (resize_within_memory).
template <class Buffer>
void grow_for_rerun(Buffer& buffer, std::uint64_t wanted) {
    if (wanted > buffer.size()) resize_within_memory(buffer, rerun_capacity(buffer.size(), wanted), wanted);
}

/// @brief The colliding pairs' window when the candidates outgrew their buffer of
/// `candidate_capacity_before` keys and it grew to `candidate_capacity`: the window grows by the same
/// factor (never shrinks here). The frame runs its search and narrow phase again for the candidates
/// anyway, so the window grows in that rerun instead of outgrowing in one of its own a frame or two
/// later (in a deepening overlap the pairs grow with the candidates). Only sizes go in: which of the
/// candidates fitted, and so how many pairs the narrow phase found among them, depends on how the
/// threads shared the work, and the detector's memory would too.
inline std::uint64_t pairs_window_for_candidates(std::uint64_t window, std::uint64_t candidate_capacity_before,
                                                 std::uint64_t candidate_capacity) {
    if (candidate_capacity_before == 0) return window;
    const double grown = std::ceil(static_cast<double>(window) / static_cast<double>(candidate_capacity_before) *
                                   static_cast<double>(candidate_capacity));
    return std::max(window, static_cast<std::uint64_t>(grown));
}

} // namespace kdet
