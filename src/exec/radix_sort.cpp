#include "exec/radix_sort.hpp"

#include <algorithm>
#include <utility>
#include <vector>

namespace kdet {

void radix_sort(std::uint64_t* keys, std::size_t n, int bits, std::uint64_t* scratch) {
    if (n <= 1 << 14) {
        std::sort(keys, keys + n);
        return;
    }
    // Only over the bits the keys use, skipping digits that every key shares (a pair key of a 100k-tet
    // mesh: 4 passes where a comparison sort makes log2(n) of them).
    constexpr int digit_bits = 11;
    constexpr std::size_t digits = std::size_t{1} << digit_bits;
    std::vector<std::size_t> start(digits);
    std::uint64_t* from = keys;
    std::uint64_t* to = scratch;
    for (int shift = 0; shift < bits; shift += digit_bits) {
        std::fill(start.begin(), start.end(), std::size_t{0});
        for (std::size_t i = 0; i < n; ++i) ++start[(from[i] >> shift) & (digits - 1)];
        if (std::find(start.begin(), start.end(), n) != start.end()) continue; // one digit: nothing moves
        std::size_t sum = 0;
        for (std::size_t& s : start) sum += std::exchange(s, sum);
        for (std::size_t i = 0; i < n; ++i) to[start[(from[i] >> shift) & (digits - 1)]++] = from[i];
        std::swap(from, to);
    }
    if (from != keys) std::copy(from, from + n, keys);
}

} // namespace kdet
