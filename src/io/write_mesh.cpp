/// @file write_mesh.cpp
/// @brief The TetGen and MEDIT writers.

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include <charconv>
#include <cstdint>
#include <fstream>
#include <string>
#include <string_view>

namespace kdet {
namespace {

/// @brief A file being written; numbers go out as the shortest text that reads back exactly.
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

    /// @brief Closes the file; a failed write (a full disk) surfaces here.
    void close() {
        out_.close();
        if (!out_) throw Error(path_ + ": cannot write file");
    }

private:
    std::string path_;
    std::ofstream out_;
};

void write_coordinates(OutputFile& out, const TetMesh& mesh, std::size_t vertex) {
    for (std::size_t axis = 0; axis < 3; ++axis) {
        if (axis > 0) out.text(" ");
        out.number(mesh.positions[3 * vertex + axis]);
    }
}

void write_corners(OutputFile& out, const TetMesh& mesh, std::size_t tet, std::uint64_t base) {
    for (std::size_t k = 0; k < 4; ++k) {
        if (k > 0) out.text(" ");
        out.number(std::uint64_t{mesh.tets[4 * tet + k]} + base);
    }
}

/// @brief Refuses to write what the readers would reject, except degenerate tetrahedra, which the
/// readers accept on request.
void check_writable(const TetMesh& mesh, const std::string& path) {
    ReadOptions accept_degenerate;
    accept_degenerate.allow_degenerate = true;
    validate_tet_mesh(mesh, path, accept_degenerate);
}

/// @brief Writes a TetGen file: @p comment, the header "<count><header_rest>", then one line per entry
/// that starts with the entry's 0-based number.
template <typename WriteEntry>
void write_tetgen_file(const std::string& path, std::string_view comment, std::size_t count,
                       std::string_view header_rest, WriteEntry&& write_entry) {
    OutputFile out(path);
    out.text(comment);
    out.number(count);
    out.text(header_rest);
    for (std::size_t i = 0; i < count; ++i) {
        out.number(i);
        out.text(" ");
        write_entry(out, i);
        out.text("\n");
    }
    out.close();
}

} // namespace

void write_tetgen(const TetMesh& mesh, const std::string& stem) {
    check_writable(mesh, stem);
    write_tetgen_file(
        stem + ".node", "# <#points> <dimension> <#attributes> <#boundary markers>, then <index> <x> <y> <z>\n",
        mesh.num_vertices(), " 3 0 0\n", [&mesh](OutputFile& out, std::size_t v) { write_coordinates(out, mesh, v); });
    write_tetgen_file(
        stem + ".ele", "# <#tetrahedra> <nodes per tetrahedron> <#attributes>, then <index> <4 point indices>\n",
        mesh.num_tets(), " 4 0\n", [&mesh](OutputFile& out, std::size_t t) { write_corners(out, mesh, t, 0); });
}

void write_medit(const TetMesh& mesh, const std::string& path) {
    check_writable(mesh, path);

    OutputFile out(path);
    // Version 2 declares double precision, which the exact coordinates need.
    out.text("MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n");
    out.number(mesh.num_vertices());
    out.text("\n");
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
        write_coordinates(out, mesh, v);
        out.text(" 0\n");
    }
    out.text("\nTetrahedra\n");
    out.number(mesh.num_tets());
    out.text("\n");
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        write_corners(out, mesh, t, 1);
        out.text(" 0\n");
    }
    out.text("\nEnd\n");
    out.close();
}

} // namespace kdet
