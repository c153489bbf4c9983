/// @file test_locate_cgal.cpp
/// @brief Point location judged by CGAL: for every query point, the tets whose closed set holds it by
/// CGAL::orientation in exact rational arithmetic on the float coordinates (no tet's orientation with the
/// point in place of a vertex opposite to the tet's own), over all (point, tet) pairs whose boxes meet,
/// on generated and real meshes with the points that stress containment (tests/locate_cases.hpp).

#include <kdet/io.hpp>
#include <kdet/locate.hpp>
#include <kdet/prepare.hpp>
#include <kdet/scenes.hpp>

#include <CGAL/Gmpq.h>
#include <CGAL/Simple_cartesian.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "../locate_cases.hpp"

namespace {

// Exact rational arithmetic throughout, no floating-point filter: the oracle shares no rounding with kdet.
using Kernel = CGAL::Simple_cartesian<CGAL::Gmpq>;
using Point = Kernel::Point_3;
using Hit = std::pair<std::uint64_t, std::uint32_t>;

Point point_of(const std::array<double, 3>& p) { return Point(p[0], p[1], p[2]); }

/// Every (point, tet) whose closed tet holds the point by CGAL's orientation over rationals; the meshes here
/// have no zero-volume tets (the readers refuse them; tests/test_locate.cpp covers those).
std::set<Hit> cgal_hits(const kdet::TetMesh& mesh, const std::vector<double>& xyz) {
    std::set<Hit> hits;
    const std::size_t points = xyz.size() / 3;
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        std::array<std::array<double, 3>, 4> v;
        for (int k = 0; k < 4; ++k) v[k] = kdet::test::float_vertex(mesh, mesh.tets[4 * t + k]);
        std::array<double, 3> lo = v[0], hi = v[0];
        for (int k = 1; k < 4; ++k)
            for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], v[k][a]), hi[a] = std::max(hi[a], v[k][a]);
        const Point a = point_of(v[0]), b = point_of(v[1]), c = point_of(v[2]), d = point_of(v[3]);
        const CGAL::Orientation own = CGAL::orientation(a, b, c, d);
        EXPECT_NE(own, CGAL::COPLANAR) << "tet " << t;
        for (std::size_t i = 0; i < points; ++i) {
            const double* p = &xyz[3 * i];
            if (p[0] < lo[0] || p[0] > hi[0] || p[1] < lo[1] || p[1] > hi[1] || p[2] < lo[2] || p[2] > hi[2]) continue;
            const Point q(p[0], p[1], p[2]);
            const CGAL::Orientation opposite = own == CGAL::POSITIVE ? CGAL::NEGATIVE : CGAL::POSITIVE;
            if (CGAL::orientation(q, b, c, d) == opposite || CGAL::orientation(a, q, c, d) == opposite ||
                CGAL::orientation(a, b, q, d) == opposite || CGAL::orientation(a, b, c, q) == opposite)
                continue;
            hits.emplace(i, static_cast<std::uint32_t>(t));
        }
    }
    return hits;
}

void expect_cgal_hits(const kdet::TetMesh& mesh, const std::vector<double>& xyz, const std::string& what) {
    const kdet::LocateResult r = kdet::locate(mesh, xyz);
    std::set<Hit> found;
    for (std::size_t p = 0; p < r.point_count; ++p)
        for (std::uint64_t h = r.offsets[p]; h < r.offsets[p + 1]; ++h) found.emplace(p, r.tets[h]);
    const std::set<Hit> expected = cgal_hits(mesh, xyz);
    EXPECT_EQ(found, expected) << what << ": kdet " << found.size() << " hits, CGAL " << expected.size();
    EXPECT_GT(expected.size(), xyz.size() / 3 / 4) << what; // most points are inside: the cases are not empty
}

kdet::TetMesh model(const char* file) {
    const char* set = std::getenv("KDET_DATA_DIR");
    if (!set || !*set) setenv("KDET_DATA_DIR", KDET_DEFAULT_DATA_DIR, 1);
    return kdet::read_tet_mesh(kdet::data_path(file));
}

TEST(LocateCgal, GeneratedBoxMesh) {
    const kdet::TetMesh mesh = kdet::make_box_mesh(4, 3, 2, 0.1);
    expect_cgal_hits(mesh, kdet::test::locate_query_points(mesh, mesh.num_tets(), 1000, 21), "box mesh");
}

TEST(LocateCgal, RotatedBoxMeshOffTheGrid) {
    // Rotated: the vertices and midpoints no longer lie on coordinate planes, so float rounding puts
    // midpoints on either side of their faces.
    kdet::TetMesh mesh = kdet::make_box_mesh(3, 3, 2, 0.37);
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
        double* p = &mesh.positions[3 * v];
        const double x = p[0], y = p[1], z = p[2];
        p[0] = 0.8 * x - 0.6 * y + 3.1;
        p[1] = 0.6 * x + 0.8 * y - 7.3;
        p[2] = z + 0.3 * x;
    }
    expect_cgal_hits(mesh, kdet::test::locate_query_points(mesh, mesh.num_tets(), 1000, 22), "rotated box mesh");
}

TEST(LocateCgal, RealMeshes) {
    const kdet::TetMesh octopus = model("octopus-low.mesh"), hand = model("hand.mesh");
    expect_cgal_hits(octopus, kdet::test::locate_query_points(octopus, 1000, 2000, 23), "octopus-low.mesh");
    // Of hand.mesh's points every 64th: each (point, tet) whose boxes meet costs the oracle rational arithmetic.
    const std::vector<double> all = kdet::test::locate_query_points(hand, 2000, 2000, 24);
    std::vector<double> some;
    for (std::size_t i = 0; 3 * i < all.size(); i += 64) some.insert(some.end(), all.begin() + 3 * i, all.begin() + 3 * i + 3);
    expect_cgal_hits(hand, some, "hand.mesh");
}

} // namespace
