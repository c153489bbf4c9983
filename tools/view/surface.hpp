#pragma once
/// @file surface.hpp
/// @brief Host-side mesh processing the viewer does once per object: which tets share each face,
/// and from that the boundary surface (the faces only one tet uses), oriented outward.

#include <kdet/mesh.hpp>

#include <cstdint>
#include <vector>

namespace kdet::view {

/// @brief The corners (0-3 within the tet) of a tet's faces 0-3, the order the viewer numbers them.
constexpr int tet_face_vertices[4][3] = {{0, 1, 2}, {0, 3, 1}, {1, 3, 2}, {0, 2, 3}};

/// @brief Marks a face without a neighbour.
constexpr std::uint32_t no_tet = 0xffffffffu;

/// @brief What the viewer knows about a tet mesh's faces.
struct MeshFaces {
    /// The boundary's triangles, three vertex indices each, counter-clockwise seen from outside.
    /// Faces shared by two tets are interior; a face used by three or more tets (a non-manifold
    /// mesh) is interior too.
    std::vector<std::uint32_t> boundary;
    /// The tet each boundary triangle belongs to.
    std::vector<std::uint32_t> boundary_tet;
    /// neighbour[4 * t + k]: the tet across face k of tet t, or no_tet on the boundary (and for
    /// faces of a non-manifold fan).
    std::vector<std::uint32_t> neighbour;
};

MeshFaces analyse_faces(const TetMesh& mesh);

/// @brief Appends the faces of the flagged tets (flags[t] != 0) that are not shared with another
/// flagged tet, three vertex indices each: the surface of the flagged region. Orientation is not
/// fixed (the renderer lights both sides).
void append_flagged_region(const TetMesh& mesh, const MeshFaces& faces, const std::vector<std::uint8_t>& flags,
                           std::vector<std::uint32_t>& out);

} // namespace kdet::view
