#pragma once
/// @file io.hpp
/// @brief Reading and writing tetrahedral meshes (TetGen .node/.ele, ASCII MEDIT .mesh, Gmsh .msh,
/// legacy VTK .vtk) and reading triangle surfaces (OBJ, OFF, STL, PLY).
///
/// Every reader checks what it reads: bad input throws kdet::Error with a one-line message that
/// starts with "path:line: " (the line of the offending token, 1-based) and says what is wrong.
/// Past the start of binary data the location is a byte offset instead: "path: byte N: " (0-based).

#include <kdet/mesh.hpp>

#include <string>

namespace kdet {

/// @brief Choices of what a reader accepts.
struct ReadOptions {
    /// @brief Accept tetrahedra of zero volume (including ones that repeat a vertex index).
    bool allow_degenerate = false;
};

/// @brief Reads a mesh, choosing the format by the extension of @p path:
/// ".mesh" is MEDIT; ".msh" is Gmsh; ".vtk" is legacy VTK (these three in any case); ".node", ".ele"
/// or no extension is TetGen (see read_tetgen).
/// @throws Error for any other extension (naming the file and the supported formats) and for bad input.
TetMesh read_tet_mesh(const std::string& path, const ReadOptions& options = {});

/// @brief Reads a TetGen mesh: the pair `name.node` + `name.ele`.
/// @p path may be spelled `name`, `name.node` or `name.ele`. Indices may be 0- or 1-based: the base is
/// the index of the first point in the .node file. Point attributes and boundary markers, tetrahedron
/// attributes and the nodes past the fourth of 10-node tetrahedra are read and dropped.
TetMesh read_tetgen(const std::string& path, const ReadOptions& options = {});

/// @brief Reads an ASCII MEDIT mesh (Dimension 3, 1-based indices). Only Vertices and Tetrahedra are
/// kept; the other known sections (Triangles, Edges, Corners, Ridges, ...) are skipped.
TetMesh read_medit(const std::string& path, const ReadOptions& options = {});

/// @brief Reads a Gmsh MSH file, version 2.2 or 4.1, ASCII or binary (little-endian, as Gmsh writes
/// it on every common machine). Elements of type 4 (tetrahedron) and 11 (10-node tetrahedron, its
/// first four nodes) are kept; other elements are skipped, and so are sections other than $Nodes and
/// $Elements. Node tags may be any distinct positive numbers; they are mapped to 0-based indices in
/// the order the nodes appear.
TetMesh read_gmsh(const std::string& path, const ReadOptions& options = {});

/// @brief Reads a legacy VTK file holding an UNSTRUCTURED_GRID: the classic layout (versions 2.0 to
/// 4.2: CELLS count size, then "n i0 .. in-1" per cell) or the VTK 9 layout (version 5.1: OFFSETS
/// and CONNECTIVITY arrays), ASCII or binary (big-endian, as the format prescribes). POINTS may be
/// float or double. Cells of type 10 (tetra) and 24 (quadratic tetra, its first four points) are
/// kept, others skipped; point and cell data are not read.
TetMesh read_vtk(const std::string& path, const ReadOptions& options = {});

/// @brief Reads a triangle surface, choosing the format by the extension of @p path (any case):
/// ".obj" (v and f records; polygons are fan-triangulated, "f a/b/c" forms and negative indices are
/// understood, the rest is ignored), ".off" (OFF, polygons fan-triangulated), ".stl" (ASCII or
/// binary; identical vertices are merged) or ".ply" (ASCII, binary_little_endian or
/// binary_big_endian; vertex x, y, z and the face list vertex_indices or vertex_index).
/// @throws Error for another extension, bad input, non-finite coordinates, indices out of range,
/// faces with fewer than 3 vertices or a surface without triangles.
TriangleMesh read_surface(const std::string& path);

/// @brief Reads query points: a text file of `x y z` lines (`#` starts a comment), or any tet mesh file
/// read_tet_mesh() reads (by its extension, or a TetGen stem with its .node beside it), whose vertices
/// are the points (its tets may be degenerate). Returns x y z per point (none for a file of comments
/// and blank lines only).
/// Throws kdet::Error naming the file and line for a malformed line or a coordinate that is not
/// finite or beyond float range.
std::vector<double> read_points(const std::string& path);

/// @brief The Gmsh MSH versions write_gmsh writes.
enum class GmshVersion { v2_2, v4_1 };

/// @brief How write_gmsh writes: the version, and binary or ASCII.
struct GmshFormat {
    GmshVersion version = GmshVersion::v4_1;
    bool binary = false;
};

/// @brief The legacy VTK layouts write_vtk writes: classic (4.2) or VTK 9 (5.1, OFFSETS/CONNECTIVITY).
enum class VtkVersion { v4_2, v5_1 };

/// @brief How write_vtk writes: the version, and binary (big-endian) or ASCII.
struct VtkFormat {
    VtkVersion version = VtkVersion::v5_1;
    bool binary = false;
};

/// @brief Writes `stem.node` and `stem.ele`, 0-based, with coordinates that read back exactly.
/// @throws Error when the mesh is invalid (see validate_tet_mesh; degenerate tetrahedra are allowed)
/// or a file cannot be written.
void write_tetgen(const TetMesh& mesh, const std::string& stem);

/// @brief Writes an ASCII MEDIT file (Dimension 3, 1-based) with coordinates that read back exactly.
/// @throws Error when the mesh is invalid (see validate_tet_mesh; degenerate tetrahedra are allowed)
/// or the file cannot be written.
void write_medit(const TetMesh& mesh, const std::string& path);

/// @brief Writes a Gmsh MSH file in @p format: the vertices as nodes 1..n and the tetrahedra as type 4
/// elements 1..m; coordinates read back exactly.
/// @throws Error when the mesh is invalid (see validate_tet_mesh; degenerate tetrahedra are allowed)
/// or the file cannot be written.
void write_gmsh(const TetMesh& mesh, const std::string& path, const GmshFormat& format = {});

/// @brief Writes a legacy VTK UNSTRUCTURED_GRID in @p format, with double coordinates that read back
/// exactly and tetra cells (type 10).
/// @throws Error when the mesh is invalid (see validate_tet_mesh; degenerate tetrahedra are allowed)
/// or the file cannot be written.
void write_vtk(const TetMesh& mesh, const std::string& path, const VtkFormat& format = {});

/// @brief How write_tet_mesh writes formats that have a binary form (Gmsh, VTK).
struct WriteOptions {
    bool binary = false;
};

/// @brief Writes a mesh in the format that read_tet_mesh chooses for the extension of @p path:
/// ".mesh" MEDIT, ".msh" Gmsh 4.1, ".vtk" VTK 5.1 (binary when @p options say so), and ".node",
/// ".ele" or no extension TetGen (`name.node` + `name.ele`). Coordinates read back exactly.
/// Degenerate tetrahedra are written; reading them back needs ReadOptions::allow_degenerate.
/// @throws Error for any other extension, an invalid mesh or a file that cannot be written.
void write_tet_mesh(const TetMesh& mesh, const std::string& path, const WriteOptions& options = {});

/// @brief Checks a mesh built in memory with the same rules the readers apply: whole vertices and
/// tetrahedra, finite coordinates, indices in range, at least one tetrahedron, and no zero-volume
/// tetrahedra unless @p options allows them.
/// @throws Error with a message such as "source: tet 17: ..." or "source: vertex 3: ...".
void validate_tet_mesh(const TetMesh& mesh, const std::string& source, const ReadOptions& options = {});

} // namespace kdet
