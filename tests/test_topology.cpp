// Topology that changes: after every removal, split, replacement and re-add, the next frame equals
// brute force on the meshes as they are now, on any buffer size, and on the GPU as on the CPU.

#include "filter_support.hpp"
#include "device_like_exec.hpp"
#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace kdet {
namespace {

using test::error_message;
using test::jittered_box;
using test::random_soup;

/// What the detector under test should hold: per id the mesh (none once removed) and its self-collision.
struct Objects {
    std::vector<std::optional<TetMesh>> meshes;
    std::vector<bool> self;

    std::vector<ObjectId> live() const {
        std::vector<ObjectId> ids;
        for (ObjectId o = 0; o < meshes.size(); ++o)
            if (meshes[o]) ids.push_back(o);
        return ids;
    }
};

/// Brute force on the live meshes, in a detector of their own, renamed to the tested detector's ids.
FrameResult oracle(const Objects& objects) {
    DetectorOptions options;
    options.method = Method::brute_force_loop;
    Detector detector(options);
    const std::vector<ObjectId> ids = objects.live();
    for (ObjectId o : ids) detector.set_self_collision(detector.add_object(*objects.meshes[o]), objects.self[o]);
    FrameResult r = detector.detect();
    for (TetPair& p : r.pairs) p.object_a = ids[p.object_a], p.object_b = ids[p.object_b];
    std::vector<std::vector<std::uint8_t>> colliding(objects.meshes.size());
    for (std::size_t i = 0; i < ids.size(); ++i) colliding[ids[i]] = r.colliding[i];
    r.colliding = colliding;
    return r;
}

/// A random mesh: a soup or a crumpled box, somewhere in a shared region, so that objects overlap.
TetMesh random_mesh(std::mt19937& rng) {
    const unsigned seed = static_cast<unsigned>(rng());
    if (rng() % 2) return random_soup(150 + rng() % 250, 2.0, 1.0, seed);
    return jittered_box(3 + static_cast<int>(rng() % 4), 3, 3, 0.4, 0.3, seed, 0.3 * static_cast<double>(rng() % 4));
}

/// The tets of `mesh` in a random order, two thirds in one mesh and the rest in another, both on all
/// of its vertices: the split of a fracture.
std::pair<TetMesh, TetMesh> split(const TetMesh& mesh, std::mt19937& rng) {
    std::vector<std::uint32_t> order(mesh.num_tets());
    for (std::uint32_t t = 0; t < order.size(); ++t) order[t] = t;
    std::shuffle(order.begin(), order.end(), rng);
    TetMesh first, second;
    first.positions = second.positions = mesh.positions;
    for (std::size_t i = 0; i < order.size(); ++i) {
        TetMesh& part = i < order.size() * 2 / 3 ? first : second;
        part.tets.insert(part.tets.end(), mesh.tets.begin() + 4 * order[i], mesh.tets.begin() + 4 * order[i] + 4);
    }
    return {first, second};
}

/// A frame's pairs read from DeviceResults (host memory on the CPU backend) through first_tet().
std::vector<TetPair> pairs_through_first_tet(const Detector& detector, const Objects& objects) {
    const DeviceResults device = detector.device_results();
    const device_like::BackendMemoryReadable readable;
    std::vector<TetPair> pairs;
    const std::vector<ObjectId> ids = objects.live();
    const auto locate = [&](std::uint32_t global, std::uint32_t& object, std::uint32_t& tet) {
        for (ObjectId o : ids)
            if (global >= detector.first_tet(o) && global - detector.first_tet(o) < detector.tet_count(o)) {
                object = o, tet = global - detector.first_tet(o);
                return;
            }
        ADD_FAILURE() << "global tet " << global << " is in no object";
    };
    for (std::size_t i = 0; i < device.pair_count; ++i) {
        TetPair p{};
        locate(static_cast<std::uint32_t>(device.pair_keys[i] >> 32), p.object_a, p.tet_a);
        locate(static_cast<std::uint32_t>(device.pair_keys[i]), p.object_b, p.tet_b);
        pairs.push_back(p);
    }
    return pairs;
}

/// Runs a random sequence of changes on a detector with `options`, checking every frame against brute
/// force; returns every frame's pairs.
std::vector<std::vector<TetPair>> random_changes(DetectorOptions options, unsigned seed, int steps) {
    std::mt19937 rng(seed);
    Detector detector(options);
    Objects objects;
    const auto add = [&](const TetMesh& mesh) {
        const ObjectId id = detector.add_object(mesh);
        objects.meshes.push_back(mesh);
        objects.self.push_back(rng() % 2 == 0);
        detector.set_self_collision(id, objects.self.back());
        return id;
    };
    for (int i = 0; i < 3; ++i) add(random_mesh(rng));
    std::vector<std::vector<TetPair>> frames;
    for (int step = 0; step < steps; ++step) {
        const std::vector<ObjectId> live = objects.live();
        const ObjectId o = live[rng() % live.size()];
        TetMesh& mesh = *objects.meshes[o];
        std::string change;
        switch (rng() % 6) {
        case 0:
            if (live.size() < 2) break;
            change = "remove " + std::to_string(o);
            detector.remove_object(o);
            objects.meshes[o].reset();
            EXPECT_EQ(error_message([&] { detector.set_self_collision(o, true); }),
                      "object id " + std::to_string(o) + " was removed");
            break;
        case 1: { // fracture: a part of the tets stays, the rest becomes a new object on the same vertices
            change = "split " + std::to_string(o);
            auto [kept, broken_off] = split(mesh, rng);
            detector.set_tets(o, kept.tets.data(), kept.num_tets());
            mesh = kept;
            add(broken_off);
            break;
        }
        case 2: { // remeshing: new vertices and tets
            change = "replace " + std::to_string(o);
            const TetMesh next = random_mesh(rng);
            detector.set_tets(o, next);
            mesh = next;
            break;
        }
        case 3:
            change = "add";
            add(random_mesh(rng));
            break;
        case 4: { // moved, then another object's tets change before the frame
            change = "move " + std::to_string(o) + " and tear";
            mesh = test::moved(mesh, 0.3, 0.1, 0.05, 0.0);
            detector.set_positions_on_device(o, PositionsView{mesh.positions.data(), true, mesh.num_vertices()});
            const ObjectId torn = live[rng() % live.size()];
            TetMesh& other = *objects.meshes[torn];
            other.tets.resize(other.tets.size() - 4 * (other.num_tets() / 5));
            detector.set_tets(torn, other.tets.data(), other.num_tets());
            break;
        }
        default: // every tet gone, then some back
            change = "empty " + std::to_string(o);
            detector.set_tets(o, nullptr, 0);
            mesh.tets.clear();
            EXPECT_TRUE(detector.detect().colliding[o].empty());
            break;
        }
        const FrameResult& r = detector.detect();
        const FrameResult expected = oracle(objects);
        EXPECT_EQ(r.pairs, expected.pairs) << "step " << step << ": " << change;
        if (options.method != Method::kdet_no_pairs) {
            EXPECT_EQ(r.colliding, expected.colliding) << "step " << step << ": " << change;
        }
        if (options.backend == Backend::cpu) {
            EXPECT_EQ(pairs_through_first_tet(detector, objects), r.pairs) << "step " << step << ": " << change;
        }
        frames.push_back(r.pairs);
    }
    return frames;
}

TEST(Topology, RandomRemovalsSplitsAndReaddsMatchBruteForce) {
    for (unsigned seed : {1u, 2u}) random_changes(DetectorOptions{}, seed, 10);
}

TEST(Topology, TinyBuffersGrowAfterEveryChange) {
    DetectorOptions tiny;
    tiny.initial_candidate_capacity = 1;
    random_changes(tiny, 3, 8);
    tiny.method = Method::brute_force_pairs;
    random_changes(tiny, 4, 4);
}

TEST(CudaTopology, MatchesTheCpuThroughEveryChange) {
    std::string reason;
    if (!cuda_available(&reason)) GTEST_SKIP() << "CUDA backend not tested: " << reason;
    DetectorOptions gpu;
    gpu.backend = Backend::cuda;
    gpu.initial_candidate_capacity = 1;
    EXPECT_EQ(random_changes(gpu, 5, 12), random_changes(DetectorOptions{}, 5, 12));
}

TEST(Topology, TearingSceneFramesEqualAFreshDetectorOnTheFramesMeshes) {
    const std::unique_ptr<Scene> scene = open_scene("tearing");
    ASSERT_TRUE(scene->changes_tets());
    Detector detector;
    add_scene_objects(detector, *scene, true);
    std::vector<std::vector<std::uint32_t>> current = {scene->rest_mesh(0).tets, scene->rest_mesh(1).tets};
    std::size_t torn_pairs = 0;
    for (int frame : {0, 25, 60, 119}) {
        set_scene_tets(detector, *scene, frame, current);
        Detector fresh;
        for (std::size_t o = 0; o < 2; ++o) {
            TetMesh mesh;
            scene->positions(o, frame, mesh.positions);
            mesh.tets = current[o];
            fresh.set_self_collision(fresh.add_object(mesh), true);
            std::vector<double> xyz;
            scene->positions(o, frame, xyz);
            detector.set_positions(static_cast<ObjectId>(o), xyz.data(), xyz.size() / 3);
        }
        EXPECT_EQ(detector.tet_count(0), current[0].size() / 4) << frame;
        const std::vector<TetPair> expected = fresh.detect().pairs;
        EXPECT_EQ(detector.detect().pairs, expected) << "frame " << frame;
        if (frame > 0) torn_pairs += expected.size();
    }
    // The cut runs across the slab: two columns of cubes, 24 x 3 of them each, six tets a cube.
    EXPECT_EQ(scene->rest_mesh(0).tets.size() - current[0].size(), 4u * 2 * 24 * 3 * 6);
    EXPECT_GT(torn_pairs, 100u) << "the box pressed into the torn slab";
}

TEST(Topology, ExclusionsFollowTheirObjectsThroughOtherObjectsChanges) {
    // Object 1 has rings and rest contacts; object 0 before it changes its tet count and object 2
    // is removed: the pairs are those of a detector built afresh on what remains.
    const TetMesh first = random_soup(300, 2.0, 1.0, 21);
    const TetMesh crumpled = jittered_box(6, 4, 4, 0.1, 0.45, 22);
    const TetMesh third = jittered_box(4, 4, 4, 0.1, 0.45, 23, 0.2);
    const TetMesh crumpled_later = jittered_box(6, 4, 4, 0.1, 0.45, 24);
    const TetMesh first_later = random_soup(500, 2.0, 1.0, 25);
    Detector detector;
    detector.add_object(first);
    detector.set_self_collision(detector.add_object(crumpled), true);
    detector.add_object(third);
    detector.set_self_exclusion_rings(1, 1);
    detector.exclude_rest_contacts(1);
    ASSERT_GT(detector.exclude_rest_contacts(1, 2), 0u);
    detector.set_positions(1, crumpled_later.positions.data(), crumpled_later.num_vertices());
    detector.set_tets(0, first_later);
    detector.remove_object(2);

    Detector fresh;
    fresh.add_object(first_later);
    fresh.set_self_collision(fresh.add_object(crumpled), true);
    fresh.set_self_exclusion_rings(1, 1);
    fresh.exclude_rest_contacts(1);
    fresh.set_positions(1, crumpled_later.positions.data(), crumpled_later.num_vertices());
    const std::vector<TetPair> expected = fresh.detect().pairs;
    ASSERT_GT(expected.size(), 10u);
    EXPECT_EQ(detector.detect().pairs, expected);

    // Its own tets changing, it keeps its rings and forgets its rest contacts.
    detector.set_tets(1, crumpled_later.tets.data(), crumpled_later.num_tets());
    Detector rings_only;
    rings_only.add_object(first_later);
    rings_only.set_self_collision(rings_only.add_object(crumpled_later), true);
    rings_only.set_self_exclusion_rings(1, 1);
    EXPECT_EQ(detector.self_exclusion_rings(1), 1);
    EXPECT_EQ(detector.detect().pairs, rings_only.detect().pairs);
}

TEST(Topology, ARemovedIdIsAnErrorInEveryCall) {
    const TetMesh mesh = random_soup(50, 1.0, 0.5, 31);
    Detector detector;
    detector.add_object(mesh);
    detector.add_object(mesh);
    detector.remove_object(1);
    EXPECT_TRUE(detector.contains(0));
    EXPECT_FALSE(detector.contains(1));
    EXPECT_FALSE(detector.contains(2));
    EXPECT_EQ(detector.object_count(), 2u);
    const std::string removed = "object id 1 was removed";
    const std::vector<float> xyz(3 * mesh.num_vertices(), 0.0f);
    EXPECT_EQ(error_message([&] { detector.set_positions(1, xyz.data(), mesh.num_vertices()); }), removed);
    EXPECT_EQ(error_message([&] { detector.set_positions_on_device(1, xyz.data(), mesh.num_vertices()); }), removed);
    EXPECT_EQ(error_message([&] { detector.set_self_collision(1, true); }), removed);
    EXPECT_EQ(error_message([&] { detector.set_pair_collision(0, 1, true); }), removed);
    EXPECT_EQ(error_message([&] { detector.set_collision_filter(1, 1, 1); }), removed);
    EXPECT_EQ(error_message([&] { detector.collision_filter(1); }), removed);
    EXPECT_EQ(error_message([&] { detector.set_self_exclusion_rings(1, 1); }), removed);
    EXPECT_EQ(error_message([&] { detector.self_exclusion_rings(1); }), removed);
    EXPECT_EQ(error_message([&] { detector.exclude_rest_contacts(0, 1); }), removed);
    EXPECT_EQ(error_message([&] { detector.remove_object(1); }), removed);
    EXPECT_EQ(error_message([&] { detector.set_tets(1, mesh); }), removed);
    EXPECT_EQ(error_message([&] { detector.first_tet(1); }), removed);
    EXPECT_EQ(error_message([&] { detector.tet_count(1); }), removed);
    const FrameResult& r = detector.detect();
    EXPECT_EQ(r.colliding.size(), 2u);
    EXPECT_TRUE(r.colliding[1].empty());
    // A new object takes a new id.
    EXPECT_EQ(detector.add_object(mesh), 2u);
    EXPECT_EQ(detector.first_tet(2), mesh.num_tets());
}

TEST(Topology, BadTetsOrPositionsLeaveTheDetectorAsItWas) {
    const TetMesh a = jittered_box(4, 3, 3, 0.1, 0.45, 41), b = jittered_box(4, 3, 3, 0.1, 0.45, 42, 0.2);
    Detector detector;
    detector.set_self_collision(detector.add_object(a), true);
    detector.add_object(b);
    const std::vector<TetPair> before = detector.detect().pairs;
    ASSERT_FALSE(before.empty());
    std::vector<std::uint32_t> tets = a.tets;
    tets[9] = static_cast<std::uint32_t>(a.num_vertices());
    EXPECT_EQ(error_message([&] { detector.set_tets(0, tets.data(), a.num_tets()); }),
              "object 0: tet 2 has vertex index " + std::to_string(a.num_vertices()) + " out of range [0, " +
                  std::to_string(a.num_vertices()) + ")");
    TetMesh bad = b;
    bad.positions[7] = std::nan("");
    EXPECT_EQ(error_message([&] { detector.set_tets(0, bad); }),
              "object 0: vertex 2 has a non-finite coordinate (or one beyond float range)");
    EXPECT_EQ(error_message([&] { detector.set_tets(0, a.tets.data(), a.num_tets(), PositionsView{nullptr, false, 4}); }),
              "object 0: the positions' data pointer is null");
    EXPECT_EQ(detector.tet_count(0), a.num_tets());
    EXPECT_EQ(detector.first_tet(1), a.num_tets());
    EXPECT_EQ(detector.detect().pairs, before);
}

} // namespace
} // namespace kdet
