/// @file read_mesh.cpp
/// @brief The TetGen and MEDIT readers, the reader and the writer chosen by extension, and
/// validate_tet_mesh.

#include "io/text_reader.hpp"

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace kdet {
namespace {

using namespace io;

// ---------------------------------------------------------------------------------------------
// TetGen

/// @brief Reads the next record of a TetGen file: one line of exactly @p fields tokens.
void read_tetgen_record(TextFile& file, std::vector<Token>& record, std::size_t fields, std::size_t index,
                        std::size_t count, const char* what, const char* layout) {
    if (!file.next_line(record)) fail_truncated(file, file.last_token_line(), count, index, what);
    // A short last line is where a cut-off file ends, not a malformed record.
    if (record.size() < fields && file.at_end()) fail_truncated(file, record.front().line, count, index, what);
    if (record.size() != fields) {
        file.fail(record.front().line, "expected " + std::to_string(fields) + " fields (" + layout + "), found " +
                                           std::to_string(record.size()));
    }
}

/// @brief Reads the header line of a TetGen file: 1 to @p max_fields counts, the missing ones 0.
std::vector<Token> read_tetgen_header(TextFile& file, std::size_t max_fields, const char* layout) {
    std::vector<Token> header;
    if (!file.next_line(header)) file.fail(1, "empty file");
    if (header.size() > max_fields) {
        file.fail(header.front().line, "header has " + std::to_string(header.size()) + " fields, expected " + layout);
    }
    return header;
}

/// @brief Reads the attribute count at @p position of a TetGen header, 0 when the header stops before.
/// Every attribute takes at least two bytes on every line, so a count beyond the rest of the file is
/// rejected, which also keeps the field counts computed from it far from overflow.
std::size_t read_attribute_count(const TextFile& file, const std::vector<Token>& header, std::size_t position) {
    if (header.size() <= position) return 0;
    const std::size_t count = read_count(file, header[position], "an attribute count");
    if (count > file.remaining_bytes()) {
        file.fail(header[position].line, "attribute count " + std::to_string(count) + " does not fit in the file");
    }
    return count;
}

/// @brief Reads a .node file into @p positions; returns the index of its first point (0 or 1), the base
/// of every index of the mesh.
long long read_tetgen_points(const std::string& path, std::vector<double>& positions) {
    TextFile file(path);
    const char* layout = "<#points> <dimension> <#attributes> <#boundary markers>";
    const std::vector<Token> header = read_tetgen_header(file, 4, layout);
    const std::size_t count = read_vertex_count(file, header[0], "a point count");
    if (header.size() > 1) {
        const long long dimension = read_integer(file, header[1], "a dimension");
        if (dimension != 3) file.fail(header[1].line, "dimension must be 3, found " + std::to_string(dimension));
    }
    const std::size_t attributes = read_attribute_count(file, header, 2);
    const std::size_t markers = header.size() > 3 ? read_count(file, header[3], "a boundary marker count") : 0;
    if (markers > 1)
        file.fail(header[3].line, "boundary marker count must be 0 or 1, found " + std::to_string(markers));

    const std::size_t fields = 4 + attributes + markers;
    positions.clear();
    positions.reserve(3 * reservable(count, fields, file));
    long long base = 0;
    std::vector<Token> record;
    for (std::size_t i = 0; i < count; ++i) {
        read_tetgen_record(file, record, fields, i, count, "points", "index, x, y, z, attributes, boundary marker");
        const long long index = read_integer(file, record[0], "a point index");
        const long long expected = base + static_cast<long long>(i);
        if (i == 0) {
            if (index != 0 && index != 1)
                file.fail(record[0].line, "first point index must be 0 or 1, found " + std::to_string(index));
            base = index;
        } else if (index >= base && index < expected) {
            file.fail(record[0].line, "duplicate point index " + std::to_string(index));
        } else if (index != expected) {
            file.fail(record[0].line, "point index " + std::to_string(index) + " out of sequence, expected " +
                                          std::to_string(expected));
        }
        for (std::size_t k = 1; k < 4; ++k) positions.push_back(read_coordinate(file, record[k]));
        for (std::size_t k = 4; k < 4 + attributes; ++k) check_number(file, record[k]);
        if (markers == 1) read_integer(file, record.back(), "a boundary marker");
    }
    reject_trailing_data(file, count, "points");
    return base;
}

/// @brief Reads a .ele file into @p mesh, whose positions are already read.
void read_tetgen_tetrahedra(const std::string& path, long long base, const ReadOptions& options, TetMesh& mesh) {
    TextFile file(path);
    const std::vector<Token> header =
        read_tetgen_header(file, 3, "<#tetrahedra> <nodes per tetrahedron> <#attributes>");
    const std::size_t count = read_count(file, header[0], "a tetrahedron count");
    if (count == 0) file.fail(header[0].line, "no tetrahedra");
    const std::size_t nodes = header.size() > 1 ? read_count(file, header[1], "a node count") : 4;
    if (nodes != 4 && nodes != 10)
        file.fail(header[1].line, "nodes per tetrahedron must be 4 or 10, found " + std::to_string(nodes));
    const std::size_t attributes = read_attribute_count(file, header, 2);

    const std::size_t fields = 1 + nodes + attributes;
    const std::size_t vertex_count = mesh.num_vertices();
    mesh.tets.clear();
    mesh.tets.reserve(4 * reservable(count, fields, file));
    std::vector<Token> record;
    for (std::size_t i = 0; i < count; ++i) {
        read_tetgen_record(file, record, fields, i, count, "tetrahedra", "index, nodes, attributes");
        read_integer(file, record[0], "a tetrahedron index");
        for (std::size_t k = 1; k <= nodes; ++k) {
            // Nodes 5 to 10 of a quadratic tetrahedron are checked like the corners, then dropped.
            const std::uint32_t corner = read_vertex_index(file, record[k], base, vertex_count);
            if (k <= 4) mesh.tets.push_back(corner);
        }
        for (std::size_t k = 1 + nodes; k < fields; ++k) check_number(file, record[k]);
        check_last_tet(file, record.front(), mesh, base, options);
    }
    reject_trailing_data(file, count, "tetrahedra");
}

/// @brief `name`, `name.node` and `name.ele` all name the pair `name.node` + `name.ele`.
std::string tetgen_stem(const std::string& path) {
    const std::string extension = std::filesystem::path(path).extension().string();
    if (extension == ".node" || extension == ".ele") return path.substr(0, path.size() - extension.size());
    return path;
}

// ---------------------------------------------------------------------------------------------
// MEDIT

/// @brief A MEDIT section the reader skips, and how many tokens each of its records has in 3D.
struct SkippedSection {
    std::string_view keyword;
    std::size_t fields;
};

constexpr SkippedSection skipped_sections[] = {
    {"Edges", 3},
    {"Triangles", 4},
    {"Quadrilaterals", 5},
    {"Prisms", 7},
    {"Pentahedra", 7},
    {"Pyramids", 6},
    {"Hexahedra", 9},
    {"EdgesP2", 4},
    {"TrianglesP2", 7},
    {"QuadrilateralsQ2", 10},
    {"TetrahedraP2", 11},
    {"HexahedraQ2", 28},
    {"Corners", 1},
    {"Ridges", 1},
    {"RequiredVertices", 1},
    {"RequiredEdges", 1},
    {"RequiredTriangles", 1},
    {"RequiredQuadrilaterals", 1},
    {"Normals", 3},
    {"Tangents", 3},
    {"NormalAtVertices", 2},
    {"NormalAtTriangleVertices", 3},
    {"NormalAtQuadrilateralVertices", 4},
    {"TangentAtEdgeVertices", 3},
};

const SkippedSection* find_skipped_section(std::string_view keyword) {
    for (const SkippedSection& section : skipped_sections) {
        if (section.keyword == keyword) return &section;
    }
    return nullptr;
}

bool is_medit_keyword(std::string_view word) {
    return word == "MeshVersionFormatted" || word == "Dimension" || word == "Vertices" || word == "Tetrahedra" ||
           word == "End" || find_skipped_section(word) != nullptr;
}

/// @brief Reads the value that follows a keyword (on the same line or a later one).
Token read_value(TextFile& file, const Token& keyword) {
    Token value;
    if (!file.next_token(value)) {
        file.fail(keyword.line, "file ends after " + std::string(keyword.text) + ", which needs a value");
    }
    return value;
}

/// @brief Calls @p handle on each of the @p count records of a MEDIT section, @p fields tokens each;
/// a record may span lines. A keyword where a value should be means the section holds fewer records
/// than announced.
template <typename Handle>
void for_each_medit_record(TextFile& file, std::size_t count, std::size_t fields, const std::string& what,
                           Handle&& handle) {
    std::vector<Token> record;
    for (std::size_t i = 0; i < count; ++i) {
        record.clear();
        Token token;
        for (std::size_t k = 0; k < fields; ++k) {
            if (!file.next_token(token)) fail_truncated(file, file.last_token_line(), count, i, what);
            if (is_medit_keyword(token.text)) {
                file.fail(token.line, "expected " + std::to_string(count) + " " + what + ", found " +
                                          std::to_string(i) + " before " + excerpt(token.text));
            }
            record.push_back(token);
        }
        handle(record);
    }
}

void read_medit_vertices(TextFile& file, const Token& keyword, TetMesh& mesh) {
    const std::size_t count = read_vertex_count(file, read_value(file, keyword), "a vertex count");
    constexpr std::size_t fields = 4; // x y z reference
    mesh.positions.reserve(3 * reservable(count, fields, file));
    for_each_medit_record(file, count, fields, "vertices", [&](const std::vector<Token>& record) {
        for (std::size_t k = 0; k < 3; ++k) mesh.positions.push_back(read_coordinate(file, record[k]));
        read_integer(file, record[3], "a vertex reference");
    });
}

void read_medit_tetrahedra(TextFile& file, const Token& keyword, const ReadOptions& options, TetMesh& mesh) {
    const Token count_token = read_value(file, keyword);
    const std::size_t count = read_count(file, count_token, "a tetrahedron count");
    if (count == 0) file.fail(count_token.line, "no tetrahedra");
    constexpr std::size_t fields = 5; // four corners and a reference
    constexpr long long base = 1;
    mesh.tets.reserve(4 * reservable(count, fields, file));
    for_each_medit_record(file, count, fields, "tetrahedra", [&](const std::vector<Token>& record) {
        for (std::size_t k = 0; k < 4; ++k)
            mesh.tets.push_back(read_vertex_index(file, record[k], base, mesh.num_vertices()));
        read_integer(file, record[4], "a tetrahedron reference");
        check_last_tet(file, record.front(), mesh, base, options);
    });
}

void skip_medit_section(TextFile& file, const Token& keyword, const SkippedSection& section) {
    const std::size_t count = read_count(file, read_value(file, keyword), "a record count");
    for_each_medit_record(file, count, section.fields, std::string(section.keyword),
                          [&](const std::vector<Token>& record) {
                              for (const Token& value : record) check_number(file, value);
                          });
}

} // namespace

// ---------------------------------------------------------------------------------------------
// Public functions

TetMesh read_tetgen(const std::string& path, const ReadOptions& options) {
    const std::string stem = tetgen_stem(path);
    TetMesh mesh;
    const long long base = read_tetgen_points(stem + ".node", mesh.positions);
    read_tetgen_tetrahedra(stem + ".ele", base, options, mesh);
    return mesh;
}

TetMesh read_medit(const std::string& path, const ReadOptions& options) {
    TextFile file(path);
    TetMesh mesh;
    Token keyword;
    if (!file.next_token(keyword)) file.fail(1, "empty file");
    bool have_dimension = false, have_vertices = false, have_tetrahedra = false;
    do {
        if (keyword.text == "End") break;
        if (keyword.text == "MeshVersionFormatted") {
            // 1 and 2 differ only in the precision of binary files; ASCII reads the same.
            read_integer(file, read_value(file, keyword), "a format version");
        } else if (keyword.text == "Dimension") {
            const Token value = read_value(file, keyword);
            const long long dimension = read_integer(file, value, "a dimension");
            if (dimension != 3) file.fail(value.line, "dimension must be 3, found " + std::to_string(dimension));
            have_dimension = true;
        } else if (keyword.text == "Vertices") {
            if (!have_dimension) file.fail(keyword.line, "Vertices before Dimension");
            if (have_vertices) file.fail(keyword.line, "second Vertices section");
            read_medit_vertices(file, keyword, mesh);
            have_vertices = true;
        } else if (keyword.text == "Tetrahedra") {
            // Corners are checked as they are read, which needs the vertices first (every writer does so).
            if (!have_vertices) file.fail(keyword.line, "Tetrahedra before Vertices");
            if (have_tetrahedra) file.fail(keyword.line, "second Tetrahedra section");
            read_medit_tetrahedra(file, keyword, options, mesh);
            have_tetrahedra = true;
        } else if (const SkippedSection* section = find_skipped_section(keyword.text)) {
            skip_medit_section(file, keyword, *section);
        } else {
            file.fail(keyword.line, "unknown keyword " + excerpt(keyword.text));
        }
    } while (file.next_token(keyword));
    if (!have_tetrahedra) file.fail(file.last_token_line(), "no tetrahedra (no Tetrahedra section)");
    return mesh;
}

TetMesh read_tet_mesh(const std::string& path, const ReadOptions& options) {
    // Any case for the formats of one file; TetGen's pair is found by the spelling given.
    const std::string given = std::filesystem::path(path).extension().string(), extension = lowercase_extension(path);
    if (extension == ".mesh") return read_medit(path, options);
    if (extension == ".msh") return read_gmsh(path, options);
    if (extension == ".vtk") return read_vtk(path, options);
    if (given.empty() || given == ".node" || given == ".ele") return read_tetgen(path, options);
    throw Error(path + ": unsupported mesh format " + excerpt(given) +
                "; supported: .mesh (MEDIT ASCII), .msh (Gmsh 2.2/4.1), .vtk (legacy VTK), .node/.ele or a name "
                "without extension (TetGen)");
}

void write_tet_mesh(const TetMesh& mesh, const std::string& path, const WriteOptions& options) {
    const std::string given = std::filesystem::path(path).extension().string(), extension = lowercase_extension(path);
    if (extension == ".mesh") return write_medit(mesh, path);
    if (extension == ".msh") return write_gmsh(mesh, path, GmshFormat{GmshVersion::v4_1, options.binary});
    if (extension == ".vtk") return write_vtk(mesh, path, VtkFormat{VtkVersion::v5_1, options.binary});
    if (given.empty() || given == ".node" || given == ".ele") return write_tetgen(mesh, tetgen_stem(path));
    throw Error(path + ": cannot write mesh format " + excerpt(given) +
                "; supported: .mesh (MEDIT), .msh (Gmsh 4.1), .vtk (legacy VTK 5.1), .node/.ele or a name without "
                "extension (TetGen)");
}

void validate_tet_mesh(const TetMesh& mesh, const std::string& source, const ReadOptions& options) {
    const auto fail = [&source](const std::string& what) { throw Error(source + ": " + what); };
    io::check_whole_entries(mesh, source);
    if (mesh.num_tets() == 0) fail("no tetrahedra");
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
        for (std::size_t axis = 0; axis < 3; ++axis) {
            const double value = mesh.positions[3 * v + axis];
            if (!std::isfinite(value)) {
                fail("vertex " + std::to_string(v) + ": coordinate " + "xyz"[axis] + " is not finite (" +
                     short_number(value) + ")");
            }
            if (!fits_float(value))
                fail("vertex " + std::to_string(v) + ": coordinate " + "xyz"[axis] + " (" + short_number(value) + ") is " +
                     float_range);
        }
    }
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        const std::string tet_name = "tet " + std::to_string(t) + ": ";
        for (std::size_t k = 0; k < 4; ++k) {
            const std::uint32_t corner = mesh.tets[4 * t + k];
            if (corner >= mesh.num_vertices()) fail(tet_name + index_out_of_range(corner, 0, mesh.num_vertices()));
        }
        if (options.allow_degenerate) continue;
        const std::string problem = degeneracy(mesh, t, 0);
        if (!problem.empty()) fail(tet_name + problem);
    }
}

} // namespace kdet
