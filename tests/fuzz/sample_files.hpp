#pragma once
/// Small valid surface files, built in code: what the surface tests read and what the fuzzers start
/// from. Each holds the unit square as the triangles (0 1 2) and (0 2 3), or as one quad.

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

namespace kdet::test {

inline const char* const square_obj = "# a square\nmtllib x.mtl\no square\nv 0 0 0\nv 1 0 0 1.0\n"
                                      "vt 0 0\nvn 0 0 1\nv 1 1 0\nv 0 1 0 0.5 0.5 0.5\n"
                                      "g face\nusemtl m\ns off\nf 1/1/1 2//1 3/1 4\n";

inline const char* const square_off = "OFF\n# comment\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 255 0 0\n";

inline const char* const square_stl = "solid square\n"
                                      "  facet normal 0 0 1\n    outer loop\n"
                                      "      vertex 0 0 0\n      vertex 1 0 0\n      vertex 1 1 0\n"
                                      "    endloop\n  endfacet\n"
                                      "  facet normal 0 0 1\n    outer loop\n"
                                      "      vertex 0 0 0\n      vertex 1 1 0\n      vertex 0 1 0\n"
                                      "    endloop\n  endfacet\n"
                                      "endsolid square\n";

/// Appends the bytes of @p value to @p bytes, big-endian or little-endian (the host is little-endian).
template <typename T>
void append_bytes(std::string& bytes, T value, bool big_endian = false) {
    char raw[sizeof value];
    std::memcpy(raw, &value, sizeof value);
    if (big_endian) std::reverse(raw, raw + sizeof raw);
    bytes.append(raw, sizeof raw);
}

/// A binary STL of the unit square; the header starts with "solid" as some writers' do.
inline std::string square_binary_stl() {
    std::string bytes = "solid but binary";
    bytes.resize(80, ' ');
    append_bytes(bytes, std::uint32_t{2});
    const float corners[2][3][3] = {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}};
    for (const auto& triangle : corners) {
        for (const float normal : {0.0f, 0.0f, 1.0f}) append_bytes(bytes, normal);
        for (const auto& corner : triangle)
            for (const float value : corner) append_bytes(bytes, value);
        append_bytes(bytes, std::uint16_t{0});
    }
    return bytes;
}

/// The PLY header of the unit square in @p format (ascii, binary_little_endian, binary_big_endian):
/// vertices with float x, y, double z and a colour byte, one quad face, and an edge element to skip.
inline std::string square_ply_header(const std::string& format) {
    return "ply\nformat " + format +
           " 1.0\ncomment a unit square\n"
           "element vertex 4\nproperty float x\nproperty float y\nproperty double z\nproperty uchar red\n"
           "element face 1\nproperty list uchar int vertex_indices\n"
           "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
           "end_header\n";
}

inline const char* const square_ply_ascii_body = "0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n4 0 1 2 3\n0 1\n";

/// The body that follows square_ply_header() in binary of either byte order.
inline std::string square_ply_binary_body(bool big_endian) {
    std::string bytes;
    const double square[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    for (const auto& corner : square) {
        append_bytes(bytes, static_cast<float>(corner[0]), big_endian);
        append_bytes(bytes, static_cast<float>(corner[1]), big_endian);
        append_bytes(bytes, corner[2], big_endian);
        append_bytes(bytes, std::uint8_t{200}, big_endian);
    }
    append_bytes(bytes, std::uint8_t{4}, big_endian);
    for (const std::int32_t index : {0, 1, 2, 3}) append_bytes(bytes, index, big_endian);
    append_bytes(bytes, std::int32_t{0}, big_endian);
    append_bytes(bytes, std::int32_t{1}, big_endian);
    return bytes;
}

} // namespace kdet::test
