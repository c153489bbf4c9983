/// @file vtk.cpp
/// @brief The legacy VTK reader and writer for unstructured grids: the classic layout (versions up to
/// 4.2, "CELLS n size" then "k i0 .. ik-1" per cell) and the VTK 9 layout (version 5.1, OFFSETS and
/// CONNECTIVITY arrays), ASCII or binary. Binary legacy VTK is big-endian; each binary array starts
/// right after the line break of its keyword line.

#include "io/output_file.hpp"
#include "io/text_reader.hpp"

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace kdet {
namespace {

using namespace io;

constexpr long long vtk_tetra = 10;
constexpr long long vtk_quadratic_tetra = 24; // 10 points: the first 4 are the corners

/// @brief The data type named by @p token, as VTK spells them in legacy files.
Scalar read_vtk_type(const TextFile& file, const Token& token) {
    static const std::pair<std::string_view, Scalar> names[] = {
        {"char", Scalar::int8},          {"unsigned_char", Scalar::uint8},
        {"short", Scalar::int16},        {"unsigned_short", Scalar::uint16},
        {"int", Scalar::int32},          {"unsigned_int", Scalar::uint32},
        {"long", Scalar::int64},         {"unsigned_long", Scalar::uint64},
        {"float", Scalar::float32},      {"double", Scalar::float64},
        {"vtktypeint32", Scalar::int32}, {"vtktypeuint32", Scalar::uint32},
        {"vtktypeint64", Scalar::int64}, {"vtktypeuint64", Scalar::uint64},
    };
    for (const auto& [name, type] : names) {
        if (token.text == name) return type;
    }
    file.fail(token, "unsupported data type " + excerpt(token.text));
}

/// @brief The cells read so far: cell c has the points connectivity[offsets[c] .. offsets[c + 1]).
struct Cells {
    std::vector<std::size_t> offsets{0};
    std::vector<std::uint32_t> connectivity;
    std::size_t count() const { return offsets.size() - 1; }
};

/// @brief Ends a keyword line; in binary files the data starts after its line break.
void start_data(NumberStream& in) {
    if (in.binary()) in.file().skip_line_end();
}

void skip_field(NumberStream& in) {
    TextFile& file = in.file();
    file.expect_token("a field name");
    const std::size_t arrays = read_count(file, file.expect_token("an array count"), "an array count");
    for (std::size_t a = 0; a < arrays; ++a) {
        file.expect_token("an array name");
        const std::size_t components = read_count(file, file.expect_token("a component count"), "a component count");
        const Token tuples_token = file.expect_token("a tuple count");
        const std::size_t tuples = read_count(file, tuples_token, "a tuple count");
        const Scalar type = read_vtk_type(file, file.expect_token("a data type"));
        if (components != 0 && tuples > std::numeric_limits<std::size_t>::max() / components)
            file.fail(tuples_token, "field array too large");
        start_data(in);
        in.expect_records(components * tuples, scalar_size(type), "field values");
        for (std::size_t k = 0; k < components * tuples; ++k) in.real(type, "a field value");
    }
}

/// @brief Skips a METADATA block, which runs to the next empty line.
void skip_metadata(TextFile& file) {
    Token line;
    file.next_raw_line(line); // the rest of the METADATA line
    while (file.next_raw_line(line) && line.text.find_first_not_of(" \t") != std::string_view::npos) {
    }
}

void read_points(NumberStream& in, TetMesh& mesh) {
    TextFile& file = in.file();
    if (mesh.num_vertices() > 0) file.fail_here("second POINTS section");
    const std::size_t count = read_vertex_count(file, file.expect_token("a point count"), "a point count");
    const Token type_token = file.expect_token("a data type");
    const Scalar type = read_vtk_type(file, type_token);
    if (is_integer(type)) file.fail(type_token, "POINTS must be float or double, found " + excerpt(type_token.text));
    start_data(in);
    in.expect_records(count, 3 * scalar_size(type), "points");
    mesh.positions.reserve(3 * in.reservable(count, 3, type));
    for (std::size_t i = 0; i < 3 * count; ++i) mesh.positions.push_back(in.coordinate(type));
}

/// @brief Classic layout: per cell its point count, then its points, all 32-bit ints.
void read_classic_cells(NumberStream& in, std::size_t vertex_count, Cells& cells) {
    TextFile& file = in.file();
    const std::size_t count = read_count(file, file.expect_token("a cell count"), "a cell count");
    const Token size_token = file.expect_token("a cell list size");
    const std::size_t size = read_count(file, size_token, "a cell list size");
    if (count > size)
        file.fail(size_token, "cell list size " + std::to_string(size) + " is less than the " + std::to_string(count) +
                                  " cells need");
    start_data(in);
    in.expect_records(size, 4, "cell list values");
    cells.offsets.reserve(1 + in.reservable(count, 1, Scalar::int32));
    cells.connectivity.reserve(in.reservable(size, 1, Scalar::int32));
    std::size_t read = 0;
    for (std::size_t c = 0; c < count; ++c) {
        const std::size_t points = in.count(Scalar::int32, "a cell point count");
        if (points >= size - read) {
            in.fail("cell " + std::to_string(c) + " of " + std::to_string(points) +
                    " points overruns the cell list size " + std::to_string(size));
        }
        for (std::size_t k = 0; k < points; ++k)
            cells.connectivity.push_back(in.vertex_index(Scalar::int32, 0, vertex_count));
        read += 1 + points;
        cells.offsets.push_back(cells.connectivity.size());
    }
    if (read != size)
        in.fail("cells hold " + std::to_string(read) + " values, the header announces " + std::to_string(size));
}

/// @brief Reads the keyword line of an OFFSETS or CONNECTIVITY array; returns its integer type.
Scalar read_array_header(NumberStream& in, std::string_view keyword) {
    TextFile& file = in.file();
    file.expect_keyword(keyword);
    const Token type_token = file.expect_token("a data type");
    const Scalar type = read_vtk_type(file, type_token);
    if (!is_integer(type))
        file.fail(type_token, std::string(keyword) + " must hold integers, found " + excerpt(type_token.text));
    start_data(in);
    return type;
}

/// @brief VTK 9 layout: "CELLS offsets connectivity", then the OFFSETS and CONNECTIVITY arrays.
void read_offset_cells(NumberStream& in, std::size_t vertex_count, Cells& cells) {
    TextFile& file = in.file();
    const Token offsets_token = file.expect_token("an offset count");
    const std::size_t offset_count = read_count(file, offsets_token, "an offset count");
    const std::size_t size = read_count(file, file.expect_token("a connectivity size"), "a connectivity size");
    if (offset_count == 0 && size != 0) file.fail(offsets_token, "connectivity without offsets");

    const Scalar offset_type = read_array_header(in, "OFFSETS");
    in.expect_records(offset_count, scalar_size(offset_type), "offsets");
    cells.offsets.clear();
    cells.offsets.reserve(in.reservable(offset_count, 1, offset_type));
    for (std::size_t i = 0; i < offset_count; ++i) {
        const std::size_t offset = in.count(offset_type, "an offset");
        const std::size_t previous = cells.offsets.empty() ? 0 : cells.offsets.back();
        if (i == 0 && offset != 0) in.fail("the first offset must be 0, found " + std::to_string(offset));
        if (offset < previous || offset > size) {
            in.fail("offset " + std::to_string(offset) + " out of order or past the connectivity size " +
                    std::to_string(size));
        }
        cells.offsets.push_back(offset);
    }
    if (offset_count == 0) cells.offsets.push_back(0);
    if (cells.offsets.back() != size) {
        in.fail("the last offset must be the connectivity size " + std::to_string(size) + ", found " +
                std::to_string(cells.offsets.back()));
    }

    const Scalar index_type = read_array_header(in, "CONNECTIVITY");
    in.expect_records(size, scalar_size(index_type), "connectivity values");
    cells.connectivity.reserve(in.reservable(size, 1, index_type));
    for (std::size_t i = 0; i < size; ++i) cells.connectivity.push_back(in.vertex_index(index_type, 0, vertex_count));
}

/// @brief Reads CELL_TYPES and keeps the tetrahedra of @p cells in @p mesh.
void read_cell_types(NumberStream& in, const Cells& cells, const ReadOptions& options, TetMesh& mesh) {
    TextFile& file = in.file();
    const Token count_token = file.expect_token("a cell type count");
    const std::size_t count = read_count(file, count_token, "a cell type count");
    if (count != cells.count()) {
        file.fail(count_token,
                  "CELL_TYPES lists " + std::to_string(count) + " cells, CELLS holds " + std::to_string(cells.count()));
    }
    start_data(in);
    in.expect_records(count, 4, "cell types");
    for (std::size_t c = 0; c < count; ++c) {
        const long long type = in.integer(Scalar::int32, "a cell type");
        if (type != vtk_tetra && type != vtk_quadratic_tetra) continue;
        const std::size_t expected = type == vtk_tetra ? 4 : 10;
        const std::size_t first = cells.offsets[c], points = cells.offsets[c + 1] - first;
        if (points != expected) {
            in.fail("cell " + std::to_string(c) + " of type " + std::to_string(type) + " has " +
                    std::to_string(points) + " points, expected " + std::to_string(expected));
        }
        mesh.tets.insert(mesh.tets.end(), cells.connectivity.begin() + static_cast<std::ptrdiff_t>(first),
                         cells.connectivity.begin() + static_cast<std::ptrdiff_t>(first + 4));
        check_last_tet(file, in.last(), mesh, 0, options);
    }
}

/// @brief Reads the first three lines; returns whether the file is binary and sets @p offset_layout.
bool read_vtk_header(TextFile& file, bool& offset_layout) {
    Token line;
    if (!file.next_raw_line(line)) file.fail(1, "empty file");
    constexpr std::string_view signature = "# vtk DataFile Version ";
    if (line.text.substr(0, signature.size()) != signature)
        file.fail(line, "expected '# vtk DataFile Version x.y', found " + excerpt(line.text));
    const std::string_view version = line.text.substr(signature.size());
    const bool classic =
        version == "2.0" || version == "3.0" || version == "4.0" || version == "4.1" || version == "4.2";
    offset_layout = version == "5.1";
    if (!classic && !offset_layout)
        file.fail(line, "unsupported VTK version " + excerpt(version) + "; supported: 2.0 to 4.2 and 5.1");
    if (!file.next_raw_line(line)) file.fail(line.line, "file ends after the first line: expected a title");
    const Token encoding = file.expect_token("ASCII or BINARY");
    if (encoding.text != "ASCII" && encoding.text != "BINARY")
        file.fail(encoding, "expected ASCII or BINARY, found " + excerpt(encoding.text));
    file.expect_keyword("DATASET");
    const Token dataset = file.expect_token("a dataset type");
    if (dataset.text != "UNSTRUCTURED_GRID")
        file.fail(dataset, "only UNSTRUCTURED_GRID datasets are read, found " + excerpt(dataset.text));
    return encoding.text == "BINARY";
}

} // namespace

TetMesh read_vtk(const std::string& path, const ReadOptions& options) {
    TextFile file(path, '\0'); // legacy VTK has no comments
    bool offset_layout = false;
    const bool binary = read_vtk_header(file, offset_layout);
    NumberStream in(file, binary, Endian::big);
    TetMesh mesh;
    Cells cells;
    bool have_cells = false, have_types = false;
    Token keyword;
    while (file.next_token(keyword)) {
        if (keyword.text == "POINTS") {
            read_points(in, mesh);
        } else if (keyword.text == "CELLS") {
            // Cell points are checked as they are read, which needs the points first.
            if (mesh.num_vertices() == 0) file.fail(keyword, "CELLS before POINTS");
            if (have_cells) file.fail(keyword, "second CELLS section");
            offset_layout ? read_offset_cells(in, mesh.num_vertices(), cells)
                          : read_classic_cells(in, mesh.num_vertices(), cells);
            have_cells = true;
        } else if (keyword.text == "CELL_TYPES") {
            if (!have_cells) file.fail(keyword, "CELL_TYPES before CELLS");
            if (have_types) file.fail(keyword, "second CELL_TYPES section");
            read_cell_types(in, cells, options, mesh);
            have_types = true;
        } else if (keyword.text == "FIELD") {
            skip_field(in);
        } else if (keyword.text == "METADATA") {
            skip_metadata(file);
        } else if (keyword.text == "POINT_DATA" || keyword.text == "CELL_DATA") {
            break; // attributes are not read
        } else {
            file.fail(keyword, "unknown keyword " + excerpt(keyword.text));
        }
    }
    if (!have_types) file.fail_here("no CELL_TYPES section");
    if (mesh.tets.empty()) file.fail_here("no tetrahedra (no cell of type 10 or 24)");
    return mesh;
}

void write_vtk(const TetMesh& mesh, const std::string& path, const VtkFormat& format) {
    check_writable(mesh, path);
    const bool offset_layout = format.version == VtkVersion::v5_1;
    if (!offset_layout && mesh.num_vertices() >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
        throw Error(path + ": too many vertices for the classic VTK layout, whose indices are 32-bit ints; use 5.1");
    OutputFile out(path);
    out.text(offset_layout ? "# vtk DataFile Version 5.1\n" : "# vtk DataFile Version 4.2\n");
    out.text("kdet tetrahedral mesh\n");
    out.text(format.binary ? "BINARY\n" : "ASCII\n");
    out.text("DATASET UNSTRUCTURED_GRID\nPOINTS ");
    out.number(mesh.num_vertices());
    out.text(" double\n");
    RecordWriter records(out, format.binary, Endian::big);
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
        for (std::size_t axis = 0; axis < 3; ++axis) records.field(mesh.positions[3 * v + axis]);
        records.end_record();
    }
    const std::size_t tets = mesh.num_tets();
    records.end_section("CELLS ");
    if (offset_layout) {
        out.number(tets + 1);
        out.text(" ");
        out.number(4 * tets);
        out.text("\nOFFSETS vtktypeint64\n");
        for (std::size_t t = 0; t <= tets; ++t) {
            records.field(static_cast<std::int64_t>(4 * t));
            records.end_record();
        }
        records.end_section("CONNECTIVITY vtktypeint64\n");
        for (std::size_t t = 0; t < tets; ++t) {
            for (std::size_t k = 0; k < 4; ++k) records.field(static_cast<std::int64_t>(mesh.tets[4 * t + k]));
            records.end_record();
        }
    } else {
        out.number(tets);
        out.text(" ");
        out.number(5 * tets);
        out.text("\n");
        for (std::size_t t = 0; t < tets; ++t) {
            records.field(std::int32_t{4});
            for (std::size_t k = 0; k < 4; ++k) records.field(static_cast<std::int32_t>(mesh.tets[4 * t + k]));
            records.end_record();
        }
    }
    records.end_section("CELL_TYPES ");
    out.number(tets);
    out.text("\n");
    for (std::size_t t = 0; t < tets; ++t) {
        records.field(static_cast<std::int32_t>(vtk_tetra));
        records.end_record();
    }
    records.end_section("");
    out.close();
}

} // namespace kdet
