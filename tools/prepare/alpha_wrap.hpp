#pragma once
/// @file alpha_wrap.hpp
/// @brief CGAL's 3D alpha wrapping behind a plain interface, so that only this file sees CGAL.

#include <kdet/mesh.hpp>

#include <string>

namespace kdet::prepare {

/// @brief Wraps @p surface (any triangle soup: holes, self-intersections and duplicate triangles are
/// fine) in a closed, 2-manifold surface without self-intersections. @p alpha sets the size of the
/// features the wrap follows (smaller: finer triangles); @p offset is how far outside the input it
/// lies. Deterministic: the same input and parameters give the same triangles.
TriangleMesh alpha_wrap(const TriangleMesh& surface, double alpha, double offset);

/// @brief The CGAL version the wrap was built with (part of the cache key).
std::string cgal_version();

} // namespace kdet::prepare
