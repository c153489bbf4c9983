#pragma once
/// @file io.hpp
/// @brief Reading and writing tetrahedral meshes (TetGen .node/.ele and ASCII MEDIT .mesh).
///
/// Every reader checks what it reads: bad input throws kdet::Error with a one-line message that
/// starts with "path:line: " (the line of the offending token, 1-based) and says what is wrong.

#include <kdet/mesh.hpp>

#include <string>

namespace kdet {

/// @brief Choices of what a reader accepts.
struct ReadOptions {
    /// @brief Accept tetrahedra of zero volume (including ones that repeat a vertex index).
    bool allow_degenerate = false;
};

/// @brief Reads a mesh, choosing the format by the extension of @p path:
/// ".mesh" is MEDIT; ".node", ".ele" or no extension is TetGen (see read_tetgen).
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

/// @brief Writes `stem.node` and `stem.ele`, 0-based, with coordinates that read back exactly.
/// @throws Error when the mesh is invalid (see validate_tet_mesh; degenerate tetrahedra are allowed)
/// or a file cannot be written.
void write_tetgen(const TetMesh& mesh, const std::string& stem);

/// @brief Writes an ASCII MEDIT file (Dimension 3, 1-based) with coordinates that read back exactly.
/// @throws Error when the mesh is invalid (see validate_tet_mesh; degenerate tetrahedra are allowed)
/// or the file cannot be written.
void write_medit(const TetMesh& mesh, const std::string& path);

/// @brief Checks a mesh built in memory with the same rules the readers apply: whole vertices and
/// tetrahedra, finite coordinates, indices in range, at least one tetrahedron, and no zero-volume
/// tetrahedra unless @p options allows them.
/// @throws Error with a message such as "source: tet 17: ..." or "source: vertex 3: ...".
void validate_tet_mesh(const TetMesh& mesh, const std::string& source, const ReadOptions& options = {});

/// @brief The folder holding the source models: $KDET_DATA_DIR when set and non-empty, else
/// "../shared/models" (relative to the working directory).
std::string data_dir();

/// @brief The path of model @p file inside data_dir().
/// @throws Error "model 'x' not found in DIR (...)" when there is no such file.
std::string data_path(const std::string& file);

} // namespace kdet
