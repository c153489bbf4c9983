#pragma once
/// @file output_file.hpp
/// @brief What the writers share: an output file taking text, exact numbers and binary values, and
/// the check that a mesh is worth writing. Private to the io module.

#include "io/text_reader.hpp"

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <string_view>
#include <type_traits>

namespace kdet::io {

/// @brief A file being written; numbers go out as the shortest text that reads back exactly, or as
/// binary values of a chosen byte order.
class OutputFile {
public:
    explicit OutputFile(const std::string& path) : path_(path), out_(path, std::ios::binary) {
        if (!out_) throw Error(path_ + ": cannot open file for writing");
    }

    void text(std::string_view text) { out_.write(text.data(), static_cast<std::streamsize>(text.size())); }

    template <typename Number>
    void number(Number value) {
        char digits[32]; // enough for any double or 64-bit integer
        const auto result = std::to_chars(digits, digits + sizeof digits, value);
        out_.write(digits, result.ptr - digits);
    }

    /// @brief Writes the bytes of @p value in @p order (the inverse of decode()).
    template <typename T>
    void binary(T value, Endian order) {
        static_assert(std::is_arithmetic_v<T> && (sizeof(T) == 4 || sizeof(T) == 8), "4- or 8-byte numbers");
        std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t> bits;
        std::memcpy(&bits, &value, sizeof bits);
        char bytes[sizeof(T)];
        for (std::size_t i = 0; i < sizeof(T); ++i) {
            const std::size_t k = order == Endian::big ? sizeof(T) - 1 - i : i;
            bytes[k] = static_cast<char>((bits >> (8 * i)) & 0xffu);
        }
        out_.write(bytes, sizeof bytes);
    }

    /// @brief Closes the file; a failed write (a full disk) surfaces here.
    void close() {
        out_.close();
        if (!out_) throw Error(path_ + ": cannot write file");
    }

private:
    std::string path_;
    std::ofstream out_;
};

/// @brief Writes the fields of records as text separated by blanks and ending in a line break, or
/// as binary values of one byte order.
class RecordWriter {
public:
    RecordWriter(OutputFile& out, bool binary, Endian order) : out_(out), binary_(binary), order_(order) {}

    template <typename T>
    void field(T value) {
        if (binary_) {
            out_.binary(value, order_);
            return;
        }
        if (!first_) out_.text(" ");
        out_.number(value);
        first_ = false;
    }

    void end_record() {
        if (!binary_) out_.text("\n");
        first_ = true;
    }

    /// @brief Ends a block of data and writes @p keyword: binary data is followed by a line break first.
    void end_section(std::string_view keyword) {
        if (binary_) out_.text("\n");
        out_.text(keyword);
    }

private:
    OutputFile& out_;
    bool binary_;
    Endian order_;
    bool first_ = true;
};

/// @brief Refuses to write what the readers would reject, except degenerate tetrahedra, which the
/// readers accept on request.
inline void check_writable(const TetMesh& mesh, const std::string& path) {
    ReadOptions accept_degenerate;
    accept_degenerate.allow_degenerate = true;
    validate_tet_mesh(mesh, path, accept_degenerate);
}

/// @brief Writes "x y z" of @p vertex.
inline void write_coordinates(OutputFile& out, const TetMesh& mesh, std::size_t vertex) {
    for (std::size_t axis = 0; axis < 3; ++axis) {
        if (axis > 0) out.text(" ");
        out.number(mesh.positions[3 * vertex + axis]);
    }
}

/// @brief Writes the four corners of @p tet, numbered from @p base.
inline void write_corners(OutputFile& out, const TetMesh& mesh, std::size_t tet, std::uint64_t base) {
    for (std::size_t k = 0; k < 4; ++k) {
        if (k > 0) out.text(" ");
        out.number(std::uint64_t{mesh.tets[4 * tet + k]} + base);
    }
}

} // namespace kdet::io
