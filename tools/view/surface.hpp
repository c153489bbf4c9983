#pragma once
/// @file surface.hpp
/// @brief Host-side mesh processing the viewer does once per object: the boundary surface of a tet
/// mesh (the faces that only one tet uses), oriented outward.

#include <kdet/mesh.hpp>

#include <cstdint>
#include <vector>

namespace kdet::view {

/// @brief The triangles of @p mesh's boundary, three vertex indices each, counter-clockwise seen
/// from outside the tet they belong to. Faces shared by two tets are interior and left out; a face
/// used by three or more tets (a non-manifold mesh) is interior too.
std::vector<std::uint32_t> boundary_triangles(const TetMesh& mesh);

/// @brief The vertex indices of the four faces of tet @p tet (12 values), appended to @p out.
/// Orientation is not fixed: the renderer lights both sides of these faces.
inline void append_tet_faces(const TetMesh& mesh, std::uint32_t tet, std::vector<std::uint32_t>& out) {
    const std::uint32_t* v = &mesh.tets[4 * static_cast<std::size_t>(tet)];
    const std::uint32_t faces[12] = {v[0], v[1], v[2], v[0], v[3], v[1], v[1], v[3], v[2], v[0], v[2], v[3]};
    out.insert(out.end(), faces, faces + 12);
}

} // namespace kdet::view
