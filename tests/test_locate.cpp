/// @file test_locate.cpp
/// @brief Point location against brute force: every (point, tet) with the same exact predicate over all
/// tets (tests/cgal/test_locate_cgal.cpp judges the predicate itself by CGAL), the nearest tet within a
/// distance over all tets, barycentric coordinates that rebuild the point, objects and errors, and the
/// CUDA backend against the CPU to the bit.

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/locate.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "geometry/point_tet.hpp"
#include "locate_cases.hpp"
#include "pipeline/point_location.hpp"
#include "test_support.hpp"

namespace kdet {
namespace {

using Hit = std::pair<std::uint64_t, std::uint32_t>; // (point, tet)

vec3 float_point(const std::vector<double>& xyz, std::size_t i) {
    return vec3{static_cast<float>(xyz[3 * i]), static_cast<float>(xyz[3 * i + 1]), static_cast<float>(xyz[3 * i + 2])};
}

void float_tet(const TetMesh& mesh, std::size_t t, vec3 v[4]) {
    for (int k = 0; k < 4; ++k) {
        const double* p = &mesh.positions[3 * std::size_t{mesh.tets[4 * t + k]}];
        v[k] = vec3{static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])};
    }
}

/// Every (point, tet) whose closed tet holds the point, over all pairs.
std::set<Hit> brute_force_holding(const TetMesh& mesh, const std::vector<double>& xyz) {
    std::set<Hit> hits;
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        vec3 v[4];
        float_tet(mesh, t, v);
        const Aabb box = tet_box(v);
        for (std::size_t i = 0; i < xyz.size() / 3; ++i) {
            const vec3 p = float_point(xyz, i);
            if (!boxes_overlap(box, Aabb{p, p})) continue;
            point_query::PointTetSigns signs;
            if (point_query::tet_holds_point(v, p, signs)) hits.emplace(i, static_cast<std::uint32_t>(t));
        }
    }
    return hits;
}

std::set<Hit> hits_of(const LocateResult& r) {
    std::set<Hit> hits;
    for (std::size_t p = 0; p < r.point_count; ++p)
        for (std::uint64_t h = r.offsets[p]; h < r.offsets[p + 1]; ++h) hits.emplace(p, r.tets[h]);
    return hits;
}

/// The result is well formed: offsets ascending, tets ascending per point, barycentric coordinates in
/// [0, 1] summing to 1 that rebuild the closest point, which is the point itself at distance 0.
void expect_consistent(const TetMesh& mesh, const std::vector<double>& xyz, const LocateResult& r) {
    ASSERT_EQ(r.offsets.size(), r.point_count + 1);
    ASSERT_EQ(r.offsets.back(), r.hit_count);
    ASSERT_EQ(r.tets.size(), r.hit_count);
    for (std::size_t p = 0; p < r.point_count; ++p) {
        ASSERT_LE(r.offsets[p], r.offsets[p + 1]);
        for (std::uint64_t h = r.offsets[p]; h < r.offsets[p + 1]; ++h) {
            if (h > r.offsets[p]) {
                EXPECT_LT(r.tets[h - 1], r.tets[h]);
            }
            double sum = 0, rebuilt[3] = {0, 0, 0}, scale = 0;
            for (int k = 0; k < 4; ++k) {
                const double b = r.barycentrics[4 * h + k];
                EXPECT_GE(b, 0.0);
                EXPECT_LE(b, 1.0);
                sum += b;
                const std::uint32_t v = mesh.tets[4 * std::size_t{r.tets[h]} + k];
                const auto q = test::float_vertex(mesh, v);
                for (int a = 0; a < 3; ++a) {
                    rebuilt[a] += b * q[a];
                    scale = std::max(scale, std::fabs(q[a]));
                }
            }
            EXPECT_NEAR(sum, 1.0, 1e-12);
            for (int a = 0; a < 3; ++a) EXPECT_NEAR(rebuilt[a], r.closest_points[3 * h + a], 1e-9 * scale + 1e-300);
            if (r.distances[h] == 0.0) {
                for (int a = 0; a < 3; ++a)
                    EXPECT_EQ(r.closest_points[3 * h + a], static_cast<double>(static_cast<float>(xyz[3 * p + a])));
            }
        }
    }
}

void expect_matches_brute_force(const TetMesh& mesh, const std::vector<double>& xyz, const char* what) {
    const LocateResult r = locate(mesh, xyz);
    const std::set<Hit> expected = brute_force_holding(mesh, xyz);
    const std::set<Hit> found = hits_of(r);
    EXPECT_EQ(found, expected) << what << ": " << found.size() << " hits, brute force " << expected.size();
    for (std::size_t h = 0; h < r.hit_count; ++h) EXPECT_EQ(r.distances[h], 0.0) << what;
    expect_consistent(mesh, xyz, r);
}

TEST(Locate, BoxMeshSharedFeatures) {
    // Grid vertices are shared by up to 24 tets, edges and faces by several: each must get all of them.
    const TetMesh mesh = make_box_mesh(4, 3, 3, 0.25);
    const std::vector<double> xyz = test::locate_query_points(mesh, mesh.num_tets(), 500, 1);
    const std::set<Hit> hits = brute_force_holding(mesh, xyz);
    std::size_t most = 0;
    for (std::size_t p = 0; p < xyz.size() / 3; ++p) {
        std::size_t n = 0;
        for (auto it = hits.lower_bound({p, 0}); it != hits.end() && it->first == p; ++it) ++n;
        most = std::max(most, n);
    }
    EXPECT_GE(most, 12u); // an inner vertex of the Kuhn split
    expect_matches_brute_force(mesh, xyz, "box mesh");
}

TEST(Locate, GroupsJoinTheTetsOfOneCube) {
    // The six tets of a cube of a cut grid share its box: a group takes them all, and no tet of the
    // next cube, whose union with them would be twice as long.
    const TetMesh mesh = make_box_mesh(2, 1, 1, 1.0);
    ASSERT_EQ(mesh.num_tets(), 12u);
    std::vector<Aabb> boxes;
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        vec3 v[4];
        float_tet(mesh, t, v);
        boxes.push_back(tet_box(v));
    }
    const auto cube_of = [](const Aabb& b) { return b.lo.x < 0.5f ? 0 : 1; };
    for (std::size_t a = 0; a < boxes.size(); ++a)
        for (std::size_t b = 0; b < boxes.size(); ++b)
            EXPECT_EQ(locate_group_takes(boxes[a], boxes[a].hi - boxes[a].lo, boxes[b]), cube_of(boxes[a]) == cube_of(boxes[b]))
                << a << " " << b;
    // A flat box joins a box as wide when the union stays within a quarter more of the widest side.
    const Aabb square{{0, 0, 0}, {1, 1, 0}};
    EXPECT_TRUE(locate_group_takes(square, square.hi - square.lo, Aabb{{0, 0, 0.2f}, {1, 1, 0.2f}}));
    EXPECT_FALSE(locate_group_takes(square, square.hi - square.lo, Aabb{{0, 0, 0.4f}, {1, 1, 0.4f}}));
}

TEST(Locate, GroupsOfNearlySharedBoxesLoseNoPoint) {
    // A grid with its vertices moved a little: the boxes of a cube's tets differ but still group, so a
    // group reads the points of its union, and each tet must keep exactly those it holds, also those
    // on the faces, edges and corners it shares and just outside its own box.
    TetMesh mesh = make_box_mesh(5, 4, 3, 0.5);
    std::mt19937 random(17);
    std::uniform_real_distribution<double> jitter(-0.04, 0.04);
    for (double& x : mesh.positions) x += jitter(random);
    std::vector<double> xyz = test::locate_query_points(mesh, mesh.num_tets(), 3000, 6);
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        vec3 v[4];
        float_tet(mesh, t, v);
        const Aabb b = tet_box(v);
        for (const vec3 corner : {b.lo, b.hi, vec3{next_float_down(b.lo.x), b.lo.y, b.lo.z}, vec3{b.hi.x, next_float_up(b.hi.y), b.hi.z}})
            for (const float c : {corner.x, corner.y, corner.z}) xyz.push_back(c);
    }
    expect_matches_brute_force(mesh, xyz, "jittered grid");
}

TEST(Locate, AnswersFollowThePointsWhateverTheirOrder) {
    // The hits are found tet by tet and then placed in the points' order: the same points shuffled,
    // some twice, and with a distance get each point's own answer.
    const TetMesh mesh = make_box_mesh(3, 3, 2, 0.5);
    const std::vector<double> xyz = test::locate_query_points(mesh, mesh.num_tets(), 400, 4);
    const std::size_t n = xyz.size() / 3;
    std::vector<std::size_t> from(n);
    for (std::size_t i = 0; i < n; ++i) from[i] = i;
    std::shuffle(from.begin(), from.end(), std::mt19937(5));
    for (std::size_t i = 0; i < n; i += 7) from.push_back(from[i]);
    std::vector<double> shuffled;
    for (const std::size_t i : from) shuffled.insert(shuffled.end(), {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]});
    for (const double within : {0.0, 0.2}) {
        LocateOptions options;
        options.within = within;
        const LocateResult r = locate(mesh, xyz, options), s = locate(mesh, shuffled, options);
        expect_consistent(mesh, shuffled, s);
        ASSERT_EQ(s.point_count, from.size());
        for (std::size_t j = 0; j < from.size(); ++j) {
            const std::size_t i = from[j];
            ASSERT_EQ(s.offsets[j + 1] - s.offsets[j], r.offsets[i + 1] - r.offsets[i]) << j;
            for (std::uint64_t k = 0; k < r.offsets[i + 1] - r.offsets[i]; ++k) {
                const std::uint64_t hs = s.offsets[j] + k, hr = r.offsets[i] + k;
                EXPECT_EQ(s.tets[hs], r.tets[hr]);
                EXPECT_EQ(s.distances[hs], r.distances[hr]);
                for (int c = 0; c < 4; ++c) EXPECT_EQ(s.barycentrics[4 * hs + c], r.barycentrics[4 * hr + c]);
            }
        }
    }
}

/// The nearest tet within d against brute force (distance to the boundary of each tet that does not
/// hold the point); returns how many points got one.
std::size_t expect_nearest_matches_brute_force(const TetMesh& mesh, const std::vector<double>& xyz, double within) {
    LocateOptions options;
    options.within = within;
    const LocateResult r = locate(mesh, xyz, options);
    const LocateResult held = locate(mesh, xyz);
    expect_consistent(mesh, xyz, r);
    std::size_t nearest = 0;
    for (std::size_t p = 0; p < r.point_count; ++p) {
        const vec3 q = float_point(xyz, p);
        if (held.offsets[p + 1] > held.offsets[p]) {
            // Held points keep exactly their holding tets.
            EXPECT_EQ(r.offsets[p + 1] - r.offsets[p], held.offsets[p + 1] - held.offsets[p]) << "point " << p;
            continue;
        }
        double best = within;
        std::uint32_t best_tet = 0xffffffffu;
        for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
            vec3 v[4];
            float_tet(mesh, t, v);
            const double d = point_query::closest_on_tet_boundary(v, q).distance;
            if (d < best || (d == best && t < best_tet)) best = d, best_tet = static_cast<std::uint32_t>(t);
        }
        if (best_tet == 0xffffffffu) {
            EXPECT_EQ(r.offsets[p + 1], r.offsets[p]) << "point " << p;
            continue;
        }
        if (r.offsets[p + 1] - r.offsets[p] != 1u) {
            ADD_FAILURE() << "point " << p << " within " << within << ": " << r.offsets[p + 1] - r.offsets[p] << " hits";
            continue;
        }
        // The nearest tet, up to the rounding of the distances in double (docs/point-location.md):
        // its distance as brute force computes it is within a tolerance of the least.
        const std::uint64_t h = r.offsets[p];
        vec3 v[4];
        float_tet(mesh, r.tets[h], v);
        const double tolerance = 1e-7 * test::extent_of(mesh);
        EXPECT_EQ(r.tets[h], best_tet) << "point " << p << " within " << within;
        EXPECT_LE(point_query::closest_on_tet_boundary(v, q).distance, best + tolerance) << "point " << p;
        EXPECT_NEAR(r.distances[h], best, tolerance) << "point " << p;
        EXPECT_GT(r.distances[h], 0.0);
        const double dx = r.closest_points[3 * h] - q.x, dy = r.closest_points[3 * h + 1] - q.y, dz = r.closest_points[3 * h + 2] - q.z;
        EXPECT_NEAR(std::sqrt(dx * dx + dy * dy + dz * dz), r.distances[h], 1e-12 * (1 + best));
        ++nearest;
    }
    return nearest;
}

TEST(Locate, PreparedFacesGiveTheExactOrientations) {
    // TetFaces decides each face's orientation from rows computed once per tet and a rounding bound
    // computed once for the tet's box; its signs must be orient3d's with the point in place of the
    // vertex, for points of the box on the faces' planes (vertices and edge midpoints of a power-of-two
    // lattice, exactly coplanar) and a float step off them too.
    std::mt19937 random(9);
    std::uniform_int_distribution<int> lattice(-8, 8);
    std::uniform_real_distribution<float> scale(-30.0f, 30.0f);
    std::size_t zeros = 0, tested = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        const float unit = std::ldexp(1.0f, static_cast<int>(scale(random)));
        vec3 v[4];
        for (vec3& q : v) q = vec3{unit * static_cast<float>(lattice(random)), unit * static_cast<float>(lattice(random)),
                                   unit * static_cast<float>(lattice(random))};
        const point_query::TetFaces faces(v);
        const Aabb box = tet_box(v);
        for (int n = 0; n < 8; ++n) {
            const vec3& a = v[random() % 4];
            const vec3& b = v[random() % 4];
            vec3 p{(a.x + b.x) * 0.5f, (a.y + b.y) * 0.5f, (a.z + b.z) * 0.5f};
            if (n % 2) p.y = n % 4 == 1 ? next_float_up(p.y) : next_float_down(p.y);
            if (!box_holds(box, p)) continue; // the bound is for the points of the box
            double values[4];
            faces.face_values(p, values);
            ++tested;
            for (int k = 0; k < 4; ++k) {
                vec3 w[4];
                point_query::replace_vertex(v, k, p, w);
                const int expected = point_query::orient3d_sign(w[0], w[1], w[2], w[3]);
                ASSERT_EQ(faces.decided_sign(v, k, p, values[k]), expected) << trial << " " << n << " " << k;
                zeros += expected == 0;
            }
        }
    }
    EXPECT_GT(tested, 20000u);
    EXPECT_GT(zeros, 1000u); // the points on a face's plane were tested
}

TEST(Locate, FarApartClustersAndABigTet) {
    // Two box meshes 1e5 apart leave too many cells in their common region for a dense table: the
    // hashed grid answers. A tet larger than all the others spans more cells than there are points
    // and scans every point; points far outside the tets get no grid key and no hit.
    TetMesh mesh = make_box_mesh(4, 3, 3, 0.25);
    TetMesh other = make_box_mesh(3, 3, 2, 0.5);
    const auto vertices = static_cast<std::uint32_t>(mesh.num_vertices());
    for (std::size_t i = 0; i < other.positions.size(); ++i) mesh.positions.push_back(other.positions[i] + (i % 3 == 1 ? 1e5 : 0.0));
    for (const std::uint32_t v : other.tets) mesh.tets.push_back(v + vertices);
    std::vector<double> xyz = test::locate_query_points(mesh, mesh.num_tets(), 1000, 8);
    xyz.insert(xyz.end(), {-5e5, 3, 3, 7, 2e5, 1, 0.5, 1e5 + 0.5, 0.5});
    expect_matches_brute_force(mesh, xyz, "clusters");
    for (const double within : {0.1, 3.0}) EXPECT_GT(expect_nearest_matches_brute_force(mesh, xyz, within), 0u) << within;
    const auto first = static_cast<std::uint32_t>(mesh.num_vertices());
    mesh.positions.insert(mesh.positions.end(), {-1e3, -1e3, -1e3, 1e3, -1e3, -1e3, 0, 1e3, -1e3, 0, 0, 1e3});
    mesh.tets.insert(mesh.tets.end(), {first, first + 1, first + 2, first + 3});
    const std::vector<double> few = {0.3, 0.2, 0.1, 0.5, 1e5 + 0.7, 0.2, 2e3, 0, 0};
    expect_matches_brute_force(mesh, few, "big tet");
}

TEST(Locate, RandomSoupOfManySizes) {
    const TetMesh soup = test::random_soup(600, 10.0, 4.0, 7);
    expect_matches_brute_force(soup, test::locate_query_points(soup, 200, 2000, 2), "soup");
}

TEST(Locate, RealMesh) {
    const TetMesh mesh = test::load_model("octopus-low.mesh");
    expect_matches_brute_force(mesh, test::locate_query_points(mesh, 300, 2000, 3), "octopus-low.mesh");
}

TEST(Locate, FarAndTinyCoordinates) {
    // A mesh far from the origin and one of subnormal-scale cells: the grid's cells and the exact
    // predicates hold at both ends of float's range.
    TetMesh far = make_box_mesh(3, 2, 2, 1e-3);
    for (std::size_t i = 0; i < far.positions.size(); ++i) far.positions[i] += i % 3 == 0 ? 1e4 : -3e3;
    expect_matches_brute_force(far, test::locate_query_points(far, far.num_tets(), 300, 4), "far");
    const TetMesh tiny = make_box_mesh(2, 2, 2, std::ldexp(1.0, -140));
    expect_matches_brute_force(tiny, test::locate_query_points(tiny, tiny.num_tets(), 300, 5), "tiny");
}

TEST(Locate, DegenerateTets) {
    // Flat and collinear tets (allowed by the detector) hold the points of their hull only.
    TetMesh mesh;
    mesh.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0,   // a flat square
                      2, 0, 0, 3, 0, 0, 4, 0, 0, 5, 0, 0,   // a segment
                      6, 0, 0, 6, 0, 0, 6, 0, 0, 6, 0, 0};  // a point
    mesh.tets = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
    const std::vector<double> xyz = {0.5, 0.5, 0, 0.5, 0.5, 1e-7, 1, 1, 0, 1.5, 0, 0, 3.5, 0, 0, 3.5, 1e-7, 0,
                                     6, 0, 0, 6, 0, 1e-30, 5, 0, 0, 0.25, 0.75, 0};
    expect_matches_brute_force(mesh, xyz, "degenerate");
    const LocateResult r = locate(mesh, xyz);
    EXPECT_EQ(hits_of(r), (std::set<Hit>{{0, 0}, {2, 0}, {4, 1}, {6, 2}, {8, 1}, {9, 0}}));
}

TEST(Locate, WithinGivesNearestTet) {
    const TetMesh mesh = test::random_soup(300, 10.0, 2.0, 11);
    const std::vector<double> xyz = test::locate_query_points(mesh, 50, 1500, 6);
    for (double within : {0.05, 0.5, 30.0}) EXPECT_GT(expect_nearest_matches_brute_force(mesh, xyz, within), 0u) << within;
}

TEST(Locate, NearestTiesAndFarPoints) {
    // Points off a box mesh's corners, edges and faces (a corner vertex is as near to each tet that
    // shares it: the lowest id wins the tie), points a hundred times the mesh's size away, and a
    // `within` that reaches them all: the search's cost follows the tets near each point, and its
    // answer is brute force's.
    const TetMesh mesh = make_box_mesh(5, 4, 3, 0.5);
    std::vector<double> xyz;
    for (const double x : {-0.5, 0.0, 1.25, 2.5, 3.0})
        for (const double y : {-1.0, 0.0, 1.0, 2.0, 2.5})
            for (const double z : {-0.25, 0.0, 0.75, 1.5, 2.0}) xyz.insert(xyz.end(), {x, y, z});
    std::mt19937 random(21);
    std::uniform_real_distribution<double> far(-150.0, 150.0);
    for (int i = 0; i < 300; ++i) xyz.insert(xyz.end(), {far(random), far(random), far(random)});
    const LocateResult inside = locate(mesh, xyz);
    std::size_t points_held = 0;
    for (std::size_t p = 0; p < inside.point_count; ++p) points_held += inside.offsets[p + 1] > inside.offsets[p];
    EXPECT_GT(points_held, 0u);
    // Each point that no tet holds gets one.
    EXPECT_EQ(expect_nearest_matches_brute_force(mesh, xyz, 1e30), xyz.size() / 3 - points_held);
    EXPECT_GT(expect_nearest_matches_brute_force(mesh, xyz, 0.5), 0u);
}

TEST(Locate, DetectorObjectsAndMovedPositions) {
    const TetMesh a = make_box_mesh(3, 3, 3, 1.0);
    TetMesh b = make_box_mesh(2, 2, 2, 1.0);
    for (std::size_t i = 0; i < b.positions.size(); ++i) b.positions[i] += 1.0; // overlaps a's inner cubes
    Detector detector;
    const ObjectId ia = detector.add_object(a), ib = detector.add_object(b);
    const std::vector<double> xyz = test::locate_query_points(b, b.num_tets(), 300, 8);
    const PositionsView points = PositionsView{xyz.data(), true, xyz.size() / 3};

    const LocateResult all = detector.locate(points, all_objects);
    std::set<std::tuple<std::uint64_t, std::uint32_t, std::uint32_t>> expected, found;
    for (const auto& [p, t] : brute_force_holding(a, xyz)) expected.emplace(p, ia, t);
    for (const auto& [p, t] : brute_force_holding(b, xyz)) expected.emplace(p, ib, t);
    for (std::size_t p = 0; p < all.point_count; ++p)
        for (std::uint64_t h = all.offsets[p]; h < all.offsets[p + 1]; ++h) found.emplace(p, all.objects[h], all.tets[h]);
    EXPECT_EQ(found, expected);

    const LocateResult only_b = detector.locate(points, ib);
    EXPECT_EQ(hits_of(only_b), brute_force_holding(b, xyz));
    for (std::uint32_t o : only_b.objects) EXPECT_EQ(o, ib);

    // Located at the positions as last set, before any detect().
    TetMesh moved = b;
    for (std::size_t i = 0; i < moved.positions.size(); ++i) moved.positions[i] += 0.3;
    detector.set_positions(ib, moved.positions.data(), moved.num_vertices());
    EXPECT_EQ(hits_of(detector.locate(points, ib)), brute_force_holding(moved, xyz));
    detector.detect();
    EXPECT_EQ(hits_of(detector.locate(points, ib)), brute_force_holding(moved, xyz));
}

TEST(Locate, EmptyInputs) {
    const TetMesh mesh = make_box_mesh(1, 1, 1, 1.0);
    const LocateResult none = locate(mesh, std::vector<double>{});
    EXPECT_EQ(none.point_count, 0u);
    EXPECT_EQ(none.offsets, std::vector<std::uint64_t>{0});
    Detector empty;
    const std::vector<double> xyz = {0.5, 0.5, 0.5};
    const LocateResult r = empty.locate(PositionsView{xyz.data(), true, 1}, all_objects);
    EXPECT_EQ(r.offsets, (std::vector<std::uint64_t>{0, 0}));
}

TEST(Locate, BadInputIsOneLineError) {
    const TetMesh mesh = make_box_mesh(1, 1, 1, 1.0);
    const std::vector<double> bad = {0, 0, 0, 1, std::numeric_limits<double>::quiet_NaN(), 0};
    EXPECT_NE(test::error_message([&] { locate(mesh, bad); }).find("point 1 has a non-finite coordinate"), std::string::npos);
    const std::vector<double> huge = {1e300, 0, 0};
    EXPECT_NE(test::error_message([&] { locate(mesh, huge); }).find("point 0"), std::string::npos);
    LocateOptions negative;
    negative.within = -1;
    EXPECT_NE(test::error_message([&] { locate(mesh, std::vector<double>{0, 0, 0}, negative); }).find("within"), std::string::npos);
    negative.within = std::numeric_limits<double>::infinity();
    EXPECT_NE(test::error_message([&] { locate(mesh, std::vector<double>{0, 0, 0}, negative); }).find("within"), std::string::npos);
    EXPECT_NE(test::error_message([&] { locate(mesh, std::vector<double>{0, 0}); }).find("x y z"), std::string::npos);
    Detector detector;
    detector.add_object(mesh);
    const std::vector<double> xyz = {0, 0, 0};
    EXPECT_NE(test::error_message([&] { detector.locate(PositionsView{xyz.data(), true, 1}, 3); }).find("object id 3"),
              std::string::npos);
    EXPECT_NE(test::error_message([&] { detector.locate(PositionsView{nullptr, true, 1}, 0); }).find("data pointer is null"),
              std::string::npos);
}

TEST(Locate, CudaMatchesCpuToTheBit) {
    std::string reason;
    if (!cuda_available(&reason)) GTEST_SKIP() << "CUDA backend not tested: " << reason;
    DetectorOptions cuda;
    cuda.backend = Backend::cuda;
    const TetMesh meshes[] = {test::load_model("octopus-low.mesh"), make_box_mesh(6, 5, 4, 0.5), test::random_soup(2000, 10.0, 3.0, 9)};
    for (const TetMesh& mesh : meshes) {
        const std::vector<double> xyz = test::locate_query_points(mesh, 500, 20000, 10);
        for (double within : {0.0, 0.2}) {
            LocateOptions options;
            options.within = within;
            const LocateResult cpu = locate(mesh, xyz, options), gpu = locate(mesh, xyz, options, cuda);
            ASSERT_EQ(gpu.offsets, cpu.offsets);
            EXPECT_EQ(gpu.tets, cpu.tets);
            EXPECT_EQ(gpu.objects, cpu.objects);
            const auto same_bits = [](const std::vector<double>& x, const std::vector<double>& y) {
                return x.size() == y.size() && (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(double)) == 0);
            };
            EXPECT_TRUE(same_bits(gpu.barycentrics, cpu.barycentrics));
            EXPECT_TRUE(same_bits(gpu.closest_points, cpu.closest_points));
            EXPECT_TRUE(same_bits(gpu.distances, cpu.distances));
        }
    }
}

} // namespace
} // namespace kdet
