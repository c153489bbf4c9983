#pragma once
/// @file radix_sort.hpp
/// @brief The host's sort of 64-bit keys (the CPU backend's sort stage and the storage order of
/// add_object use it), and the bits a sort of keys with a value in their high word must look at.

#include <cstddef>
#include <cstdint>

namespace kdet {

/// @brief Sorts keys[0, n) ascending by their bits [first_bit, bits), every key below 2^bits, stably
/// (keys equal in those bits keep their order; with first_bit 0, simply ascending): least significant
/// digit first, at most 12 bits a pass, a pass skipped where every key has the same digit; `scratch`
/// holds n keys. Keys with a value in each word (pair keys) may say that their low word is below
/// 2^low_word_bits (then first_bit must be 0): the passes skip the low word's unused bits. Up to
/// `threads` threads count and move a slice of the keys each. Small inputs go to a comparison sort.
void radix_sort(std::uint64_t* keys, std::size_t n, int bits, std::uint64_t* scratch, int threads, int first_bit = 0,
                int low_word_bits = 32);

/// @brief Bits of a key whose high word (from bit 32 on) holds a value below `high_values`: every such
/// key is below 2^bits, so a radix sort can stop there.
inline int high_word_key_bits(std::uint64_t high_values) {
    int bits = 32;
    for (std::uint64_t largest = high_values ? high_values - 1 : 0; largest; largest >>= 1) ++bits;
    return bits;
}

} // namespace kdet
