// The order in which the pipeline stores tets, and that results still use the caller's numbering.

#include "device_like_exec.hpp"
#include "test_support.hpp"

#include "geometry/tet_intersect.hpp"
#include "pipeline/pipeline_base.hpp"
#include "pipeline/spatial_order.hpp"

#include <kdet/detector.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>

namespace kdet {
namespace {

/// A block of n^3 unit cubes, one tet per cube, listed in shuffled order.
TetMesh shuffled_block(int n, unsigned seed) {
    TetMesh mesh;
    std::vector<int> cubes(static_cast<std::size_t>(n * n * n));
    std::iota(cubes.begin(), cubes.end(), 0);
    std::shuffle(cubes.begin(), cubes.end(), std::mt19937(seed));
    for (int c : cubes) {
        const double x = c % n, y = (c / n) % n, z = c / (n * n);
        const double corners[4][3] = {{x, y, z}, {x + 1, y, z}, {x, y + 1, z}, {x, y, z + 1}};
        for (const auto& p : corners) mesh.positions.insert(mesh.positions.end(), p, p + 3);
        const auto v = static_cast<std::uint32_t>(mesh.tets.size());
        for (std::uint32_t k = 0; k < 4; ++k) mesh.tets.push_back(v + k);
    }
    return mesh;
}

double mean_step(const std::vector<vec3>& centroid, const std::vector<std::uint32_t>& order) {
    double sum = 0;
    for (std::size_t i = 1; i < order.size(); ++i) sum += std::sqrt(length_squared(centroid[order[i]] - centroid[order[i - 1]]));
    return sum / static_cast<double>(order.size() - 1);
}

TEST(SpatialOrder, IsAPermutationThatKeepsNeighboursTogether) {
    const TetMesh mesh = shuffled_block(24, 3);
    std::vector<vec3> positions;
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v)
        positions.push_back(make_vec3(static_cast<float>(mesh.positions[3 * v]), static_cast<float>(mesh.positions[3 * v + 1]),
                                      static_cast<float>(mesh.positions[3 * v + 2])));
    const std::vector<std::uint32_t> order = spatial_tet_order(positions.data(), mesh.tets.data(), mesh.num_tets());
    std::vector<std::uint32_t> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    std::vector<std::uint32_t> identity(mesh.num_tets());
    std::iota(identity.begin(), identity.end(), 0u);
    ASSERT_EQ(sorted, identity);

    std::vector<vec3> centroid(mesh.num_tets());
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        const std::uint32_t* v = &mesh.tets[4 * t];
        centroid[t] = (positions[v[0]] + positions[v[1]] + positions[v[2]] + positions[v[3]]) * 0.25f;
    }
    // Shuffled: consecutive tets are about a third of the block apart; a Morton order walks cube by cube.
    EXPECT_GT(mean_step(centroid, identity), 7.0);
    EXPECT_LT(mean_step(centroid, order), 1.6);
}

TEST(SpatialOrder, IsTheSameOnAnyNumberOfThreads) {
    const TetMesh mesh = shuffled_block(42, 5); // 74,088 tets: enough for the threaded passes
    std::vector<vec3> positions;
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v)
        positions.push_back(make_vec3(static_cast<float>(mesh.positions[3 * v]), static_cast<float>(mesh.positions[3 * v + 1]),
                                      static_cast<float>(mesh.positions[3 * v + 2])));
    const std::vector<std::uint32_t> one = spatial_tet_order(positions.data(), mesh.tets.data(), mesh.num_tets(), 1);
    EXPECT_EQ(spatial_tet_order(positions.data(), mesh.tets.data(), mesh.num_tets(), 2), one);
    EXPECT_EQ(spatial_tet_order(positions.data(), mesh.tets.data(), mesh.num_tets(), 3), one);
}

TEST(SpatialOrder, HandlesEmptyAndFlatInput) {
    EXPECT_TRUE(spatial_tet_order(nullptr, nullptr, 0).empty());
    const std::vector<vec3> same(4, make_vec3(1, 1, 1));
    const std::vector<std::uint32_t> tets = {0, 1, 2, 3, 3, 2, 1, 0};
    EXPECT_EQ(spatial_tet_order(same.data(), tets.data(), 2), (std::vector<std::uint32_t>{0, 1}));
}

/// The caller's tets of one object as the pipeline sees them (float32).
std::vector<std::array<vec3, 4>> float_tets(const TetMesh& mesh) {
    std::vector<std::array<vec3, 4>> out(mesh.num_tets());
    for (std::size_t t = 0; t < mesh.num_tets(); ++t)
        for (int k = 0; k < 4; ++k) {
            const double* p = &mesh.positions[3 * mesh.tets[4 * t + k]];
            out[t][k] = make_vec3(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
        }
    return out;
}

TEST(SpatialOrder, PairsFlagsAndContactsUseTheCallersNumbering) {
    // Oracle without the detector: every pair of the caller's tets, in the caller's order.
    const TetMesh a = test::random_soup(700, 2.0, 1.0, 81), b = test::random_soup(700, 2.0, 1.0, 82);
    const auto ta = float_tets(a), tb = float_tets(b);
    std::vector<TetPair> expected;
    std::vector<Contact> expected_contacts;
    for (std::uint32_t i = 0; i < ta.size(); ++i)
        for (std::uint32_t j = 0; j < tb.size(); ++j) {
            if (!boxes_overlap(tet_box(ta[i].data()), tet_box(tb[j].data())) ||
                !tets_intersect(DetectorOptions{}.narrow_phase, ta[i].data(), tb[j].data()))
                continue;
            expected.push_back(TetPair{0, i, 1, j});
            float depth = 0;
            vec3 direction{};
            tets_intersect_sat_mtv(ta[i].data(), tb[j].data(), depth, direction);
            expected_contacts.push_back(Contact{depth, {direction.x, direction.y, direction.z}});
        }
    ASSERT_GT(expected.size(), 20u);

    for (Method method : {Method::kdet, Method::brute_force_loop}) {
        DetectorOptions options;
        options.method = method;
        options.contacts = true;
        Detector detector(options);
        detector.add_object(a);
        detector.add_object(b);
        const FrameResult& r = detector.detect();
        EXPECT_EQ(r.pairs, expected) << to_string(method);
        ASSERT_EQ(r.contacts.size(), expected_contacts.size());
        for (std::size_t k = 0; k < expected_contacts.size(); ++k) {
            EXPECT_EQ(r.contacts[k].depth, expected_contacts[k].depth);
            for (int c = 0; c < 3; ++c) EXPECT_EQ(r.contacts[k].direction[c], expected_contacts[k].direction[c]);
        }
        for (const TetPair& p : expected) {
            EXPECT_EQ(r.colliding[0][p.tet_a], 1);
            EXPECT_EQ(r.colliding[1][p.tet_b], 1);
        }
        EXPECT_EQ(r.counts.colliding_tets,
                  static_cast<std::uint64_t>(std::count(r.colliding[0].begin(), r.colliding[0].end(), 1) +
                                             std::count(r.colliding[1].begin(), r.colliding[1].end(), 1)));
        const DeviceResults device = detector.device_results();
        const device_like::BackendMemoryReadable readable;
        ASSERT_EQ(device.pair_count, expected.size());
        for (std::size_t k = 0; k < expected.size(); ++k)
            EXPECT_EQ(device.pair_keys[k], (std::uint64_t{expected[k].tet_a} << 32) |
                                               (detector.first_tet(1) + expected[k].tet_b));
    }
}

/// `mesh` with its vertices listed in shuffled order and `unused` more vertices that no tet uses.
TetMesh with_shuffled_vertices(const TetMesh& mesh, unsigned seed, std::size_t unused) {
    std::vector<std::uint32_t> new_id(mesh.num_vertices() + unused);
    std::iota(new_id.begin(), new_id.end(), 0u);
    std::shuffle(new_id.begin(), new_id.end(), std::mt19937(seed));
    TetMesh out;
    out.positions.resize(3 * new_id.size(), 1e6);
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v)
        for (int c = 0; c < 3; ++c) out.positions[3 * new_id[v] + c] = mesh.positions[3 * v + c];
    for (const std::uint32_t v : mesh.tets) out.tets.push_back(new_id[v]);
    return out;
}

TEST(SpatialOrder, VerticesAreStoredInTheOrderTheStoredTetsFirstUseThemUnusedOnesLast) {
    const TetMesh first = test::random_soup(30, 1.0, 1.0, 83);
    const TetMesh mesh = with_shuffled_vertices(test::load_model("octopus-low.mesh"), 84, 5);
    SceneTopology topology;
    for (const TetMesh* m : {&first, &mesh}) {
        std::vector<vec3> positions(m->num_vertices());
        for (std::size_t v = 0; v < positions.size(); ++v)
            positions[v] = make_vec3(static_cast<float>(m->positions[3 * v]), static_cast<float>(m->positions[3 * v + 1]),
                                     static_cast<float>(m->positions[3 * v + 2]));
        topology.add_object(positions.data(), static_cast<std::uint32_t>(positions.size()), m->tets.data(), m->num_tets());
    }
    const std::uint32_t base = static_cast<std::uint32_t>(first.num_vertices());
    ASSERT_EQ(topology.vertex_count, base + mesh.num_vertices());
    ASSERT_EQ(topology.vertex_user_id.size(), topology.vertex_count);
    // Each object's vertices keep its range of ids, each id once.
    std::vector<std::uint32_t> ids(topology.vertex_user_id.begin() + base, topology.vertex_user_id.end());
    std::sort(ids.begin(), ids.end());
    for (std::uint32_t k = 0; k < ids.size(); ++k) ASSERT_EQ(ids[k], base + k);
    // The stored tets are the caller's, through both numberings; stored ids appear in increasing order.
    std::uint32_t next_new = base;
    for (std::uint32_t t = topology.object_tet_begin[1]; t < topology.object_tet_begin[2]; ++t) {
        const std::uint32_t user_tet = topology.tet_user_id[t] - topology.object_tet_begin[1];
        for (int k = 0; k < 4; ++k) {
            const std::uint32_t stored = topology.tets[t].v[k];
            EXPECT_EQ(topology.vertex_user_id[stored], base + mesh.tets[4 * user_tet + k]);
            ASSERT_LE(stored, next_new);
            if (stored == next_new) ++next_new;
        }
    }
    // Only the five vertices no tet uses come after the used ones.
    EXPECT_EQ(next_new, topology.vertex_count - 5);
    std::vector<vec3> caller(mesh.num_vertices()), stored(mesh.num_vertices());
    for (std::uint32_t v = 0; v < caller.size(); ++v) caller[v] = make_vec3(static_cast<float>(v), 0.0f, 0.0f);
    topology.to_stored_order(base, static_cast<std::uint32_t>(caller.size()), caller.data(), stored.data());
    for (std::uint32_t v = 0; v < stored.size(); ++v)
        EXPECT_EQ(stored[v].x, static_cast<float>(topology.vertex_user_id[base + v] - base));
}

std::vector<IndexPair> pairs_between(const FrameResult& r, ObjectId a, ObjectId b) {
    std::vector<IndexPair> got;
    for (const TetPair& p : r.pairs)
        if (p.object_a == a && p.object_b == b) got.emplace_back(p.tet_a, p.tet_b);
    return got;
}

TEST(SpatialOrder, ResultsDoNotDependOnHowTheCallerNumbersTheVertices) {
    // The same tets with their vertices listed in another order (and a few unused): the same pairs,
    // whether positions come with the object, from set_positions or from set_positions_on_device.
    // One object of two overlapping copies of a model, so that it collides with itself.
    const TetMesh octopus = test::load_model("octopus-low.mesh");
    const TetMesh copy = test::moved(octopus, 0.2, 0.3 * test::extent_of(octopus), 0.0, 0.0);
    TetMesh model = octopus;
    model.positions.insert(model.positions.end(), copy.positions.begin(), copy.positions.end());
    for (const std::uint32_t v : copy.tets) model.tets.push_back(static_cast<std::uint32_t>(octopus.num_vertices()) + v);
    const TetMesh shuffled = with_shuffled_vertices(model, 85, 3);
    const auto moved_pair = [](const TetMesh& m, double dx) { return test::moved(m, 0.3, dx, 0.02, 0.0); };
    // The moved model, listed as `shuffled` is (the same seed shuffles alike).
    const auto moved_shuffled = [&](double dx) { return with_shuffled_vertices(moved_pair(model, dx), 85, 3); };
    const auto xyz = [](const TetMesh& m) { return std::vector<float>(m.positions.begin(), m.positions.end()); };
    const double shift = 0.5 * test::extent_of(model);
    DetectorOptions brute;
    brute.method = Method::brute_force_loop;
    const auto expected_at = [&](double dx) { return collide(model, moved_pair(model, dx), brute); };

    Detector detector;
    detector.set_self_collision(detector.add_object(shuffled), true);
    const ObjectId moving = detector.add_object(moved_shuffled(shift));
    const std::vector<IndexPair> self_expected = collide_self(model, brute);
    ASSERT_FALSE(self_expected.empty());
    const auto check = [&](double dx, const char* how) {
        const FrameResult& r = detector.detect();
        const std::vector<IndexPair> expected = expected_at(dx);
        ASSERT_FALSE(expected.empty()) << how;
        EXPECT_EQ(pairs_between(r, 0, moving), expected) << how;
        EXPECT_EQ(pairs_between(r, 0, 0), self_expected) << how;
    };
    check(shift, "added");
    detector.set_positions(moving, moved_shuffled(0.6 * shift).positions.data(), shuffled.num_vertices());
    check(0.6 * shift, "set_positions");
    const std::vector<float> on_device = xyz(moved_shuffled(0.4 * shift));
    detector.set_positions_on_device(moving, on_device.data(), shuffled.num_vertices());
    check(0.4 * shift, "set_positions_on_device");
    // Positions only the backend holds, staged or current, survive a rebuild for a new object.
    detector.add_object(test::random_soup(5, 1.0, 0.0, 86));
    check(0.4 * shift, "current on the device, then an object added");
    const std::vector<float> staged = xyz(moved_shuffled(0.7 * shift));
    detector.set_positions_on_device(moving, staged.data(), shuffled.num_vertices());
    detector.add_object(test::random_soup(5, 1.0, 0.0, 87));
    check(0.7 * shift, "staged on the device, then an object added");
}

TEST(SpatialOrder, LargeObjectsPositionsAreCheckedAndStoredAlikeOnAnyNumberOfThreads) {
    // Enough vertices (80k) for the detector to check and reorder positions on several threads.
    const TetMesh soup = test::random_soup(20000, 1.0, 2.0, 88);
    const TetMesh shuffled = with_shuffled_vertices(soup, 89, 7);
    const TetMesh moved_soup = test::moved(soup, 0.1, 0.05, 0.0, 0.0);
    const TetMesh moved_shuffled = with_shuffled_vertices(moved_soup, 89, 7);
    DetectorOptions one_thread;
    one_thread.threads = 1;
    Detector reference(one_thread);
    reference.set_self_collision(reference.add_object(soup), true);
    reference.set_positions(0, moved_soup.positions.data(), moved_soup.num_vertices());
    const std::vector<IndexPair> expected = pairs_between(reference.detect(), 0, 0);
    ASSERT_FALSE(expected.empty());
    for (const int threads : {1, 2, 3}) {
        DetectorOptions options;
        options.threads = threads;
        Detector detector(options);
        detector.set_self_collision(detector.add_object(shuffled), true);
        detector.set_positions(0, moved_shuffled.positions.data(), shuffled.num_vertices());
        EXPECT_EQ(pairs_between(detector.detect(), 0, 0), expected) << threads << " threads";
        // The first bad vertex is named whichever thread finds it; the positions stay as they were.
        std::vector<double> bad = moved_shuffled.positions;
        bad[3 * 70001 + 2] = std::numeric_limits<double>::quiet_NaN();
        bad[3 * 30002] = std::numeric_limits<double>::infinity();
        EXPECT_EQ(test::error_message([&] { detector.set_positions(0, bad.data(), shuffled.num_vertices()); }),
                  "object 0: vertex 30002 has a non-finite coordinate (or one beyond float range)")
            << threads << " threads";
        EXPECT_EQ(pairs_between(detector.detect(), 0, 0), expected) << threads << " threads, after the rejection";
        // So are the first bad index and the first bad vertex of an object added (its 80k indices and
        // vertices checked on the threads too); the detector keeps the one object it had.
        const std::string vertices = std::to_string(shuffled.num_vertices());
        TetMesh bad_indices = shuffled;
        bad_indices.tets[4 * 15000 + 1] = 80000000u;
        bad_indices.tets[4 * 6000 + 3] = static_cast<std::uint32_t>(shuffled.num_vertices());
        EXPECT_EQ(test::error_message([&] { detector.add_object(bad_indices); }),
                  "object 1: tet 6000 has vertex index " + vertices + " out of range [0, " + vertices + ")")
            << threads << " threads";
        TetMesh bad_vertices = shuffled;
        bad_vertices.positions[3 * 60000 + 1] = std::numeric_limits<double>::quiet_NaN();
        bad_vertices.positions[3 * 20001] = -std::numeric_limits<double>::infinity();
        EXPECT_EQ(test::error_message([&] { detector.add_object(bad_vertices); }),
                  "object 1: vertex 20001 has a non-finite coordinate (or one beyond float range)")
            << threads << " threads";
        EXPECT_EQ(detector.object_count(), 1u);
    }
}

TEST(Detector, AFailedAddLeavesTheDetectorAsItWas) {
    Detector detector;
    const TetMesh a = test::random_soup(50, 1.0, 1.0, 91);
    detector.add_object(a);
    TetMesh bad = a;
    bad.positions[7] = std::nan("");
    EXPECT_THROW(detector.add_object(bad), Error);
    EXPECT_EQ(detector.object_count(), 1u);
    detector.set_self_collision(0, true);
    EXPECT_NO_THROW(detector.detect());
}

TEST(Detector, MoreTetsThanTheGridsIdsHoldAreRejectedBeforeAnyIsRead) {
    Detector detector;
    const TetMesh a = test::random_soup(50, 1.0, 1.0, 91);
    detector.add_object(a);
    // The count alone decides: the tet array (one tet here) is never read past its end.
    const std::size_t too_many = (std::size_t{1} << 29) - 50;
    try {
        detector.add_object(a.positions.data(), a.positions.size() / 3, a.tets.data(), too_many);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("too many tetrahedra"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("536870911"), std::string::npos) << e.what();
    }
    EXPECT_EQ(detector.object_count(), 1u);
    EXPECT_NO_THROW(detector.add_object(a.positions.data(), a.positions.size() / 3, a.tets.data(), 1));
}

} // namespace
} // namespace kdet
