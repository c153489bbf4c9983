// Tests of the built-in meshes and scenes: make_box_mesh, make_torus_mesh, ProceduralScene, fold_bar.

#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <vector>

namespace {

using kdet::TetMesh;

struct Point {
    double x, y, z;
};

Point vertex_at(const std::vector<double>& positions, std::uint32_t v) {
    return {positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]};
}

double signed_volume(Point a, Point b, Point c, Point d) {
    const Point u{b.x - a.x, b.y - a.y, b.z - a.z};
    const Point v{c.x - a.x, c.y - a.y, c.z - a.z};
    const Point w{d.x - a.x, d.y - a.y, d.z - a.z};
    return (u.x * (v.y * w.z - v.z * w.y) + u.y * (v.z * w.x - v.x * w.z) + u.z * (v.x * w.y - v.y * w.x)) / 6.0;
}

std::array<Point, 4> tet_corners(const TetMesh& mesh, const std::vector<double>& positions, std::size_t t) {
    std::array<Point, 4> corners{};
    for (std::size_t c = 0; c < 4; ++c) corners[c] = vertex_at(positions, mesh.tets[4 * t + c]);
    return corners;
}

double tet_volume(const TetMesh& mesh, const std::vector<double>& positions, std::size_t t) {
    const auto c = tet_corners(mesh, positions, t);
    return signed_volume(c[0], c[1], c[2], c[3]);
}

double smallest_tet_volume(const TetMesh& mesh, const std::vector<double>& positions) {
    double smallest = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) smallest = std::min(smallest, tet_volume(mesh, positions, t));
    return smallest;
}

double total_volume(const TetMesh& mesh) {
    double total = 0.0;
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) total += tet_volume(mesh, mesh.positions, t);
    return total;
}

/// Strictly inside: `p` is on the inner side of all four faces of the positively oriented tet.
bool point_in_tet(Point p, const std::array<Point, 4>& c) {
    return signed_volume(p, c[1], c[2], c[3]) > 0 && signed_volume(c[0], p, c[2], c[3]) > 0 &&
           signed_volume(c[0], c[1], p, c[3]) > 0 && signed_volume(c[0], c[1], c[2], p) > 0;
}

struct Box {
    Point lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
             std::numeric_limits<double>::infinity()};
    Point hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
             -std::numeric_limits<double>::infinity()};

    void add(Point p) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    bool overlaps(const Box& o) const {
        return lo.x <= o.hi.x && o.lo.x <= hi.x && lo.y <= o.hi.y && o.lo.y <= hi.y && lo.z <= o.hi.z &&
               o.lo.z <= hi.z;
    }
};

Box bounding_box(const std::vector<double>& positions) {
    Box box;
    for (std::uint32_t v = 0; v < positions.size() / 3; ++v) box.add(vertex_at(positions, v));
    return box;
}

/// How many tets have each face, the face given by its sorted vertex indices.
std::map<std::array<std::uint32_t, 3>, int> face_counts(const TetMesh& mesh) {
    std::map<std::array<std::uint32_t, 3>, int> counts;
    for (std::size_t t = 0; t < mesh.num_tets(); ++t)
        for (std::size_t skipped = 0; skipped < 4; ++skipped) {
            std::array<std::uint32_t, 3> face{};
            std::size_t n = 0;
            for (std::size_t c = 0; c < 4; ++c)
                if (c != skipped) face[n++] = mesh.tets[4 * t + c];
            std::sort(face.begin(), face.end());
            ++counts[face];
        }
    return counts;
}

/// Every index is a vertex, every vertex is used, and no tet repeats a vertex.
void expect_indices_valid(const TetMesh& mesh) {
    ASSERT_EQ(mesh.positions.size(), 3 * mesh.num_vertices());
    ASSERT_EQ(mesh.tets.size(), 4 * mesh.num_tets());
    std::vector<bool> used(mesh.num_vertices(), false);
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        std::array<std::uint32_t, 4> tet{};
        for (std::size_t c = 0; c < 4; ++c) {
            tet[c] = mesh.tets[4 * t + c];
            ASSERT_LT(tet[c], mesh.num_vertices());
            used[tet[c]] = true;
        }
        std::sort(tet.begin(), tet.end());
        EXPECT_EQ(std::adjacent_find(tet.begin(), tet.end()), tet.end()) << "tet " << t;
    }
    EXPECT_EQ(std::count(used.begin(), used.end(), false), 0) << "unused vertices";
}

/// Interior faces are shared by exactly two tets, boundary faces belong to one.
void expect_conforming(const TetMesh& mesh) {
    for (const auto& [face, count] : face_counts(mesh))
        EXPECT_TRUE(count == 1 || count == 2) << "face " << face[0] << ' ' << face[1] << ' ' << face[2];
}

std::vector<double> scene_positions(const kdet::ProceduralScene& scene, std::size_t object, int frame) {
    std::vector<double> positions;
    scene.positions(object, frame, positions);
    return positions;
}

const double kPi = std::acos(-1.0);

TEST(BoxMesh, CountsMatchTheGrid) {
    const TetMesh mesh = kdet::make_box_mesh(2, 3, 4, 0.5);
    EXPECT_EQ(mesh.num_tets(), 6u * 2 * 3 * 4);
    EXPECT_EQ(mesh.num_vertices(), 3u * 4 * 5);
    expect_indices_valid(mesh);
    const Box box = bounding_box(mesh.positions);
    EXPECT_DOUBLE_EQ(box.lo.x, 0.0);
    EXPECT_DOUBLE_EQ(box.hi.x, 1.0);
    EXPECT_DOUBLE_EQ(box.hi.y, 1.5);
    EXPECT_DOUBLE_EQ(box.hi.z, 2.0);
}

TEST(BoxMesh, TetsArePositiveAndFillTheBox) {
    const double cell = 0.25;
    const TetMesh mesh = kdet::make_box_mesh(3, 2, 2, cell);
    EXPECT_NEAR(smallest_tet_volume(mesh, mesh.positions), cell * cell * cell / 6.0, 1e-12);
    EXPECT_NEAR(total_volume(mesh), 12 * cell * cell * cell, 1e-12);
}

TEST(BoxMesh, IsConforming) {
    const int nx = 3, ny = 2, nz = 4;
    const TetMesh mesh = kdet::make_box_mesh(nx, ny, nz, 1.0);
    const auto counts = face_counts(mesh);
    std::size_t boundary_faces = 0;
    for (const auto& [face, count] : counts) {
        ASSERT_TRUE(count == 1 || count == 2);
        if (count == 2) continue;
        ++boundary_faces;
        // A face met by one tet only must lie in one of the six sides of the box.
        const Point a = vertex_at(mesh.positions, face[0]);
        const Point b = vertex_at(mesh.positions, face[1]);
        const Point c = vertex_at(mesh.positions, face[2]);
        const auto on_side = [](double u, double v, double w, double side) { return u == side && v == side && w == side; };
        EXPECT_TRUE(on_side(a.x, b.x, c.x, 0) || on_side(a.x, b.x, c.x, nx) || on_side(a.y, b.y, c.y, 0) ||
                    on_side(a.y, b.y, c.y, ny) || on_side(a.z, b.z, c.z, 0) || on_side(a.z, b.z, c.z, nz));
    }
    // Each square on the surface is split into two triangles.
    EXPECT_EQ(boundary_faces, 2u * 2 * (nx * ny + ny * nz + nz * nx));
}

TEST(BoxMesh, RejectsBadArguments) {
    EXPECT_THROW(kdet::make_box_mesh(0, 1, 1, 1.0), kdet::Error);
    EXPECT_THROW(kdet::make_box_mesh(1, 1, -1, 1.0), kdet::Error);
    EXPECT_THROW(kdet::make_box_mesh(1, 1, 1, 0.0), kdet::Error);
    EXPECT_THROW(kdet::make_box_mesh(5000, 5000, 5000, 1.0), kdet::Error);
}

TEST(TorusMesh, TetCountIsNearTheTarget) {
    for (std::size_t target : {1000u, 10000u, 100000u}) {
        const TetMesh mesh = kdet::make_torus_mesh(1.0, 0.4, target);
        EXPECT_NEAR(static_cast<double>(mesh.num_tets()), static_cast<double>(target), 0.1 * static_cast<double>(target))
            << "target " << target;
    }
}

TEST(TorusMesh, IsAConformingSolidTorus) {
    const double major = 2.0, minor = 0.5;
    const TetMesh mesh = kdet::make_torus_mesh(major, minor, 20000);
    expect_indices_valid(mesh);
    expect_conforming(mesh);
    EXPECT_GT(smallest_tet_volume(mesh, mesh.positions), 0.0);
    EXPECT_NEAR(total_volume(mesh), 2 * kPi * kPi * major * minor * minor, 0.05 * 2 * kPi * kPi * major * minor * minor);
    // The hole stays empty: no vertex near the axis.
    for (std::uint32_t v = 0; v < mesh.num_vertices(); ++v) {
        const Point p = vertex_at(mesh.positions, v);
        EXPECT_GT(std::hypot(p.x, p.y), major - 2 * minor);
    }
}

TEST(TorusMesh, RejectsBadArguments) {
    EXPECT_THROW(kdet::make_torus_mesh(1.0, 1.0, 1000), kdet::Error);
    EXPECT_THROW(kdet::make_torus_mesh(1.0, 0.0, 1000), kdet::Error);
    EXPECT_THROW(kdet::make_torus_mesh(1.0, 0.5, 0), kdet::Error);
}

TEST(ProceduralScene, RejectsBadOptions) {
    EXPECT_THROW(kdet::ProceduralScene({99, 10}), kdet::Error);
    EXPECT_THROW(kdet::ProceduralScene({20'000'001, 10}), kdet::Error);
    EXPECT_THROW(kdet::ProceduralScene({1000, 0}), kdet::Error);
    EXPECT_NO_THROW(kdet::ProceduralScene({100, 1}));
}

TEST(ProceduralScene, RejectsBadObjectOrFrame) {
    const kdet::ProceduralScene scene({1000, 5});
    std::vector<float> out;
    EXPECT_THROW(scene.rest_mesh(2), kdet::Error);
    EXPECT_THROW(scene.positions(2, 0, out), kdet::Error);
    EXPECT_THROW(scene.positions(0, 5, out), kdet::Error);
    EXPECT_THROW(scene.positions(1, -1, out), kdet::Error);
    EXPECT_NO_THROW(scene.positions(1, 4, out));
}

TEST(ProceduralScene, SplitsTheTetsBetweenTwoObjects) {
    const kdet::ProceduralScene scene({20000, 7});
    ASSERT_EQ(scene.num_objects(), 2u);
    EXPECT_EQ(scene.num_frames(), 7);
    for (std::size_t object = 0; object < 2; ++object) {
        const TetMesh& mesh = scene.rest_mesh(object);
        EXPECT_NEAR(static_cast<double>(mesh.num_tets()), 10000.0, 1000.0);
        expect_indices_valid(mesh);
        std::vector<float> out;
        scene.positions(object, 3, out);
        EXPECT_EQ(out.size(), mesh.positions.size());
    }
}

TEST(ProceduralScene, IsDeterministic) {
    const kdet::ProceduralScene first({5000, 10});
    const kdet::ProceduralScene second({5000, 10});
    ASSERT_EQ(first.rest_mesh(0).positions, second.rest_mesh(0).positions);
    ASSERT_EQ(first.rest_mesh(0).tets, second.rest_mesh(0).tets);
    const int threads = omp_get_max_threads();
    for (int frame : {0, 4, 9})
        for (std::size_t object = 0; object < 2; ++object) {
            std::vector<float> a, b;
            first.positions(object, frame, a);
            omp_set_num_threads(1);
            second.positions(object, frame, b);
            omp_set_num_threads(threads);
            // Bit-identical, not merely close.
            EXPECT_EQ(a, b) << "object " << object << " frame " << frame;
        }
}

TEST(ProceduralScene, FloatPositionsRoundTheDoublePositions) {
    const kdet::ProceduralScene scene({2000, 9});
    for (int frame : {0, 4, 8}) {
        const std::vector<double> exact = scene_positions(scene, 1, frame);
        std::vector<float> rounded;
        scene.positions(1, frame, rounded);
        ASSERT_EQ(rounded.size(), exact.size());
        for (std::size_t i = 0; i < exact.size(); ++i) ASSERT_EQ(rounded[i], static_cast<float>(exact[i]));
    }
}

TEST(ProceduralScene, ApartAtTheEndsAndInterpenetratingInTheMiddle) {
    const kdet::ProceduralScene scene({2000, 120});
    const int last = scene.num_frames() - 1;
    const int middle = last / 2;
    for (int frame : {0, last})
        EXPECT_FALSE(bounding_box(scene_positions(scene, 0, frame)).overlaps(bounding_box(scene_positions(scene, 1, frame))))
            << "frame " << frame;
    EXPECT_TRUE(bounding_box(scene_positions(scene, 0, middle)).overlaps(bounding_box(scene_positions(scene, 1, middle))));

    // Deep, not just touching: many vertices of object 1 lie inside tets of object 0.
    const TetMesh& mesh = scene.rest_mesh(0);
    const auto count_inside = [&](int frame) {
        const std::vector<double> solid = scene_positions(scene, 0, frame);
        const std::vector<double> points = scene_positions(scene, 1, frame);
        std::size_t inside = 0;
        for (std::uint32_t v = 0; v < points.size() / 3; ++v)
            for (std::size_t t = 0; t < mesh.num_tets(); ++t)
                if (point_in_tet(vertex_at(points, v), tet_corners(mesh, solid, t))) {
                    ++inside;
                    break;
                }
        return inside;
    };
    EXPECT_EQ(count_inside(0), 0u);
    EXPECT_GT(count_inside(middle), mesh.num_vertices() / 20);
}

TEST(ProceduralScene, NoTetInvertsAtAnyFrame) {
    const kdet::ProceduralScene scene({2000, 120});
    for (std::size_t object = 0; object < 2; ++object) {
        const TetMesh& mesh = scene.rest_mesh(object);
        // The deformation preserves volume, so tets should stay close to their rest size, not just positive.
        const double rest_smallest = smallest_tet_volume(mesh, mesh.positions);
        for (int frame = 0; frame < scene.num_frames(); ++frame)
            ASSERT_GT(smallest_tet_volume(mesh, scene_positions(scene, object, frame)), 0.5 * rest_smallest)
                << "object " << object << " frame " << frame;
    }
}

TEST(ProceduralScene, EveryVertexMovesEveryFrame) {
    const kdet::ProceduralScene scene({2000, 120});
    for (std::size_t object = 0; object < 2; ++object) {
        std::vector<float> previous, current;
        scene.positions(object, 0, previous);
        for (int frame = 1; frame < scene.num_frames(); ++frame) {
            scene.positions(object, frame, current);
            for (std::size_t v = 0; v < current.size() / 3; ++v)
                ASSERT_TRUE(current[3 * v] != previous[3 * v] || current[3 * v + 1] != previous[3 * v + 1] ||
                            current[3 * v + 2] != previous[3 * v + 2])
                    << "object " << object << " frame " << frame << " vertex " << v;
            previous.swap(current);
        }
    }
}

/// Bounding boxes of the first and of the last layer of cubes of a bar along x.
std::array<Box, 2> end_layer_boxes(const TetMesh& bar, const std::vector<double>& folded, double cell) {
    const Box rest = bounding_box(bar.positions);
    std::array<Box, 2> ends;
    for (std::uint32_t v = 0; v < bar.num_vertices(); ++v) {
        const double x = bar.positions[3 * v];
        if (x <= rest.lo.x + cell) ends[0].add(vertex_at(folded, v));
        if (x >= rest.hi.x - cell) ends[1].add(vertex_at(folded, v));
    }
    return ends;
}

TEST(FoldBar, SmallAngleBendsWithoutInverting) {
    const double cell = 0.1;
    const TetMesh bar = kdet::make_box_mesh(20, 2, 2, cell);
    std::vector<double> folded;
    kdet::fold_bar(bar, 1.0, folded);
    ASSERT_EQ(folded.size(), bar.positions.size());
    EXPECT_GT(smallest_tet_volume(bar, folded), 0.0);
    // It really bends: the far end leaves the bar's plane z in [0, 0.2].
    EXPECT_GT(end_layer_boxes(bar, folded, cell)[1].hi.z, 0.5);
    kdet::fold_bar(bar, 0.0, folded);
    EXPECT_EQ(folded, bar.positions);
}

TEST(FoldBar, EndsOverlapOnlyPastAFullTurn) {
    const double cell = 0.1;
    const TetMesh bar = kdet::make_box_mesh(20, 2, 2, cell);
    std::vector<double> folded;
    for (double turns : {0.5, 0.9}) {
        kdet::fold_bar(bar, 2 * kPi * turns, folded);
        const auto ends = end_layer_boxes(bar, folded, cell);
        EXPECT_FALSE(ends[0].overlaps(ends[1])) << turns << " turns";
    }
    for (double turns : {1.02, -1.02}) {
        kdet::fold_bar(bar, 2 * kPi * turns, folded);
        EXPECT_GT(smallest_tet_volume(bar, folded), 0.0) << turns << " turns";
        const auto ends = end_layer_boxes(bar, folded, cell);
        EXPECT_TRUE(ends[0].overlaps(ends[1])) << turns << " turns";
    }
}

TEST(FoldBar, RejectsBarsItCannotBend) {
    std::vector<double> folded;
    const TetMesh thick = kdet::make_box_mesh(4, 1, 4, 1.0);
    EXPECT_THROW(kdet::fold_bar(thick, 4 * kPi, folded), kdet::Error);
    EXPECT_THROW(kdet::fold_bar(TetMesh{}, 1.0, folded), kdet::Error);
    const TetMesh flat{{0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1}, {0, 1, 2, 3}};
    EXPECT_THROW(kdet::fold_bar(flat, 1.0, folded), kdet::Error);
}

} // namespace
