#pragma once
/// @file capacity.hpp
/// @brief How the detector's buffers grow when a frame needs more room than they have.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include <kdet/error.hpp>

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

/// @brief Makes `buffer` (an execution layer's buffer) hold `wanted` elements where the memory and
/// `room` (DetectorOptions::memory_limit's share for it, room_for) allow, else `needed` (fewer), and
/// says whether it could: near the memory's limit room with headroom can fail where the need itself
/// still fits. When not even `needed` fits the buffer may be left empty (a failed allocation frees
/// the old one), which the next frame grows again.
template <class Buffer>
bool resize_within_memory(Buffer& buffer, std::size_t wanted, std::size_t needed, std::size_t room) {
    if (needed > room) return false;
    const std::size_t headroom = std::min(wanted, room);
    if (headroom > needed && buffer.try_resize_discard(headroom)) return true;
    return buffer.try_resize_discard(needed);
}

/// @brief Makes `buffer` hold at least `wanted` elements for a frame that outgrew it: rerun_capacity's
/// room where the memory allows, else `wanted` exactly (resize_within_memory); false when not even that.
template <class Buffer>
bool grow_for_rerun(Buffer& buffer, std::uint64_t wanted, std::size_t room) {
    return wanted <= buffer.size() || resize_within_memory(buffer, rerun_capacity(buffer.size(), wanted), wanted, room);
}

/// @brief How many elements of `bytes_each` bytes fit under `limit` (DetectorOptions::memory_limit;
/// 0: none) beside `held` bytes of the detector's other buffers.
constexpr std::size_t room_for(std::size_t limit, std::size_t held, std::size_t bytes_each) {
    if (limit == 0) return static_cast<std::size_t>(-1);
    return held >= limit ? 0 : (limit - held) / bytes_each;
}

/// @brief "N bytes (X.Y GB)", or MB below a gigabyte: a size for messages.
inline std::string bytes_text(std::uint64_t bytes) {
    char scaled[32];
    const bool gb = bytes >= 1000000000u;
    std::snprintf(scaled, sizeof scaled, gb ? "%.1f GB" : "%.1f MB", static_cast<double>(bytes) / (gb ? 1e9 : 1e6));
    return std::to_string(bytes) + " bytes (" + scaled + ")";
}

/// @brief The one-line error of a frame whose pairs the memory cannot hold: "`need` B bytes, more than
/// ...": `need` names the pairs ("the frame has N candidate pairs, which take"), `held` what the
/// detector holds besides, `limit` DetectorOptions::memory_limit (0: none).
[[noreturn]] inline void throw_frame_too_large(const std::string& need, std::uint64_t bytes, std::uint64_t held,
                                               std::uint64_t limit) {
    const std::string over = limit ? "more than memory_limit " + std::to_string(limit) + " leaves"
                                   : "more than the memory holds";
    // A limit below what the detector holds for its scene leaves no room for any pair: say so first.
    const std::string below = limit && held >= limit ? " (the limit is below what the detector holds for the scene alone)" : "";
    throw Error(need + " " + bytes_text(bytes) + ", " + over + " beside the detector's " + bytes_text(held) + below +
                "; nothing was detected");
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
