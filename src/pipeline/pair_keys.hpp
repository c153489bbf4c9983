#pragma once
/// @file pair_keys.hpp
/// @brief Pairs of tets as 64-bit keys, and the appending of keys to a buffer of fixed room that
/// the candidate search, the narrow phase and the brute-force baselines share.

#include "exec/atomic.hpp"
#include "exec/radix_sort.hpp"

#include <cstdint>

namespace kdet {

/// @brief Sort key of a pair of global tet ids; the lower id goes first.
KDET_HD inline std::uint64_t pair_key(std::uint32_t t, std::uint32_t u) {
    const std::uint32_t lo = t < u ? t : u, hi = t < u ? u : t;
    return (static_cast<std::uint64_t>(lo) << 32) | hi;
}

/// @brief A candidate's key when the face-plane pre-test has already proven the pair intersecting:
/// the higher id goes first, which no pair_key does, so the narrow phase knows without testing again.
KDET_HD inline std::uint64_t proven_pair_key(std::uint32_t t, std::uint32_t u) {
    const std::uint32_t lo = t < u ? t : u, hi = t < u ? u : t;
    return (static_cast<std::uint64_t>(hi) << 32) | lo;
}
/// @brief Bits a pair key of tet ids below tet_count needs: the lower id fills the high word.
inline int pair_key_bits(std::uint32_t tet_count) { return high_word_key_bits(tet_count); }
/// @brief Bits of a pair key's low word (the higher id) that a tet id below tet_count can set.
inline int pair_key_low_word_bits(std::uint32_t tet_count) { return pair_key_bits(tet_count) - 32; }
KDET_HD inline std::uint32_t key_first(std::uint64_t key) { return static_cast<std::uint32_t>(key >> 32); }
KDET_HD inline std::uint32_t key_second(std::uint64_t key) { return static_cast<std::uint32_t>(key & 0xffffffffu); }

/// @brief A buffer slot that holds no pair: a batch that did not fit leaves it in the slots it got
/// below the capacity, so every slot below the count is defined. (t, t) is never a pair.
constexpr std::uint64_t no_pair_key = ~0ull;

/// @brief Appends to a buffer of `capacity` keys; the counter keeps counting past it, so the host
/// learns the size a rerun needs from the writers that go on appending. A batch is stored whole or
/// not at all.
struct KeyAppender {
    std::uint64_t* keys;
    std::uint64_t capacity;
    unsigned long long* count;
    /// Slots filled with no_pair_key by a batch that straddled the capacity; null where every batch
    /// is a single key, which fits or not, or where a buffer that overflows is never read (the
    /// narrow phase's pairs: the frame runs again).
    unsigned long long* padding;
    KDET_HD bool push(std::uint64_t key) const { return write(&key, 1); }
    KDET_HD bool write(const std::uint64_t* batch, std::uint32_t n) const {
        const unsigned long long first = atomic_fetch_add_gathered(count, static_cast<unsigned long long>(n));
        if (first + n <= capacity) {
            for (std::uint32_t k = 0; k < n; ++k) keys[first + k] = batch[k];
            return true;
        }
        if (first < capacity && padding) {
            for (unsigned long long k = first; k < capacity; ++k) keys[k] = no_pair_key;
            atomic_fetch_add(padding, static_cast<unsigned long long>(capacity - first));
        }
        return false;
    }
};

/// @brief One work item's keys, handed to a KeyAppender a batch at a time: one atomic per batch
/// instead of one per key, which matters when many threads append at once. Once a batch has not
/// fit, the item is `stopped`: if it goes on (to count the room a rerun needs), later batches only
/// count (every later slot is past the capacity); in a first frame it stops searching at once
/// (FindCandidatesKernel::stop_when_full).
struct KeyBatch {
    static constexpr std::uint32_t size = 16;
    const KeyAppender* out;
    std::uint32_t skip;   ///< keys an earlier run of this item stored: not written again
    std::uint32_t stored; ///< keys of this item in the buffer, the skipped ones included
    bool stopped = false;
    std::uint64_t keys[size];
    std::uint32_t n = 0;
    KDET_HD explicit KeyBatch(const KeyAppender* appender, std::uint32_t already_stored = 0)
        : out(appender), skip(already_stored), stored(already_stored) {}
    KDET_HD void push(std::uint64_t key) {
        if (skip) {
            --skip;
            return;
        }
        keys[n++] = key;
        if (n == size) flush();
    }
    KDET_HD void flush() {
        if (!n) return;
        // Once a batch has not fit, none does: the count only grows.
        if (out->write(keys, n))
            stored += n;
        else
            stopped = true;
        n = 0;
    }
};

} // namespace kdet
