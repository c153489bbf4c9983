// Tests of the mesh reading/writing module: the real MEDIT models, round trips, and one test per kind
// of bad input, each checking that the error names the file and the offending line.

#include "test_support.hpp"

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <unistd.h>

namespace {

namespace fs = std::filesystem;
using kdet::test::error_message;

/// A fresh folder for the files a test writes, removed with everything in it at the end of the test.
class TempDir {
public:
    TempDir() {
        static std::atomic<int> counter{0};
        path_ =
            fs::temp_directory_path() / ("kdet_test_io_" + std::to_string(getpid()) + "_" + std::to_string(counter++));
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ignored;
        fs::remove_all(path_, ignored);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    /// Writes @p content to file @p name in this folder and returns its path.
    std::string write(const std::string& name, const std::string& content) const {
        const std::string file = file_path(name);
        std::ofstream(file, std::ios::binary) << content;
        return file;
    }

    /// Writes the TetGen pair `name.node` + `name.ele` and returns the path of their stem.
    std::string write_tetgen(const std::string& name, const std::string& node, const std::string& ele) const {
        write(name + ".node", node);
        write(name + ".ele", ele);
        return file_path(name);
    }

    std::string file_path(const std::string& name) const { return (path_ / name).string(); }

private:
    fs::path path_;
};


/// Checks that the error of @p action starts with "file:line: " and contains @p what.
void expect_file_error(const std::function<void()>& action, const std::string& file, int line,
                       const std::string& what) {
    const std::string message = error_message(action);
    const std::string location = file + ":" + std::to_string(line) + ": ";
    EXPECT_EQ(message.rfind(location, 0), 0u) << "expected it to start with '" << location << "': " << message;
    EXPECT_NE(message.find(what), std::string::npos) << "expected it to contain '" << what << "': " << message;
}

/// Two tetrahedra sharing the face (1, 2, 3), with coordinates that have no short decimal form.
kdet::TetMesh two_tets() {
    kdet::TetMesh mesh;
    mesh.positions = {0.0, 0.0, 0.0, 1.0 / 3.0, 0.0,          0.0,         0.0,   0.1,
                      0.0, 0.0, 0.0, 2.0 / 7.0, 1.0e-3 / 3.0, 1.0e5 / 7.0, 3.0e-7};
    mesh.tets = {0, 1, 2, 3, 1, 2, 3, 4};
    return mesh;
}

void expect_same_mesh(const kdet::TetMesh& actual, const kdet::TetMesh& expected) {
    ASSERT_EQ(actual.positions.size(), expected.positions.size());
    EXPECT_EQ(actual.tets, expected.tets);
    for (std::size_t i = 0; i < expected.positions.size(); ++i) {
        EXPECT_NEAR(actual.positions[i], expected.positions[i], 1e-12 * std::abs(expected.positions[i]))
            << "value " << i;
    }
}

void expect_indices_in_range(const kdet::TetMesh& mesh) {
    for (std::uint32_t corner : mesh.tets) ASSERT_LT(corner, mesh.num_vertices());
}

/// Two tetrahedra of the unit cube's corner, sharing the face (1, 2, 3).
kdet::TetMesh two_unit_tets() {
    kdet::TetMesh mesh;
    mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    mesh.tets = {0, 1, 2, 3, 1, 2, 3, 4};
    return mesh;
}

// The files of two_unit_tets() in both formats, by hand: the readers are tested apart from the writers.
const char* const two_tets_medit = "MeshVersionFormatted 1\n"
                                   "Dimension 3\n"
                                   "Vertices\n5\n"
                                   "0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n1 1 1 0\n"
                                   "Tetrahedra\n2\n"
                                   "1 2 3 4 0\n2 3 4 5 0\n"
                                   "End\n";

/// two_tets_medit with its first @p from replaced by @p to.
std::string two_tets_medit_with(const std::string& from, const std::string& to) {
    std::string text = two_tets_medit;
    const std::size_t at = text.find(from);
    if (at == std::string::npos) {
        ADD_FAILURE() << "'" << from << "' is not in two_tets_medit";
        return text;
    }
    return text.replace(at, from.size(), to);
}

const char* const two_tets_node_0_based = "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 1\n";
const char* const two_tets_ele_0_based = "2 4 0\n0 0 1 2 3\n1 1 2 3 4\n";

// ---------------------------------------------------------------------------------------------
// Real models

struct ModelCounts {
    const char* file;
    std::size_t vertices;
    std::size_t tets;
};

// Counted from the files' own headers and section lengths (grep -n of the section keywords).
const ModelCounts real_models[] = {
    {"bunny.mesh", 5433, 34055},
    {"hand.mesh", 7234, 29998},
    {"octopus-low.mesh", 452, 1140},
};

TEST(IoMedit, ReadsTheRealModels) {
    kdet::test::use_default_data_dir();
    for (const ModelCounts& model : real_models) {
        SCOPED_TRACE(model.file);
        const kdet::TetMesh mesh = kdet::read_tet_mesh(kdet::data_path(model.file));
        EXPECT_EQ(mesh.num_vertices(), model.vertices);
        EXPECT_EQ(mesh.num_tets(), model.tets);
        expect_indices_in_range(mesh);
    }
}

TEST(IoMedit, BunnyFirstAndLastEntriesAreRead) {
    kdet::test::use_default_data_dir();
    const kdet::TetMesh mesh = kdet::read_medit(kdet::data_path("bunny.mesh"));
    // From the file: first vertex "-0.0260146 0.112578 0.0363871 0", first tetrahedron
    // "2927 2983 2982 2889 0", last tetrahedron "3887 5115 5409 5432 0" (1-based).
    ASSERT_GE(mesh.positions.size(), 3u);
    EXPECT_EQ(mesh.positions[0], -0.0260146);
    EXPECT_EQ(mesh.positions[1], 0.112578);
    EXPECT_EQ(mesh.positions[2], 0.0363871);
    ASSERT_EQ(mesh.tets.size(), 4u * 34055u);
    EXPECT_EQ(std::vector<std::uint32_t>(mesh.tets.begin(), mesh.tets.begin() + 4),
              (std::vector<std::uint32_t>{2926, 2982, 2981, 2888}));
    EXPECT_EQ(std::vector<std::uint32_t>(mesh.tets.end() - 4, mesh.tets.end()),
              (std::vector<std::uint32_t>{3886, 5114, 5408, 5431}));
}

TEST(IoMedit, ReadsHandWrittenFile) {
    TempDir dir;
    expect_same_mesh(kdet::read_medit(dir.write("two.mesh", two_tets_medit)), two_unit_tets());
}

TEST(IoMedit, SkipsOtherSectionsCommentsAndSpreadTokens) {
    TempDir dir;
    const std::string path = dir.write("sections.mesh", "# a comment line\n"
                                                        "MeshVersionFormatted 2 # a trailing comment\n"
                                                        "Dimension\n3\n"
                                                        "Vertices 5\n"
                                                        "0 0 0 0\n1 0 0\n0\n0 1 0 0 0 0 1 0\n1 1 1 0\n"
                                                        "Corners 2 1 2\n"
                                                        "Ridges\n1\n3\n"
                                                        "Edges\n2\n1 2 0\n2 3 0\n"
                                                        "Triangles\n1\n1 2 3 0\n"
                                                        "Normals\n1\n0.5 0.5 0.5\n"
                                                        "NormalAtVertices\n1\n1 1\n"
                                                        "Tetrahedra\n2\n1 2 3 4 0\n2 3\n4 5 0\n"
                                                        "Edges\n0\n"
                                                        "End\n"
                                                        "anything after End is not read\n");
    expect_same_mesh(kdet::read_medit(path), two_unit_tets());
}

TEST(IoMedit, ToleratesMissingEnd) {
    TempDir dir;
    expect_same_mesh(kdet::read_medit(dir.write("no_end.mesh", two_tets_medit_with("End\n", ""))), two_unit_tets());
}

// ---------------------------------------------------------------------------------------------
// TetGen

TEST(IoTetgen, ReadsZeroBasedFiles) {
    TempDir dir;
    dir.write("zero.node", two_tets_node_0_based);
    dir.write("zero.ele", two_tets_ele_0_based);
    expect_same_mesh(kdet::read_tetgen(dir.file_path("zero")), two_unit_tets());
}

TEST(IoTetgen, ReadsOneBasedFiles) {
    TempDir dir;
    dir.write("one.node", "5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n");
    dir.write("one.ele", "2 4 0\n1 1 2 3 4\n2 2 3 4 5\n");
    expect_same_mesh(kdet::read_tetgen(dir.file_path("one")), two_unit_tets());
}

TEST(IoTetgen, AcceptsTheThreePathSpellings) {
    TempDir dir;
    dir.write("spell.node", two_tets_node_0_based);
    dir.write("spell.ele", two_tets_ele_0_based);
    for (const std::string suffix : {"", ".node", ".ele"}) {
        SCOPED_TRACE("suffix '" + suffix + "'");
        expect_same_mesh(kdet::read_tetgen(dir.file_path("spell" + suffix)), two_unit_tets());
        expect_same_mesh(kdet::read_tet_mesh(dir.file_path("spell" + suffix)), two_unit_tets());
    }
}

TEST(IoTetgen, ReadsAttributesMarkersCommentsAndTenNodeTets) {
    TempDir dir;
    dir.write("rich.node", "# points with two attributes and a boundary marker\n"
                           "\n"
                           "5 3 2 1  # header\n"
                           "0 0 0 0  7.5 -1 1\n"
                           "1 1 0 0  7.5 -1 0\n"
                           "2 0 1 0  7.5 -1 1  # corner\n"
                           "\n"
                           "3 0 0 1  7.5 -1 0\n"
                           "4 1 1 1  7.5 -1 1\n");
    // 10-node tetrahedra: only the first four nodes are kept.
    dir.write("rich.ele", "2 10 1\n"
                          "0 0 1 2 3  4 4 4 4 4 4  2.5\n"
                          "1 1 2 3 4  0 0 0 0 0 0  2.5\n");
    expect_same_mesh(kdet::read_tetgen(dir.file_path("rich")), two_unit_tets());
}

TEST(IoTetgen, AcceptsHeadersWithDefaultedCounts) {
    TempDir dir;
    dir.write("short.node", "5\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 1\n");
    dir.write("short.ele", "2\n0 0 1 2 3\n1 1 2 3 4\n");
    expect_same_mesh(kdet::read_tetgen(dir.file_path("short")), two_unit_tets());
}

// ---------------------------------------------------------------------------------------------
// Round trips

TEST(IoRoundTrip, TetgenSmallMesh) {
    TempDir dir;
    const std::string stem = dir.file_path("small");
    kdet::write_tetgen(two_tets(), stem);
    expect_same_mesh(kdet::read_tetgen(stem), two_tets());
}

TEST(IoRoundTrip, MeditSmallMesh) {
    TempDir dir;
    const std::string path = dir.file_path("small.mesh");
    kdet::write_medit(two_tets(), path);
    expect_same_mesh(kdet::read_medit(path), two_tets());
}

TEST(IoRoundTrip, BunnyThroughBothFormats) {
    kdet::test::use_default_data_dir();
    TempDir dir;
    const kdet::TetMesh bunny = kdet::read_medit(kdet::data_path("bunny.mesh"));
    kdet::write_tetgen(bunny, dir.file_path("bunny"));
    expect_same_mesh(kdet::read_tet_mesh(dir.file_path("bunny.ele")), bunny);
    kdet::write_medit(bunny, dir.file_path("bunny.mesh"));
    expect_same_mesh(kdet::read_tet_mesh(dir.file_path("bunny.mesh")), bunny);
}

TEST(IoRoundTrip, WriterChosenByExtensionReadsBack) {
    TempDir dir;
    // The single-file formats in any case, as read_surface takes its extensions.
    for (const char* name : {"small.mesh", "small.msh", "small.vtk", "small", "small2.node", "small3.ele", "UPPER.MESH",
                             "Mixed.Msh", "UPPER.VTK"})
        for (const bool binary : {false, true}) {
            const std::string path = dir.file_path(name);
            kdet::write_tet_mesh(two_tets(), path, kdet::WriteOptions{binary});
            expect_same_mesh(kdet::read_tet_mesh(path), two_tets());
        }
    // The binary flag reaches the formats that have a binary form.
    kdet::write_tet_mesh(two_tets(), dir.file_path("ascii.msh"));
    kdet::write_tet_mesh(two_tets(), dir.file_path("binary.msh"), kdet::WriteOptions{true});
    EXPECT_NE(fs::file_size(dir.file_path("ascii.msh")), fs::file_size(dir.file_path("binary.msh")));
    const std::string message = error_message([&] { kdet::write_tet_mesh(two_tets(), dir.file_path("out.obj")); });
    EXPECT_EQ(message.rfind(dir.file_path("out.obj") + ": cannot write mesh format", 0), 0u) << message;
    EXPECT_FALSE(fs::exists(dir.file_path("out.obj")));
}

TEST(IoRoundTrip, WritersRefuseInvalidMeshes) {
    TempDir dir;
    kdet::TetMesh mesh = two_tets();
    mesh.tets[7] = 9;
    const std::string path = dir.file_path("bad.mesh");
    EXPECT_EQ(error_message([&] { kdet::write_medit(mesh, path); }),
              path + ": tet 1: vertex index 9 out of range [0, 4]");
    EXPECT_FALSE(fs::exists(path));
}

TEST(IoRoundTrip, WriterReportsUnwritablePath) {
    TempDir dir;
    const std::string path = dir.file_path("no_such_folder/out.mesh");
    EXPECT_EQ(error_message([&] { kdet::write_medit(two_tets(), path); }), path + ": cannot open file for writing");
}

// ---------------------------------------------------------------------------------------------
// Bad input: every error names the file and the line

TEST(IoErrors, MissingFile) {
    TempDir dir;
    const std::string path = dir.file_path("absent.mesh");
    EXPECT_EQ(error_message([&] { kdet::read_tet_mesh(path); }), path + ": cannot open file");
    EXPECT_EQ(error_message([&] { kdet::read_tetgen(dir.file_path("absent")); }),
              dir.file_path("absent.node") + ": cannot open file");
}

TEST(IoErrors, MissingEleForNode) {
    TempDir dir;
    dir.write("lonely.node", two_tets_node_0_based);
    EXPECT_EQ(error_message([&] { kdet::read_tetgen(dir.file_path("lonely.node")); }),
              dir.file_path("lonely.ele") + ": cannot open file");
}

TEST(IoErrors, EmptyFile) {
    TempDir dir;
    const std::string mesh_path = dir.write("empty.mesh", "");
    expect_file_error([&] { kdet::read_medit(mesh_path); }, mesh_path, 1, "empty file");
    const std::string node_path = dir.write("empty.node", "# only a comment\n\n");
    expect_file_error([&] { kdet::read_tetgen(node_path); }, node_path, 1, "empty file");
}

TEST(IoErrors, TruncatedEle) {
    TempDir dir;
    const std::string ele = dir.write_tetgen("cut", two_tets_node_0_based, "3 4 0\n0 0 1 2 3\n1 1 2 3 4\n\n") + ".ele";
    expect_file_error([&] { kdet::read_tetgen(ele); }, ele, 3, "expected 3 tetrahedra, found 2");
}

TEST(IoErrors, TruncatedEleCutMidLine) {
    TempDir dir;
    const std::string ele = dir.write_tetgen("cut", two_tets_node_0_based, "2 4 0\n0 0 1 2 3\n1 1 2") + ".ele";
    expect_file_error([&] { kdet::read_tetgen(ele); }, ele, 3, "expected 2 tetrahedra, found 1");
}

TEST(IoErrors, TruncatedNode) {
    TempDir dir;
    const std::string node =
        dir.write_tetgen("cut", "6 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 1\n", two_tets_ele_0_based) +
        ".node";
    expect_file_error([&] { kdet::read_tetgen(node); }, node, 6, "expected 6 points, found 5");
}

TEST(IoErrors, TruncatedMeditAtEndOfFile) {
    TempDir dir;
    const std::string path = dir.write("cut.mesh", two_tets_medit_with("2 3 4 5 0\nEnd\n", ""));
    expect_file_error([&] { kdet::read_medit(path); }, path, 12, "expected 2 tetrahedra, found 1");
}

TEST(IoErrors, TruncatedMeditSectionBeforeNextKeyword) {
    TempDir dir;
    const std::string path = dir.write("short_section.mesh", "MeshVersionFormatted 1\nDimension 3\nVertices\n6\n"
                                                             "0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n1 1 1 0\n"
                                                             "Tetrahedra\n1\n1 2 3 4 0\nEnd\n");
    expect_file_error([&] { kdet::read_medit(path); }, path, 10, "expected 6 vertices, found 5 before 'Tetrahedra'");
}

TEST(IoErrors, TruncatedRealModel) {
    kdet::test::use_default_data_dir();
    TempDir dir;
    // The first 20000 lines of bunny.mesh: its tetrahedra start at line 12408, so 7593 of them remain.
    std::ifstream in(kdet::data_path("bunny.mesh"));
    std::ofstream out(dir.file_path("bunny_cut.mesh"));
    std::string line;
    for (int i = 0; i < 20000 && std::getline(in, line); ++i) out << line << '\n';
    out.close();
    const std::string path = dir.file_path("bunny_cut.mesh");
    expect_file_error([&] { kdet::read_tet_mesh(path); }, path, 20000, "expected 34055 tetrahedra, found 7593");
}

TEST(IoErrors, NonNumericTokens) {
    TempDir dir;
    const std::string coordinate = dir.write("garbage.mesh", two_tets_medit_with("1 1 1 0", "1 1.0abc 1 0"));
    expect_file_error([&] { kdet::read_medit(coordinate); }, coordinate, 9, "expected a coordinate, found '1.0abc'");

    const std::string ele =
        dir.write_tetgen("garbage", two_tets_node_0_based, "2 4 0\n0 0 1 2 3\n1 1 2 x3 4\n") + ".ele";
    expect_file_error([&] { kdet::read_tetgen(ele); }, ele, 3, "expected a vertex index, found 'x3'");

    const std::string count = dir.write("count.mesh", "MeshVersionFormatted 1\nDimension 3\nVertices\nfive\n");
    expect_file_error([&] { kdet::read_medit(count); }, count, 4, "expected a vertex count, found 'five'");
}

TEST(IoErrors, UnknownMeditKeyword) {
    TempDir dir;
    const std::string path = dir.write("typo.mesh", two_tets_medit_with("Tetrahedra", "Tetrahedrons"));
    expect_file_error([&] { kdet::read_medit(path); }, path, 10, "unknown keyword 'Tetrahedrons'");
}

TEST(IoErrors, MeditSectionsOutOfPlace) {
    TempDir dir;
    const std::string no_dimension = dir.write("no_dimension.mesh", "MeshVersionFormatted 1\nVertices\n0\n");
    expect_file_error([&] { kdet::read_medit(no_dimension); }, no_dimension, 2, "Vertices before Dimension");

    const std::string tets_first = dir.write("tets_first.mesh", "Dimension 3\nTetrahedra\n1\n1 2 3 4 0\n");
    expect_file_error([&] { kdet::read_medit(tets_first); }, tets_first, 2, "Tetrahedra before Vertices");

    const std::string twice = dir.write("twice.mesh", two_tets_medit_with("End", "Vertices\n1\n0 0 0 0\nEnd"));
    expect_file_error([&] { kdet::read_medit(twice); }, twice, 14, "second Vertices section");

    const std::string no_value = dir.write("no_value.mesh", "MeshVersionFormatted 1\n\nDimension\n\n");
    expect_file_error([&] { kdet::read_medit(no_value); }, no_value, 3, "file ends after Dimension");
}

TEST(IoErrors, MoreRecordsThanTheHeaderAnnounces) {
    TempDir dir;
    const std::string node =
        dir.write_tetgen("extra", std::string(two_tets_node_0_based) + "5 2 2 2\n", two_tets_ele_0_based) + ".node";
    expect_file_error([&] { kdet::read_tetgen(node); }, node, 7, "more data after the 5 points");

    const std::string ele = dir.write_tetgen("extra_tet", two_tets_node_0_based,
                                             std::string(two_tets_ele_0_based) + "\n# fine\n2 0 1 2 4\n") +
                            ".ele";
    expect_file_error([&] { kdet::read_tetgen(ele); }, ele, 6, "more data after the 2 tetrahedra");
}

TEST(IoErrors, WrongDimension) {
    TempDir dir;
    const std::string mesh = dir.write("flat.mesh", "MeshVersionFormatted 1\nDimension\n2\nVertices\n0\nEnd\n");
    expect_file_error([&] { kdet::read_medit(mesh); }, mesh, 3, "dimension must be 3, found 2");

    const std::string node =
        dir.write_tetgen("flat", "\n3 2 0 0\n0 0 0\n1 1 0\n2 0 1\n", two_tets_ele_0_based) + ".node";
    expect_file_error([&] { kdet::read_tetgen(node); }, node, 2, "dimension must be 3, found 2");
}

TEST(IoErrors, WrongNodesPerTet) {
    TempDir dir;
    const std::string ele =
        dir.write_tetgen("wide", two_tets_node_0_based, "# five nodes\n2 5 0\n0 0 1 2 3 4\n1 1 2 3 4 0\n") + ".ele";
    expect_file_error([&] { kdet::read_tetgen(ele); }, ele, 2, "nodes per tetrahedron must be 4 or 10, found 5");
}

TEST(IoErrors, WrongFieldCountOnALine) {
    TempDir dir;
    const std::string ele = dir.write_tetgen("fields", two_tets_node_0_based, "2 4 0\n0 0 1 2\n1 1 2 3 4\n") + ".ele";
    expect_file_error([&] { kdet::read_tetgen(ele); }, ele, 2, "expected 5 fields");
}

TEST(IoErrors, VertexIndexOutOfRange) {
    TempDir dir;
    const std::string high = dir.write("high.mesh", two_tets_medit_with("2 3 4 5 0", "2 3 4 6 0"));
    expect_file_error([&] { kdet::read_medit(high); }, high, 13, "vertex index 6 out of range [1, 5]");

    const std::string negative = dir.write("negative.mesh", two_tets_medit_with("2 3 4 5 0", "2 3 -4 5 0"));
    expect_file_error([&] { kdet::read_medit(negative); }, negative, 13, "vertex index -4 out of range [1, 5]");

    // A 1-based MEDIT index 0 is out of range too; in 0-based TetGen files 5 is one past the end.
    const std::string zero = dir.write("zero.mesh", two_tets_medit_with("1 2 3 4 0", "0 2 3 4 0"));
    expect_file_error([&] { kdet::read_medit(zero); }, zero, 12, "vertex index 0 out of range [1, 5]");

    const std::string ele = dir.write_tetgen("past", two_tets_node_0_based, "2 4 0\n0 0 1 2 3\n1 1 2 3 5\n") + ".ele";
    expect_file_error([&] { kdet::read_tetgen(ele); }, ele, 3, "vertex index 5 out of range [0, 4]");
}

TEST(IoErrors, VertexIndexTooLargeForAnyInteger) {
    TempDir dir;
    const std::string path =
        dir.write("huge_index.mesh", two_tets_medit_with("2 3 4 5 0", "2 3 4 99999999999999999999999 0"));
    expect_file_error([&] { kdet::read_medit(path); }, path, 13,
                      "expected a vertex index, found '99999999999999999999999'");
}

TEST(IoErrors, NonFiniteCoordinates) {
    TempDir dir;
    int file_number = 0;
    for (const std::string value : {"nan", "inf", "-inf", "NaN", "infinity", "1e999"}) {
        SCOPED_TRACE(value);
        const std::string path = dir.write("nonfinite" + std::to_string(file_number++) + ".mesh",
                                           two_tets_medit_with("0 0 1 0", "0 0 " + value + " 0"));
        expect_file_error([&] { kdet::read_medit(path); }, path, 8, "'" + value + "'");
    }
    const std::string node =
        dir.write_tetgen("nan", "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 nan 0\n3 0 0 1\n4 1 1 1\n", two_tets_ele_0_based) +
        ".node";
    expect_file_error([&] { kdet::read_tetgen(node); }, node, 4, "coordinate 'nan' is not finite");
}

TEST(IoErrors, CoordinatesBeyondFloatRange) {
    // Finite doubles that float32 cannot hold: refused where read, not later as a zero-volume tet.
    TempDir dir;
    const std::string path = dir.write("huge.mesh", two_tets_medit_with("0 0 1 0", "0 0 1e39 0"));
    expect_file_error([&] { kdet::read_medit(path); }, path, 8,
                      "coordinate '1e39' is beyond float range (|x| <= 3.4e38: positions are float32)");
    // The largest float itself is accepted.
    const std::string largest = dir.write("largest.mesh", two_tets_medit_with("0 0 1 0", "0 0 3.4028235e38 0"));
    EXPECT_NO_THROW(kdet::read_tet_mesh(largest, kdet::ReadOptions{true}));
}

TEST(IoErrors, DuplicatePointIndex) {
    TempDir dir;
    const std::string node =
        dir.write_tetgen("dup", "5 3 0 0\n0 0 0 0\n1 1 0 0\n1 0 1 0\n3 0 0 1\n4 1 1 1\n", two_tets_ele_0_based) +
        ".node";
    expect_file_error([&] { kdet::read_tetgen(node); }, node, 4, "duplicate point index 1");
}

TEST(IoErrors, NonConsecutivePointIndex) {
    TempDir dir;
    const std::string node =
        dir.write_tetgen("gap", "5 3 0 0\n1 0 0 0\n2 1 0 0\n4 0 1 0\n5 0 0 1\n6 1 1 1\n", two_tets_ele_0_based) +
        ".node";
    expect_file_error([&] { kdet::read_tetgen(node); }, node, 4, "point index 4 out of sequence, expected 3");

    const std::string first = dir.write("first.node", "5 3 0 0\n2 0 0 0\n3 1 0 0\n4 0 1 0\n5 0 0 1\n6 1 1 1\n");
    expect_file_error([&] { kdet::read_tetgen(first); }, first, 2, "first point index must be 0 or 1, found 2");
}

TEST(IoErrors, ZeroVolumeTetrahedron) {
    TempDir dir;
    // Vertex 5 lies in the plane of vertices 2, 3 and 4.
    const std::string path = dir.write("flat_tet.mesh", two_tets_medit_with("1 1 1 0", "0 0.5 0.5 0"));
    expect_file_error([&] { kdet::read_medit(path); }, path, 13, "degenerate tetrahedron: zero volume");

    kdet::ReadOptions allow;
    allow.allow_degenerate = true;
    EXPECT_EQ(kdet::read_medit(path, allow).num_tets(), 2u);
}

TEST(IoErrors, RepeatedVertexIndexIsDegenerate) {
    TempDir dir;
    const std::string ele = dir.write_tetgen("repeat", two_tets_node_0_based, "2 4 0\n0 0 1 2 3\n1 1 2 2 4\n") + ".ele";
    expect_file_error([&] { kdet::read_tetgen(ele); }, ele, 3, "vertex index 2 repeated");

    kdet::ReadOptions allow;
    allow.allow_degenerate = true;
    EXPECT_EQ(kdet::read_tetgen(ele, allow).num_tets(), 2u);
}

TEST(IoErrors, DegeneracyIsRelativeToTheTetSize) {
    TempDir dir;
    // A well-shaped tetrahedron a millionth of a unit across is fine; one squashed to a relative height
    // of 1e-13 is not.
    const std::string tiny = dir.write("tiny.mesh", "MeshVersionFormatted 1\nDimension 3\nVertices\n4\n"
                                                    "0 0 0 0\n1e-6 0 0 0\n0 1e-6 0 0\n0 0 1e-6 0\n"
                                                    "Tetrahedra\n1\n1 2 3 4 0\nEnd\n");
    EXPECT_EQ(kdet::read_medit(tiny).num_tets(), 1u);

    const std::string sliver = dir.write("sliver.mesh", "MeshVersionFormatted 1\nDimension 3\nVertices\n4\n"
                                                        "0 0 0 0\n1 0 0 0\n0 1 0 0\n0.3 0.3 1e-13 0\n"
                                                        "Tetrahedra\n1\n1 2 3 4 0\nEnd\n");
    expect_file_error([&] { kdet::read_medit(sliver); }, sliver, 11, "zero volume");
}

TEST(IoErrors, NoTetrahedra) {
    TempDir dir;
    const std::string empty_section =
        dir.write("none.mesh", "MeshVersionFormatted 1\nDimension 3\nVertices\n4\n"
                               "0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\nTetrahedra\n0\nEnd\n");
    expect_file_error([&] { kdet::read_medit(empty_section); }, empty_section, 10, "no tetrahedra");

    const std::string no_section =
        dir.write("nosection.mesh", "MeshVersionFormatted 1\nDimension 3\nVertices\n4\n"
                                    "0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\nTriangles\n1\n1 2 3 0\nEnd\n");
    expect_file_error([&] { kdet::read_medit(no_section); }, no_section, 12, "no tetrahedra");

    const std::string ele = dir.write_tetgen("none", two_tets_node_0_based, "0 4 0\n") + ".ele";
    expect_file_error([&] { kdet::read_tetgen(ele); }, ele, 1, "no tetrahedra");
}

TEST(ReadPoints, AMeshFileGivesItsVerticesWhateverItsTets) {
    TempDir dir;
    kdet::TetMesh flat;  // one tet with its four corners in a plane
    flat.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    flat.tets = {0, 1, 2, 3};
    const std::string stem = dir.file_path("flat"), medit = dir.file_path("flat.mesh");
    kdet::write_tetgen(flat, stem);
    kdet::write_medit(flat, medit);
    EXPECT_THROW(kdet::read_tet_mesh(medit), kdet::Error);
    for (const std::string& path : {stem, stem + ".node", stem + ".ele", medit})
        EXPECT_EQ(kdet::read_points(path), flat.positions) << path;
    // A name that is neither a file nor a TetGen stem is read as a points file, and cannot be opened.
    EXPECT_NE(error_message([&] { kdet::read_points(dir.file_path("none")); }).find("none: cannot open file"),
              std::string::npos);
}

TEST(IoErrors, AbsurdAndNegativeCounts) {
    TempDir dir;
    // Far more vertices than the file holds: reported as truncation without reserving that much memory.
    const std::string absurd = dir.write("absurd.mesh", two_tets_medit_with("\n5\n", "\n4000000000\n"));
    expect_file_error([&] { kdet::read_medit(absurd); }, absurd, 10, "expected 4000000000 vertices, found 5");

    const std::string ele_absurd =
        dir.write_tetgen("absurd", two_tets_node_0_based, "9000000000000000000 4 0\n0 0 1 2 3\n") + ".ele";
    expect_file_error([&] { kdet::read_tetgen(ele_absurd); }, ele_absurd, 2,
                      "expected 9000000000000000000 tetrahedra, found 1");

    const std::string too_many = dir.write("too_many.node", "5000000000 3 0 0\n0 0 0 0\n");
    expect_file_error([&] { kdet::read_tetgen(too_many); }, too_many, 1, "too many vertices");

    const std::string overflow = dir.write("overflow.node", "99999999999999999999999 3 0 0\n0 0 0 0\n");
    expect_file_error([&] { kdet::read_tetgen(overflow); }, overflow, 1, "expected a point count");

    const std::string negative = dir.write("negative.mesh", "MeshVersionFormatted 1\nDimension 3\nVertices -5\n");
    expect_file_error([&] { kdet::read_medit(negative); }, negative, 3, "must not be negative");

    const std::string attributes = dir.write("attributes.node", "1 3 9000000000000000000 0\n0 0 0 0\n");
    expect_file_error([&] { kdet::read_tetgen(attributes); }, attributes, 1, "does not fit in the file");
}

TEST(IoErrors, UnsupportedExtension) {
    const std::string message = error_message([] { kdet::read_tet_mesh("models/bunny.obj"); });
    EXPECT_EQ(message.rfind("models/bunny.obj: ", 0), 0u) << message;
    EXPECT_NE(message.find(".mesh"), std::string::npos) << message;
    EXPECT_NE(message.find("TetGen"), std::string::npos) << message;
}

// ---------------------------------------------------------------------------------------------
// In-memory meshes and the data folder

TEST(IoValidate, AcceptsAGoodMesh) {
    EXPECT_NO_THROW(kdet::validate_tet_mesh(two_tets(), "two_tets"));
}

TEST(IoValidate, NamesTheTetOrVertex) {
    kdet::TetMesh out_of_range = two_tets();
    out_of_range.tets[5] = 17;
    EXPECT_EQ(error_message([&] { kdet::validate_tet_mesh(out_of_range, "scene"); }),
              "scene: tet 1: vertex index 17 out of range [0, 4]");

    kdet::TetMesh not_finite = two_tets();
    not_finite.positions[3 * 3 + 1] = std::nan("");
    EXPECT_EQ(error_message([&] { kdet::validate_tet_mesh(not_finite, "scene"); }),
              "scene: vertex 3: coordinate y is not finite (nan)");
    not_finite.positions[3 * 3 + 1] = -1e39;
    EXPECT_EQ(error_message([&] { kdet::validate_tet_mesh(not_finite, "scene"); }),
              "scene: vertex 3: coordinate y (-1e+39) is beyond float range (|x| <= 3.4e38: positions are float32)");

    kdet::TetMesh repeated = two_tets();
    repeated.tets[6] = repeated.tets[4];
    EXPECT_EQ(error_message([&] { kdet::validate_tet_mesh(repeated, "scene"); }),
              "scene: tet 1: degenerate tetrahedron: vertex index 1 repeated");
    kdet::ReadOptions allow;
    allow.allow_degenerate = true;
    EXPECT_NO_THROW(kdet::validate_tet_mesh(repeated, "scene", allow));

    kdet::TetMesh partial = two_tets();
    partial.tets.pop_back();
    EXPECT_EQ(error_message([&] { kdet::validate_tet_mesh(partial, "scene"); }),
              "scene: the mesh's tets hold 7 indices, not a multiple of 4");

    EXPECT_EQ(error_message([] { kdet::validate_tet_mesh(kdet::TetMesh{}, "scene"); }), "scene: no tetrahedra");
}

TEST(IoDataPath, UsesTheEnvironmentAndNamesMissingModels) {
    TempDir dir;
    dir.write("model.mesh", two_tets_medit);
    const char* previous = std::getenv("KDET_DATA_DIR");
    const std::string saved = previous != nullptr ? previous : "";

    setenv("KDET_DATA_DIR", dir.file_path("").c_str(), 1);
    EXPECT_EQ(kdet::data_path("model.mesh"), dir.file_path("model.mesh"));
    EXPECT_EQ(error_message([] { kdet::data_path("absent.mesh"); }),
              "model 'absent.mesh' not found in " + dir.file_path("") +
                  " (set KDET_DATA_DIR to the folder holding the models)");

    setenv("KDET_DATA_DIR", "", 1);
    EXPECT_EQ(kdet::data_dir(), "../shared/models");

    if (previous != nullptr) {
        setenv("KDET_DATA_DIR", saved.c_str(), 1);
    } else {
        unsetenv("KDET_DATA_DIR");
    }
}

} // namespace
