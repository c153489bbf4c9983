#pragma once
/// Random strings for the property tests of text parsing (option values, command-line flags).

#include <iterator>
#include <random>
#include <string>

namespace kdet::test {

/// A string drawn from pieces that parsers trip over, or from any bytes.
inline std::string random_text(std::mt19937& rng) {
    static const char* const pieces[] = {"0", "1", "9", "-", "+", " ", "\t", "\n", ".", "e", "x", "0x", "1e3",
                                         "9223372036854775807", "9223372036854775808", "-9223372036854775808",
                                         "18446744073709551616", "1024", "4096", "true", "FALSE", "Yes", "sat-MTV",
                                         "fnv_1a", "gpu", "cuda", "nan", "inf", "_", "\xff", "\0", ":", "slabs",
                                         "random", "yes", "1:2"};
    std::uniform_int_distribution<int> length(0, 6), kind(0, 3), byte(0, 255);
    std::uniform_int_distribution<std::size_t> piece(0, std::size(pieces) - 1);
    std::string text;
    for (int n = length(rng); n > 0; --n) {
        if (kind(rng) == 0)
            text += static_cast<char>(byte(rng));
        else
            text += std::string(pieces[piece(rng)]);
    }
    return text;
}

} // namespace kdet::test
