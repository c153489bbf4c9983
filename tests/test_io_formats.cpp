// Tests of the Gmsh, VTK and surface readers and writers: the real files in the models folder, round
// trips of every writer variant, hand-written files with the formats' options, and bad input whose
// error names the file and the line (text) or byte offset (binary).

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include "fuzz/sample_files.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace {

namespace fs = std::filesystem;
using namespace kdet::test;

/// Gives each test a fresh folder for its files, removed afterwards.
class Formats : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("kdet_formats_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ignored;
        fs::remove_all(dir_, ignored);
    }

public:
    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    /// Writes @p content to @p name and returns its path.
    std::string write(const std::string& name, const std::string& content) const {
        std::ofstream(path(name), std::ios::binary) << content;
        return path(name);
    }

private:
    fs::path dir_;
};

std::string read_bytes(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}


/// Checks that the error of @p action starts with @p location ("file:7: " or "file: byte 12: ") and
/// contains @p what.
void expect_error(const std::function<void()>& action, const std::string& location, const std::string& what) {
    const std::string message = error_message(action);
    EXPECT_EQ(message.rfind(location, 0), 0u) << "expected it to start with '" << location << "': " << message;
    EXPECT_NE(message.find(what), std::string::npos) << "expected it to contain '" << what << "': " << message;
}

std::string at_line(const std::string& file, int line) { return file + ":" + std::to_string(line) + ": "; }
std::string at_byte(const std::string& file, std::size_t byte) {
    return file + ": byte " + std::to_string(byte) + ": ";
}

/// Three tetrahedra around the unit cube's corner with coordinates that have no short decimal form.
kdet::TetMesh small_mesh() {
    kdet::TetMesh mesh;
    mesh.positions = {0.0, 0.0, 0.0,       1.0 / 3.0,    0.0,         0.0,    0.0,        0.1,        0.0,
                      0.0, 0.0, 2.0 / 7.0, 1.0e-3 / 3.0, 1.0e5 / 7.0, 3.0e-7, -1.0 / 9.0, -2.0 / 3.0, -5.0 / 11.0};
    mesh.tets = {0, 1, 2, 3, 1, 2, 3, 4, 0, 2, 1, 5};
    return mesh;
}

/// Two tetrahedra of the unit cube's corner, sharing the face (1, 2, 3).
kdet::TetMesh unit_tets() {
    kdet::TetMesh mesh;
    mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    mesh.tets = {0, 1, 2, 3, 1, 2, 3, 4};
    return mesh;
}

void expect_equal(const kdet::TetMesh& actual, const kdet::TetMesh& expected) {
    EXPECT_EQ(actual.positions, expected.positions);
    EXPECT_EQ(actual.tets, expected.tets);
}

/// A tetrahedron as the sorted coordinates of its corners: independent of vertex and tet numbering.
using TetCorners = std::array<std::array<double, 3>, 4>;

std::multiset<TetCorners> tet_set(const kdet::TetMesh& mesh) {
    std::multiset<TetCorners> tets;
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        TetCorners corners;
        for (std::size_t k = 0; k < 4; ++k) {
            const std::size_t v = mesh.tets[4 * t + k];
            corners[k] = {mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]};
        }
        std::sort(corners.begin(), corners.end());
        tets.insert(corners);
    }
    return tets;
}

// ---------------------------------------------------------------------------------------------
// Gmsh

/// Every variant the Gmsh writer has, with a file name for it.
const std::pair<kdet::GmshFormat, const char*> gmsh_formats[] = {
    {{kdet::GmshVersion::v2_2, false}, "v22_ascii.msh"},
    {{kdet::GmshVersion::v2_2, true}, "v22_binary.msh"},
    {{kdet::GmshVersion::v4_1, false}, "v41_ascii.msh"},
    {{kdet::GmshVersion::v4_1, true}, "v41_binary.msh"},
};

TEST_F(Formats, GmshHandMshIsHandMesh) {
    kdet::test::use_default_data_dir();
    const kdet::TetMesh msh = kdet::read_gmsh(kdet::data_path("hand.msh"));
    const kdet::TetMesh mesh = kdet::read_medit(kdet::data_path("hand.mesh"));
    EXPECT_EQ(msh.num_vertices(), 7234u);
    EXPECT_EQ(msh.num_tets(), 29998u);
    std::set<std::array<double, 3>> msh_vertices, mesh_vertices;
    for (std::size_t v = 0; v < msh.num_vertices(); ++v)
        msh_vertices.insert({msh.positions[3 * v], msh.positions[3 * v + 1], msh.positions[3 * v + 2]});
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v)
        mesh_vertices.insert({mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]});
    EXPECT_TRUE(msh_vertices == mesh_vertices);
    EXPECT_TRUE(tet_set(msh) == tet_set(mesh));
    // The extension chooses the reader.
    expect_equal(kdet::read_tet_mesh(kdet::data_path("hand.msh")), msh);
}

/// Writes small_mesh() and @p model in each of @p formats (a format and a file name) with @p write,
/// and checks that both read back exactly through @p read and through read_tet_mesh.
template <typename Format, std::size_t count, typename Write, typename Read>
void expect_round_trips(const Formats& test, const std::pair<Format, const char*> (&formats)[count],
                        const kdet::TetMesh& model, Write write, Read read) {
    for (const auto& [format, name] : formats) {
        SCOPED_TRACE(name);
        const std::string file = test.path(name);
        for (const kdet::TetMesh& mesh : {small_mesh(), model}) {
            write(mesh, file, format);
            expect_equal(read(file, kdet::ReadOptions{}), mesh);
            expect_equal(kdet::read_tet_mesh(file), mesh);
        }
    }
}

TEST_F(Formats, GmshRoundTripsEveryVariant) {
    kdet::test::use_default_data_dir();
    expect_round_trips(*this, gmsh_formats, kdet::read_medit(kdet::data_path("bunny.mesh")), kdet::write_gmsh,
                       kdet::read_gmsh);
}

TEST_F(Formats, GmshV22AsciiTagsOtherElementsAndSections) {
    const std::string file =
        write("hand_written.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                                  "$PhysicalNames\n1\n3 1 \"body\"\n$EndPhysicalNames\n"
                                  "$Nodes\n5\n"
                                  "10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n7 1 1 1\n"
                                  "$EndNodes\n"
                                  "$Elements\n4\n"
                                  "1 15 2 0 1 10\n"
                                  "2 2 2 0 1 10 20 30\n"
                                  "3 4 2 1 1 10 20 30 40\n"
                                  "4 11 3 1 1 5 20 30 40 7 10 10 10 10 10 10\n"
                                  "$EndElements\n"
                                  "$NodeData\n1\n\"T\"\n1\n0.0\n3\n0\n1\n1\n10 3.5\n$EndNodeData\n");
    expect_equal(kdet::read_gmsh(file), unit_tets());
}

TEST_F(Formats, GmshV41AsciiBlocksAndParametricNodes) {
    const std::string file = write("blocks.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
                                                 "$Entities\n1 0 0 1\n1 0 0 0 0\n1 0 0 0 1 1 1 0 0\n$EndEntities\n"
                                                 "$Nodes\n3 5 3 50\n"
                                                 "0 1 0 1\n3\n0 0 0\n"
                                                 "1 4 1 2\n50\n4\n1 0 0 0.25\n0 1 0 0.5\n"
                                                 "3 1 0 2\n5\n6\n0 0 1\n1 1 1\n"
                                                 "$EndNodes\n"
                                                 "$Elements\n2 3 1 3\n"
                                                 "2 1 2 1\n1 3 50 4\n"
                                                 "3 1 4 2\n2 3 50 4 5\n3 50 4 5 6\n"
                                                 "$EndElements\n");
    expect_equal(kdet::read_gmsh(file), unit_tets());
}

/// Offset of the first @p marker in @p text followed by its line break, or fails.
std::size_t after(const std::string& text, const std::string& marker) {
    const std::size_t at = text.find(marker);
    EXPECT_NE(at, std::string::npos) << marker;
    return at + marker.size();
}

TEST_F(Formats, GmshBinaryErrorsNameTheByte) {
    const std::string file = path("valid.msh");
    kdet::write_gmsh(unit_tets(), file, {kdet::GmshVersion::v2_2, true});
    const std::string valid = read_bytes(file);
    const std::size_t marker = after(valid, "2.2 1 8\n");
    const std::size_t nodes = after(valid, "$Nodes\n5\n");

    std::string big_endian = valid;
    std::reverse(big_endian.begin() + static_cast<std::ptrdiff_t>(marker),
                 big_endian.begin() + static_cast<std::ptrdiff_t>(marker) + 4);
    const std::string swapped = write("swapped.msh", big_endian);
    expect_error([&] { kdet::read_gmsh(swapped); }, at_byte(swapped, marker), "written on a big-endian machine");

    std::string garbage = valid;
    garbage[marker] = 7;
    const std::string bad_marker = write("bad_marker.msh", garbage);
    expect_error([&] { kdet::read_gmsh(bad_marker); }, at_byte(bad_marker, marker),
                 "endianness marker reads 7, expected 1");

    // Cut inside the third node: the count check before reading catches it at the start of the block.
    const std::string cut = write("cut.msh", valid.substr(0, nodes + 2 * 28 + 10));
    expect_error([&] { kdet::read_gmsh(cut); }, at_byte(cut, nodes), "5 nodes need 140 bytes, only 66 left");

    std::string nan = valid;
    const double not_a_number = std::numeric_limits<double>::quiet_NaN();
    std::memcpy(&nan[nodes + 28 + 4 + 8], &not_a_number, 8); // y of the second node
    const std::string nan_file = write("nan.msh", nan);
    expect_error([&] { kdet::read_gmsh(nan_file); }, at_byte(nan_file, nodes + 28 + 12),
                 "coordinate nan is not finite");

    // The first element's first node tag (block header 12 bytes, then number and two tags).
    const std::size_t elements = after(valid, "$Elements\n2\n");
    std::string unknown = valid;
    const std::int32_t missing_tag = 99;
    std::memcpy(&unknown[elements + 12 + 12], &missing_tag, 4);
    const std::string unknown_file = write("unknown_tag.msh", unknown);
    expect_error([&] { kdet::read_gmsh(unknown_file); }, at_byte(unknown_file, elements + 24),
                 "node tag 99 is not in $Nodes");

    std::string type = valid;
    const std::int32_t no_such_type = 1000;
    std::memcpy(&type[elements], &no_such_type, 4);
    const std::string type_file = write("type.msh", type);
    expect_error([&] { kdet::read_gmsh(type_file); }, at_byte(type_file, elements), "unknown element type 1000");
}

TEST_F(Formats, GmshV41BinaryAbsurdCountDoesNotAllocate) {
    const std::string file = path("valid.msh");
    kdet::write_gmsh(unit_tets(), file, {kdet::GmshVersion::v4_1, true});
    std::string bytes = read_bytes(file);
    const std::size_t nodes = after(bytes, "$Nodes\n");
    const std::uint64_t absurd = std::uint64_t{1} << 62;
    std::memcpy(&bytes[nodes + 8], &absurd, 8); // the node count
    const std::string absurd_file = write("absurd.msh", bytes);
    expect_error([&] { kdet::read_gmsh(absurd_file); }, at_byte(absurd_file, nodes + 8), "too many vertices");
    const std::uint64_t large = 1000000;
    std::memcpy(&bytes[nodes + 8], &large, 8);
    const std::string large_file = write("large.msh", bytes);
    expect_error([&] { kdet::read_gmsh(large_file); }, at_byte(large_file, nodes + 32),
                 "1000000 nodes need 32000000 bytes");
}

TEST_F(Formats, GmshTextErrorsNameTheLine) {
    const std::string version = write("version.msh", "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n");
    expect_error([&] { kdet::read_gmsh(version); }, at_line(version, 2), "unsupported MSH version '3.0'");
    const std::string empty = write("empty.msh", "");
    expect_error([&] { kdet::read_gmsh(empty); }, at_line(empty, 1), "empty file");

    const std::string head = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n";
    const std::string range =
        write("range.msh", head + "4 0 0 1\n$EndNodes\n$Elements\n1\n1 4 0 1 2 3 5\n$EndElements\n");
    expect_error([&] { kdet::read_gmsh(range); }, at_line(range, 13), "node tag 5 is not in $Nodes");
    const std::string nan = write("nan.msh", head + "4 0 nan 1\n$EndNodes\n");
    expect_error([&] { kdet::read_gmsh(nan); }, at_line(nan, 9), "coordinate 'nan' is not finite");
    const std::string duplicate = write("duplicate.msh", head + "3 0 0 1\n$EndNodes\n");
    expect_error([&] { kdet::read_gmsh(duplicate); }, at_line(duplicate, 9), "duplicate node tag 3");
    const std::string absurd =
        write("absurd.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4000000000\n1 0 0 0\n");
    expect_error([&] { kdet::read_gmsh(absurd); }, at_line(absurd, 6), "file ends early: expected a node tag");
    const std::string flat =
        write("flat.msh", head + "4 1 1 0\n$EndNodes\n$Elements\n1\n1 4 0 1 2 3 4\n$EndElements\n");
    expect_error([&] { kdet::read_gmsh(flat); }, at_line(flat, 13), "degenerate tetrahedron");
    kdet::ReadOptions allow;
    allow.allow_degenerate = true;
    EXPECT_EQ(kdet::read_gmsh(flat, allow).num_tets(), 1u);
    const std::string no_tets =
        write("no_tets.msh", head + "4 0 0 1\n$EndNodes\n$Elements\n1\n1 2 0 1 2 3\n$EndElements\n");
    expect_error([&] { kdet::read_gmsh(no_tets); }, at_line(no_tets, 14), "no tetrahedra");
    const std::string unterminated = write("unterminated.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Comments\nhi\n");
    expect_error([&] { kdet::read_gmsh(unterminated); }, at_line(unterminated, 4), "has no $EndComments");
}

// ---------------------------------------------------------------------------------------------
// VTK

/// Every variant the VTK writer has, with a file name for it.
const std::pair<kdet::VtkFormat, const char*> vtk_formats[] = {
    {{kdet::VtkVersion::v4_2, false}, "v42_ascii.vtk"},
    {{kdet::VtkVersion::v4_2, true}, "v42_binary.vtk"},
    {{kdet::VtkVersion::v5_1, false}, "v51_ascii.vtk"},
    {{kdet::VtkVersion::v5_1, true}, "v51_binary.vtk"},
};

TEST_F(Formats, VtkRoundTripsEveryVariant) {
    kdet::test::use_default_data_dir();
    expect_round_trips(*this, vtk_formats, kdet::read_medit(kdet::data_path("hand.mesh")), kdet::write_vtk,
                       kdet::read_vtk);
}

TEST_F(Formats, VtkClassicAsciiFieldOtherCellsAndQuadraticTets) {
    const std::string file = write("classic.vtk", "# vtk DataFile Version 3.0\nhand written\nASCII\n"
                                                  "DATASET UNSTRUCTURED_GRID\n"
                                                  "FIELD FieldData 1\nTIME 1 1 double\n2.5\n"
                                                  "POINTS 5 float\n0 0 0 1 0 0\n0 1 0 0 0 1 1 1 1\n"
                                                  "CELLS 4 22\n1 4\n3 0 1 2\n4 0 1 2 3\n10 1 2 3 4 0 0 0 0 0 0\n"
                                                  "CELL_TYPES 4\n1\n5\n10\n24\n"
                                                  "POINT_DATA 5\nSCALARS s float 1\nLOOKUP_TABLE default\n1 2 3 4 5\n");
    expect_equal(kdet::read_vtk(file), unit_tets());
}

TEST_F(Formats, VtkOffsetLayoutAsciiInt32AndMetadata) {
    const std::string file = write("offsets.vtk", "# vtk DataFile Version 5.1\nvtk output\nASCII\n"
                                                  "DATASET UNSTRUCTURED_GRID\nPOINTS 5 double\n"
                                                  "0 0 0 1 0 0 0 1 0\n0 0 1 1 1 1\n"
                                                  "METADATA\nINFORMATION 0\n\n"
                                                  "CELLS 4 11\nOFFSETS vtktypeint32\n0 4 7 11\n"
                                                  "CONNECTIVITY vtktypeint32\n0 1 2 3\n0 1 2\n1 2 3 4\n"
                                                  "CELL_TYPES 3\n10\n5\n10\n");
    expect_equal(kdet::read_vtk(file), unit_tets());
}

TEST_F(Formats, VtkBinaryErrorsNameTheByte) {
    const std::string file = path("valid.vtk");
    kdet::write_vtk(unit_tets(), file, {kdet::VtkVersion::v4_2, true});
    const std::string valid = read_bytes(file);
    const std::size_t points = after(valid, "POINTS 5 double\n");

    const std::string cut = write("cut.vtk", valid.substr(0, points + 100));
    expect_error([&] { kdet::read_vtk(cut); }, at_byte(cut, points), "5 points need 120 bytes, only 100 left");

    std::string nan = valid;
    for (std::size_t k = 0; k < 8; ++k)
        nan[points + 8 + k] = k == 0 ? '\x7f' : (k == 1 ? '\xf8' : '\0'); // big-endian NaN
    const std::string nan_file = write("nan.vtk", nan);
    expect_error([&] { kdet::read_vtk(nan_file); }, at_byte(nan_file, points + 8), "coordinate nan is not finite");

    const std::size_t cells = after(valid, "CELLS 2 10\n");
    std::string range = valid;
    range[cells + 4 + 3] = 5; // the first cell's first point, low byte
    const std::string range_file = write("range.vtk", range);
    expect_error([&] { kdet::read_vtk(range_file); }, at_byte(range_file, cells + 4),
                 "vertex index 5 out of range [0, 4]");

    std::string absurd = valid;
    absurd.replace(absurd.find("CELLS 2 10"), 10, "CELLS 2 99");
    const std::string absurd_file = write("absurd.vtk", absurd);
    expect_error([&] { kdet::read_vtk(absurd_file); }, at_byte(absurd_file, cells),
                 "99 cell list values need 396 bytes");

    const std::string v51 = path("v51.vtk");
    kdet::write_vtk(unit_tets(), v51, {kdet::VtkVersion::v5_1, true});
    std::string offsets = read_bytes(v51);
    const std::size_t first_offset = after(offsets, "OFFSETS vtktypeint64\n");
    offsets[first_offset + 7] = 1;
    const std::string offsets_file = write("offsets.vtk", offsets);
    expect_error([&] { kdet::read_vtk(offsets_file); }, at_byte(offsets_file, first_offset),
                 "the first offset must be 0, found 1");
}

TEST_F(Formats, VtkTextErrorsNameTheLine) {
    const std::string head = "# vtk DataFile Version 4.2\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                             "POINTS 5 double\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n";
    const std::string version = write("version.vtk", "# vtk DataFile Version 6.0\n");
    expect_error([&] { kdet::read_vtk(version); }, at_line(version, 1), "unsupported VTK version '6.0'");
    const std::string grid = write("grid.vtk", "# vtk DataFile Version 4.2\nt\nASCII\nDATASET POLYDATA\n");
    expect_error([&] { kdet::read_vtk(grid); }, at_line(grid, 4), "only UNSTRUCTURED_GRID datasets are read");
    const std::string range = write("range.vtk", head + "CELLS 1 5\n4 0 1 2 5\nCELL_TYPES 1\n10\n");
    expect_error([&] { kdet::read_vtk(range); }, at_line(range, 12), "vertex index 5 out of range [0, 4]");
    const std::string nan = write("nan.vtk", "# vtk DataFile Version 4.2\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                                             "POINTS 1 double\n0 nan 0\n");
    expect_error([&] { kdet::read_vtk(nan); }, at_line(nan, 6), "coordinate 'nan' is not finite");
    const std::string types = write("types.vtk", head + "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 2\n10\n10\n");
    expect_error([&] { kdet::read_vtk(types); }, at_line(types, 13), "CELL_TYPES lists 2 cells, CELLS holds 1");
    const std::string size = write("size.vtk", head + "CELLS 1 5\n3 0 1 2 3\nCELL_TYPES 1\n10\n");
    expect_error([&] { kdet::read_vtk(size); }, at_line(size, 12), "cells hold 4 values, the header announces 5");
    const std::string short_tet = write("short.vtk", head + "CELLS 1 4\n3 0 1 2\nCELL_TYPES 1\n10\n");
    expect_error([&] { kdet::read_vtk(short_tet); }, at_line(short_tet, 14),
                 "cell 0 of type 10 has 3 points, expected 4");
    const std::string absurd = write("absurd.vtk", head + "CELLS 1000000000000 2000000000000\n4 0 1 2 3\n");
    expect_error([&] { kdet::read_vtk(absurd); }, at_line(absurd, 12), "file ends early: expected a cell point count");
    const std::string no_tets = write("no_tets.vtk", head + "CELLS 1 4\n3 0 1 2\nCELL_TYPES 1\n5\n");
    expect_error([&] { kdet::read_vtk(no_tets); }, at_line(no_tets, 14), "no tetrahedra");
}

// ---------------------------------------------------------------------------------------------
// Surfaces

struct SurfaceCounts {
    const char* file;
    std::size_t vertices;
    std::size_t triangles;
};

// Vertex counts from the models README; triangle counts from the files (every face is a triangle).
const SurfaceCounts real_surfaces[] = {
    {"armadillo.obj", 43243, 86482}, {"stanford-bunny.obj", 35947, 69451}, {"max-planck.obj", 5272, 10540},
    {"bunny.off", 3485, 6966},       {"happy-buddha.off", 13295, 26999},
};

TEST_F(Formats, SurfacesReadTheRealModels) {
    kdet::test::use_default_data_dir();
    for (const SurfaceCounts& model : real_surfaces) {
        SCOPED_TRACE(model.file);
        const kdet::TriangleMesh mesh = kdet::read_surface(kdet::data_path(model.file));
        EXPECT_EQ(mesh.num_vertices(), model.vertices);
        EXPECT_EQ(mesh.num_triangles(), model.triangles);
        EXPECT_EQ(mesh.triangles.size() % 3, 0u);
        ASSERT_FALSE(mesh.triangles.empty());
        EXPECT_LT(*std::max_element(mesh.triangles.begin(), mesh.triangles.end()), mesh.num_vertices());
        for (const double value : mesh.positions) ASSERT_TRUE(std::isfinite(value));
    }
}

TEST_F(Formats, SurfaceBunnyOffFirstEntries) {
    kdet::test::use_default_data_dir();
    const kdet::TriangleMesh mesh = kdet::read_surface(kdet::data_path("bunny.off"));
    // From the file: first vertex "-0.0260146 0.112578 0.0363871", last face "3 3086 3151 3085" (0-based).
    ASSERT_GE(mesh.positions.size(), 3u);
    EXPECT_EQ(mesh.positions[0], -0.0260146);
    EXPECT_EQ(mesh.positions[1], 0.112578);
    EXPECT_EQ(mesh.positions[2], 0.0363871);
    ASSERT_EQ(mesh.triangles.size(), 3u * 6966u);
    EXPECT_EQ(std::vector<std::uint32_t>(mesh.triangles.end() - 3, mesh.triangles.end()),
              (std::vector<std::uint32_t>{3086, 3151, 3085}));
}

/// A unit square as two triangles (0 1 2) and (0 2 3), what every hand-written surface below holds.
kdet::TriangleMesh unit_square() {
    kdet::TriangleMesh mesh;
    mesh.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    mesh.triangles = {0, 1, 2, 0, 2, 3};
    return mesh;
}

void expect_equal(const kdet::TriangleMesh& actual, const kdet::TriangleMesh& expected) {
    EXPECT_EQ(actual.positions, expected.positions);
    EXPECT_EQ(actual.triangles, expected.triangles);
}

TEST_F(Formats, ObjPolygonsSlashFormsAndNegativeIndices) {
    expect_equal(kdet::read_surface(write("quad.OBJ", square_obj)), unit_square());
    const std::string negative = write("negative.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf -3 -2 -1\nv 0 1 0\nf 1 -2 -1\n");
    expect_equal(kdet::read_surface(negative), unit_square());
}

TEST_F(Formats, OffPolygonsAndColours) {
    expect_equal(kdet::read_surface(write("quad.off", square_off)), unit_square());
    const std::string header_line = write("one_line.off", "OFF 4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
    expect_equal(kdet::read_surface(header_line), unit_square());
}

TEST_F(Formats, StlAsciiAndBinaryMergeVertices) {
    expect_equal(kdet::read_surface(write("ascii.stl", square_stl)), unit_square());
    expect_equal(kdet::read_surface(write("binary.stl", square_binary_stl())), unit_square());
}

TEST_F(Formats, PlyAsciiAndBothBinaryOrders) {
    const std::string ascii = write("ascii.ply", square_ply_header("ascii") + square_ply_ascii_body);
    expect_equal(kdet::read_surface(ascii), unit_square());
    const std::string little =
        write("little.ply", square_ply_header("binary_little_endian") + square_ply_binary_body(false));
    expect_equal(kdet::read_surface(little), unit_square());
    const std::string big = write("big.ply", square_ply_header("binary_big_endian") + square_ply_binary_body(true));
    expect_equal(kdet::read_surface(big), unit_square());
}

TEST_F(Formats, PlyElementWithoutPropertiesIsSkippedWhateverItsCount) {
    // Found by the fuzzer: stepping through 10^12 empty records took minutes.
    std::string header = square_ply_header("ascii");
    header.insert(header.find("end_header"), "element nothing 1000000000000\n");
    expect_equal(kdet::read_surface(write("empty_element.ply", header + square_ply_ascii_body)), unit_square());
}

TEST_F(Formats, SurfaceErrorsNameLineOrByte) {
    const std::string unknown = write("mesh.xyz", "");
    EXPECT_EQ(error_message([&] { kdet::read_surface(unknown); }),
              unknown + ": unsupported surface format '.xyz'; supported: .obj, .off, .stl, .ply");

    const std::string obj_range = write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    expect_error([&] { kdet::read_surface(obj_range); }, at_line(obj_range, 4), "vertex index 4 out of range [1, 3]");
    const std::string obj_negative = write("negative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n");
    expect_error([&] { kdet::read_surface(obj_negative); }, at_line(obj_negative, 4),
                 "reaches before the first vertex");
    const std::string obj_nan = write("nan.obj", "v 0 0 0\nv 1 nan 0\n");
    expect_error([&] { kdet::read_surface(obj_nan); }, at_line(obj_nan, 2), "coordinate 'nan' is not finite");
    const std::string obj_edge = write("edge.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n");
    expect_error([&] { kdet::read_surface(obj_edge); }, at_line(obj_edge, 3), "face has 2 vertices, at least 3 needed");
    const std::string obj_empty = write("empty.obj", "v 0 0 0\n");
    expect_error([&] { kdet::read_surface(obj_empty); }, at_line(obj_empty, 1), "no triangles");

    const std::string off_cut = write("cut.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    expect_error([&] { kdet::read_surface(off_cut); }, at_line(off_cut, 6), "expected 2 faces, found 1");
    const std::string off_range = write("range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
    expect_error([&] { kdet::read_surface(off_range); }, at_line(off_range, 6), "vertex index 3 out of range [0, 2]");
    const std::string off_absurd = write("absurd.off", "OFF\n3 1000000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    expect_error([&] { kdet::read_surface(off_absurd); }, at_line(off_absurd, 6),
                 "expected 1000000000000 faces, found 1");

    std::string stl_text = square_stl;
    stl_text.replace(stl_text.find("endloop"), 7, "vertex 2 2 2");
    const std::string stl_four = write("four.stl", stl_text);
    expect_error([&] { kdet::read_surface(stl_four); }, at_line(stl_four, 7), "expected endloop, found 'vertex'");
    const std::string stl_cut = write("cut.stl", square_binary_stl().substr(0, 84 + 50 + 20));
    expect_error([&] { kdet::read_surface(stl_cut); }, at_byte(stl_cut, 84),
                 "2 triangles need 100 bytes, only 70 left");
    std::string stl_nan = square_binary_stl();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(&stl_nan[84 + 50 + 12 + 4], &nan, 4); // y of the second triangle's first corner
    const std::string stl_nan_file = write("nan.stl", stl_nan);
    expect_error([&] { kdet::read_surface(stl_nan_file); }, at_byte(stl_nan_file, 84 + 50 + 16),
                 "coordinate nan is not finite");

    const std::string ply_cut =
        write("cut.ply", square_ply_header("binary_little_endian") + square_ply_binary_body(false).substr(0, 30));
    const std::size_t body = square_ply_header("binary_little_endian").size();
    expect_error([&] { kdet::read_surface(ply_cut); }, at_byte(ply_cut, body),
                 "4 vertex records need 68 bytes, only 30 left");
    std::string ply_range = square_ply_binary_body(true);
    ply_range[4 * 17 + 1 + 3] = 9; // the first index, big-endian low byte
    const std::string ply_range_file = write("range.ply", square_ply_header("binary_big_endian") + ply_range);
    const std::size_t big_body = square_ply_header("binary_big_endian").size();
    expect_error([&] { kdet::read_surface(ply_range_file); }, at_byte(ply_range_file, big_body + 4 * 17 + 1),
                 "vertex index 9 out of range [0, 3]");
    const std::string ply_no_z = write("no_z.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                                   "property float y\nend_header\n0 0\n");
    expect_error([&] { kdet::read_surface(ply_no_z); }, at_line(ply_no_z, 3), "element vertex has no property z");
    const std::string ply_type = write("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty real x\n");
    expect_error([&] { kdet::read_surface(ply_type); }, at_line(ply_type, 4), "unknown property type 'real'");
}

} // namespace
