/// @file alpha_wrap.cpp
/// @brief alpha_wrap() with CGAL::alpha_wrap_3.

#include "alpha_wrap.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>
#include <CGAL/version.h>

#include <array>
#include <cstdint>
#include <vector>

namespace kdet::prepare {

TriangleMesh alpha_wrap(const TriangleMesh& surface, double alpha, double offset) {
    using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
    using Point = Kernel::Point_3;
    std::vector<Point> points;
    points.reserve(surface.num_vertices());
    for (std::size_t v = 0; v < surface.num_vertices(); ++v)
        points.emplace_back(surface.positions[3 * v], surface.positions[3 * v + 1], surface.positions[3 * v + 2]);
    std::vector<std::array<std::size_t, 3>> faces(surface.num_triangles());
    for (std::size_t t = 0; t < faces.size(); ++t)
        for (std::size_t k = 0; k < 3; ++k) faces[t][k] = surface.triangles[3 * t + k];

    CGAL::Surface_mesh<Point> wrap;
    CGAL::alpha_wrap_3(points, faces, alpha, offset, wrap);

    TriangleMesh out;
    out.positions.reserve(3 * wrap.number_of_vertices());
    std::vector<std::uint32_t> index(wrap.num_vertices());
    std::uint32_t next = 0;
    for (const auto v : wrap.vertices()) {
        const Point& p = wrap.point(v);
        out.positions.insert(out.positions.end(), {p.x(), p.y(), p.z()});
        index[v.idx()] = next++;
    }
    out.triangles.reserve(3 * wrap.number_of_faces());
    for (const auto f : wrap.faces())
        for (const auto v : CGAL::vertices_around_face(wrap.halfedge(f), wrap)) out.triangles.push_back(index[v.idx()]);
    return out;
}

std::string cgal_version() { return CGAL_VERSION_STR; }

} // namespace kdet::prepare
