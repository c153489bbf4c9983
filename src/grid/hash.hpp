#pragma once
/// @file hash.hpp
/// @brief The four grid hash functions of the thesis (section 4.4), adapted to integer cell keys.
/// Each maps a cell (x, y, z, layer) and a probe number to a 32-bit hash; table_slot maps that to a
/// slot of the power-of-two table. The probe number enters the hash, so a miss rehashes as in the thesis.

#include "geometry/vec3.hpp"

#include <kdet/config.hpp>
#include <kdet/options.hpp>

#include <cstdint>

namespace kdet {

/// @brief Integer coordinates of one grid cell; coordinates are wrapped to 19 bits.
struct CellCoord {
    std::uint32_t x, y, z, layer;
};

namespace hash_detail {

/// Odd multiplier that makes successive probes of the arithmetic hashes visit every slot.
constexpr std::uint32_t probe_stride = 2654435761u;

/// DJB2 (h = h * 33 + byte) over the 4 bytes of a word, low byte first, from h = 0. Unrolled over all
/// bytes, DJB2 is h0 * 33^n plus each byte times 33 to the number of bytes after it (mod 2^32), so
/// the bytes need not wait on each other: the hash is on the path of every cell lookup.
KDET_HD inline std::uint32_t djb2_word(std::uint32_t word) {
    return (word & 0xffu) * 35937u + ((word >> 8) & 0xffu) * 1089u + ((word >> 16) & 0xffu) * 33u + (word >> 24);
}

/// djb2_word of the two 32-bit halves of v at once, each in the same half of the result: byte pairs
/// first (b0 * 33 + b1 and b2 * 33 + b3 in each 16-bit lane, below 2^14), then each half's two pairs
/// (pair0 * 33^2 + pair1, below 2^24), so no lane carries into the next.
KDET_HD inline std::uint64_t djb2_word_pair(std::uint64_t v) {
    constexpr std::uint64_t even_bytes = 0x00ff00ff00ff00ffull, low_lanes = 0x0000ffff0000ffffull;
    const std::uint64_t pairs = (v & even_bytes) * 33u + ((v >> 8) & even_bytes);
    return (pairs & low_lanes) * 1089u + ((pairs >> 16) & low_lanes);
}

/// 33^(4 * words): what DJB2 multiplies the hash so far by over `words` more words.
constexpr std::uint32_t djb2_shift(int words) { return words == 0 ? 1u : 1185921u * djb2_shift(words - 1); }

KDET_HD inline std::uint32_t fnv1a_word(std::uint32_t hash, std::uint32_t word) {
    for (int byte = 0; byte < 4; ++byte) hash = (hash ^ ((word >> (8 * byte)) & 0xffu)) * 16777619u;
    return hash;
}

/// Spreads the low 10 bits of v so that two zero bits separate each of them.
KDET_HD inline std::uint32_t spread_bits_3(std::uint32_t v) {
    v &= 0x3ffu;
    v = (v | (v << 16)) & 0x030000ffu;
    v = (v | (v << 8)) & 0x0300f00fu;
    v = (v | (v << 4)) & 0x030c30c3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

} // namespace hash_detail

/// @brief The Morton code (10 bits an axis, x lowest) of p's place in the box from lo to hi, clamped
/// to the box (a side without extent, or one that overflows float, puts every point at its low end).
KDET_HD inline std::uint32_t morton_code_in_box(vec3 p, vec3 lo, vec3 hi) {
    const auto quantize = [](float x, float low, float high) {
        const float scaled = high > low ? (x - low) / (high - low) * 1023.0f : 0.0f;
        return scaled > 0.0f ? static_cast<std::uint32_t>(scaled < 1023.0f ? scaled : 1023.0f) : 0u;
    };
    return hash_detail::spread_bits_3(quantize(p.x, lo.x, hi.x)) | (hash_detail::spread_bits_3(quantize(p.y, lo.y, hi.y)) << 1) |
           (hash_detail::spread_bits_3(quantize(p.z, lo.z, hi.z)) << 2);
}

/// @brief A cell's hash before its probe number is mixed in. Each hash here is a function of the cell's
/// part and the probe number, so a lookup computes the cell's part once, however many slots it
/// probes (and the dispatch on the function runs outside the probe loop: inside it, the compiler
/// hoisted the cell's part of all four functions and computed them all on every lookup).
struct CellHash {
    HashFunction function;
    std::uint32_t cell_part;
};

/// @brief DJB2 over the bytes of the cell key (x, y, z, layer); the probe number's bytes follow.
KDET_HD inline std::uint32_t djb2_cell_part(CellCoord c) {
    using namespace hash_detail;
    constexpr std::uint32_t start = 5381u * djb2_shift(5);
    const std::uint64_t xy = djb2_word_pair(c.x | static_cast<std::uint64_t>(c.y) << 32);
    const std::uint64_t zl = djb2_word_pair(c.z | static_cast<std::uint64_t>(c.layer) << 32);
    return start + static_cast<std::uint32_t>(xy) * djb2_shift(4) + static_cast<std::uint32_t>(xy >> 32) * djb2_shift(3) +
           static_cast<std::uint32_t>(zl) * djb2_shift(2) + static_cast<std::uint32_t>(zl >> 32) * djb2_shift(1);
}

/// @brief FNV-1a (32-bit) over the bytes of the cell key; the probe number's bytes follow.
KDET_HD inline std::uint32_t fnv1a_cell_part(CellCoord c) {
    std::uint32_t h = 2166136261u;
    h = hash_detail::fnv1a_word(h, c.x);
    h = hash_detail::fnv1a_word(h, c.y);
    h = hash_detail::fnv1a_word(h, c.z);
    return hash_detail::fnv1a_word(h, c.layer);
}

/// @brief Teschner et al.'s three-prime hash, with the layer term of Eitz and Lixu.
KDET_HD inline std::uint32_t simple_cell_part(CellCoord c) {
    return (c.x * 73856093u) ^ (c.y * 19349663u) ^ (c.z * 83492791u) ^ (c.layer * 67867979u);
}

/// @brief Morton code of the low 10 bits of each coordinate, mixed with the layer.
KDET_HD inline std::uint32_t morton_cell_part(CellCoord c) {
    const std::uint32_t code = hash_detail::spread_bits_3(c.x) | (hash_detail::spread_bits_3(c.y) << 1) |
                               (hash_detail::spread_bits_3(c.z) << 2);
    // The high coordinate bits that the 30-bit code drops still reach the hash through the xor.
    const std::uint32_t high = ((c.x >> 10) * 73856093u) ^ ((c.y >> 10) * 19349663u) ^ ((c.z >> 10) * 83492791u);
    return code ^ high ^ (c.layer * 67867979u);
}

/// @brief The cell's part of the selected hash function.
KDET_HD inline CellHash hash_cell_part(HashFunction function, CellCoord c) {
    switch (function) {
    case HashFunction::fnv1a: return CellHash{function, fnv1a_cell_part(c)};
    case HashFunction::simple: return CellHash{function, simple_cell_part(c)};
    case HashFunction::morton: return CellHash{function, morton_cell_part(c)};
    case HashFunction::djb2:
    default: return CellHash{HashFunction::djb2, djb2_cell_part(c)};
    }
}

/// @brief The hash of probe number `probe` of a cell: DJB2 and FNV-1a go on over the probe number's
/// bytes; the arithmetic hashes add it times an odd stride.
KDET_HD inline std::uint32_t hash_probe(const CellHash& h, std::uint32_t probe) {
    switch (h.function) {
    case HashFunction::fnv1a: return hash_detail::fnv1a_word(h.cell_part, probe);
    case HashFunction::simple:
    case HashFunction::morton: return h.cell_part + probe * hash_detail::probe_stride;
    case HashFunction::djb2:
    default: return h.cell_part + hash_detail::djb2_word(probe);
    }
}

/// @brief The selected hash function of a cell and probe number.
KDET_HD inline std::uint32_t hash_cell(HashFunction function, CellCoord c, std::uint32_t probe) {
    return hash_probe(hash_cell_part(function, c), probe);
}

/// @brief Slot of a hash in a table of 2^slot_bits slots. Fibonacci hashing keeps the product's high
/// bits, so hashes whose low bits vary little (DJB2 on small cell coordinates) still spread evenly.
KDET_HD inline std::uint32_t table_slot(std::uint32_t hash, std::uint32_t slot_bits) {
    return slot_bits == 0 ? 0u : (hash * 2654435769u) >> (32u - slot_bits);
}

} // namespace kdet
