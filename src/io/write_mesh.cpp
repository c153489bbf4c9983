/// @file write_mesh.cpp
/// @brief The TetGen and MEDIT writers.

#include "io/output_file.hpp"

#include <kdet/io.hpp>

#include <cstdint>
#include <string>
#include <string_view>

namespace kdet {
namespace {

using namespace io;

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
