// Writes the seed corpus of the fuzzers: small valid files of every format and variant, made by the
// writers (tetrahedral formats) or built in code (surfaces, points), and the scene files (the built-in
// scenes' and one with every statement). Usage: kdet_fuzz_seeds OUTPUT_DIR; it
// creates OUTPUT_DIR/<format>/ with a few files each.

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include "sample_files.hpp"
#include "scene_checks.hpp"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>

namespace {

namespace fs = std::filesystem;

/// Two tetrahedra sharing a face, with coordinates that take all digits of a double.
kdet::TetMesh seed_mesh() {
    kdet::TetMesh mesh;
    mesh.positions = {0, 0, 0, 1.0 / 3.0, 0, 0, 0, 1, 0, 0, 0, 2.0 / 7.0, 1, 1, 1};
    mesh.tets = {0, 1, 2, 3, 1, 2, 3, 4};
    return mesh;
}

std::string read_bytes(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

void write_bytes(const fs::path& file, const std::string& content) { std::ofstream(file, std::ios::binary) << content; }

void write_seeds(const fs::path& root) {
    const kdet::TetMesh mesh = seed_mesh();
    for (const char* format : {"msh", "vtk", "mesh", "node", "obj", "off", "stl", "ply", "xyz", "scene"}) {
        fs::remove_all(root / format);
        fs::create_directories(root / format);
    }
    kdet::write_gmsh(mesh, (root / "msh" / "v22_ascii").string(), {kdet::GmshVersion::v2_2, false});
    kdet::write_gmsh(mesh, (root / "msh" / "v22_binary").string(), {kdet::GmshVersion::v2_2, true});
    kdet::write_gmsh(mesh, (root / "msh" / "v41_ascii").string(), {kdet::GmshVersion::v4_1, false});
    kdet::write_gmsh(mesh, (root / "msh" / "v41_binary").string(), {kdet::GmshVersion::v4_1, true});
    kdet::write_vtk(mesh, (root / "vtk" / "v42_ascii").string(), {kdet::VtkVersion::v4_2, false});
    kdet::write_vtk(mesh, (root / "vtk" / "v42_binary").string(), {kdet::VtkVersion::v4_2, true});
    kdet::write_vtk(mesh, (root / "vtk" / "v51_ascii").string(), {kdet::VtkVersion::v5_1, false});
    kdet::write_vtk(mesh, (root / "vtk" / "v51_binary").string(), {kdet::VtkVersion::v5_1, true});
    kdet::write_medit(mesh, (root / "mesh" / "two_tets").string());
    // TetGen: the .node file, a NUL byte, the .ele file (how the harness splits its input).
    const fs::path stem = root / "node" / "pair";
    kdet::write_tetgen(mesh, stem.string());
    write_bytes(root / "node" / "two_tets",
                read_bytes(stem.string() + ".node") + '\0' + read_bytes(stem.string() + ".ele"));
    fs::remove(stem.string() + ".node");
    fs::remove(stem.string() + ".ele");

    using namespace kdet::test;
    write_bytes(root / "obj" / "square", square_obj);
    write_bytes(root / "off" / "square", square_off);
    write_bytes(root / "stl" / "ascii", square_stl);
    write_bytes(root / "stl" / "binary", square_binary_stl());
    write_bytes(root / "ply" / "ascii", square_ply_header("ascii") + square_ply_ascii_body);
    write_bytes(root / "ply" / "little", square_ply_header("binary_little_endian") + square_ply_binary_body(false));
    write_bytes(root / "ply" / "big", square_ply_header("binary_big_endian") + square_ply_binary_body(true));
    // Query points of `kdet locate`: x y z lines, a comment, blank lines, exponents.
    write_bytes(root / "xyz" / "points", "# x y z\n0 0 0\n\n1.5 -2e-3 4E+2\n0.25 0.5 0.75 # last\n");
    // Points at the ends of float (subnormal, -0, near the largest float) and one beyond it (refused).
    write_bytes(root / "xyz" / "edges", "1e-45 -0 1.17549435e-38\n3.4028234e38 -3.4028234e38 1e7\n");
    write_bytes(root / "xyz" / "beyond", "0 0 0\n1e39 0 0\n");
    for (const auto& [name, text] : kdet::scenes::builtin_scene_files()) write_bytes(root / "scene" / name, text);
    write_bytes(root / "scene" / "every_statement", every_statement_scene);
}

} // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: kdet_fuzz_seeds OUTPUT_DIR\n";
        return 2;
    }
    try {
        write_seeds(argv[1]);
    } catch (const kdet::Error& error) {
        std::cerr << error.what() << "\n";
        return 1;
    }
    return 0;
}
