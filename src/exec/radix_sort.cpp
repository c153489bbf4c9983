#include "exec/radix_sort.hpp"

#include <algorithm>
#include <utility>
#include <vector>

namespace kdet {

void radix_sort(std::uint64_t* keys, std::size_t n, int bits, std::uint64_t* scratch, int threads, int first_bit,
                int low_word_bits) {
    if (n <= 1 << 14) {
        if (first_bit == 0)
            std::sort(keys, keys + n);
        else
            std::stable_sort(keys, keys + n, [first_bit](std::uint64_t a, std::uint64_t b) { return a >> first_bit < b >> first_bit; });
        return;
    }
    // Only over the bits the keys use, skipping digits that every key shares (a pair key of a 100k-tet
    // mesh: 3 passes where a comparison sort makes log2(n) of them). The digits are taken from the key
    // without the low word's unused bits (`packed`), as evenly wide as passes of at most 12 bits allow:
    // a pair key of 1M-tet ids uses 40 of its 52 bits, 4 passes where 11-bit digits of the whole key
    // took 5, and one of 68k-tet ids 3 where they took 5.
    const int gap = bits > 32 ? 32 - low_word_bits : 0;
    const std::uint64_t low_mask = (std::uint64_t{1} << low_word_bits) - 1;
    const auto packed = [gap, low_mask](std::uint64_t key) { return (key >> gap & ~low_mask) | (key & low_mask); };
    const int packed_bits = bits - gap;
    const int passes = (packed_bits - first_bit + 11) / 12;
    const int digit_bits = passes > 0 ? (packed_bits - first_bit + passes - 1) / passes : 1;
    const std::size_t digits = std::size_t{1} << digit_bits;
    // Each thread counts and moves one slice of the keys, of 32k keys or more.
    const int slices = std::max(1, std::min(threads, static_cast<int>(n >> 15)));
    const std::size_t per_slice = (n + static_cast<std::size_t>(slices) - 1) / static_cast<std::size_t>(slices);
    const auto slice_begin = [n, per_slice](int s) { return std::min(n, static_cast<std::size_t>(s) * per_slice); };
    std::vector<std::size_t> start(digits * static_cast<std::size_t>(slices)); // slice s, digit d at [s digits + d]
    std::uint64_t* from = keys;
    std::uint64_t* to = scratch;
    for (int shift = first_bit; shift < packed_bits; shift += digit_bits) {
        const auto digit = [shift, digits, packed](std::uint64_t key) { return (packed(key) >> shift) & (digits - 1); };
#pragma omp parallel for num_threads(slices)
        for (int s = 0; s < slices; ++s) {
            std::size_t* count = &start[static_cast<std::size_t>(s) * digits];
            std::fill(count, count + digits, std::size_t{0});
            for (std::size_t i = slice_begin(s); i < slice_begin(s + 1); ++i) ++count[digit(from[i])];
        }
        bool one_digit = false; // then nothing moves
        for (std::size_t d = 0; d < digits && !one_digit; ++d) {
            std::size_t keys_with_d = 0;
            for (int s = 0; s < slices; ++s) keys_with_d += start[static_cast<std::size_t>(s) * digits + d];
            one_digit = keys_with_d == n;
        }
        if (one_digit) continue;
        // A digit's keys from slice s go after those from slice s - 1: the sort stays stable.
        std::size_t sum = 0;
        for (std::size_t d = 0; d < digits; ++d)
            for (int s = 0; s < slices; ++s) sum += std::exchange(start[static_cast<std::size_t>(s) * digits + d], sum);
#pragma omp parallel for num_threads(slices)
        for (int s = 0; s < slices; ++s) {
            std::size_t* next = &start[static_cast<std::size_t>(s) * digits];
            for (std::size_t i = slice_begin(s); i < slice_begin(s + 1); ++i) to[next[digit(from[i])]++] = from[i];
        }
        std::swap(from, to);
    }
    if (from != keys) std::copy(from, from + n, keys);
}

} // namespace kdet
