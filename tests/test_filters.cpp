// Collision filters (groups and masks), self-exclusion rings and rest contacts: every method returns
// brute force's pairs filtered in plain code, and the search finds fewer candidates with them.

#include "filter_support.hpp"
#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

namespace kdet {
namespace {

using test::brute_force_everything;
using test::error_message;
using test::jittered_box;
using test::random_soup;
using test::ring_pairs;

constexpr Method every_method[] = {Method::kdet, Method::brute_force_loop, Method::brute_force_pairs, Method::kdet_no_pairs};

DetectorOptions with_method(Method method) {
    DetectorOptions o;
    o.method = method;
    return o;
}

/// Flags implied by a pair list, one vector per object of `tets` tets each.
std::vector<std::vector<std::uint8_t>> flags_of(const std::vector<TetPair>& pairs, const std::vector<std::size_t>& tets) {
    std::vector<std::vector<std::uint8_t>> flags;
    for (std::size_t n : tets) flags.emplace_back(n, 0);
    for (const TetPair& p : pairs) flags[p.object_a][p.tet_a] = flags[p.object_b][p.tet_b] = 1;
    return flags;
}

/// The detection's pairs equal `expected` (for kdet_no_pairs: its flags equal those they imply).
void expect_result(Method method, const FrameResult& r, const std::vector<TetPair>& expected, const std::vector<std::size_t>& tets) {
    if (method == Method::kdet_no_pairs)
        EXPECT_EQ(r.colliding, flags_of(expected, tets)) << to_string(method);
    else
        EXPECT_EQ(r.pairs, expected) << to_string(method);
}

std::vector<std::size_t> tet_counts(const std::vector<TetMesh>& meshes) {
    std::vector<std::size_t> n;
    for (const TetMesh& m : meshes) n.push_back(m.num_tets());
    return n;
}

TEST(Filters, GroupsAndMasksMatchFilteredBruteForceAndSaveCandidates) {
    std::vector<TetMesh> meshes;
    for (unsigned seed = 1; seed <= 4; ++seed) meshes.push_back(random_soup(700, 5.0, 1.5, seed));
    const std::vector<TetPair> all = brute_force_everything(meshes);
    // Groups: 0 and 1 are "debris" (bit 1) that ignore each other, 2 is a "body" (bit 2) that hits
    // everything, 3 is in both groups but only accepts bodies. Explicit switches win either way.
    const CollisionFilter filter[4] = {{1u, ~1u}, {1u, ~1u}, {2u, ~0u}, {3u, 2u}};
    const auto passes = [&](std::uint32_t a, std::uint32_t b) {
        if ((a == 0 && b == 3) || (a == 1 && b == 2)) return a == 0; // switched on and off explicitly
        return (filter[a].group & filter[b].mask) && (filter[b].group & filter[a].mask);
    };
    std::vector<TetPair> expected;
    for (const TetPair& p : all)
        if (p.object_a != p.object_b ? passes(p.object_a, p.object_b) : p.object_a == 2) expected.push_back(p);
    ASSERT_GT(expected.size(), 20u);
    ASSERT_LT(expected.size(), all.size() / 2);

    for (Method method : every_method) {
        Detector plain(with_method(method)), filtered(with_method(method));
        for (const TetMesh& m : meshes) plain.add_object(m), filtered.add_object(m);
        filtered.set_pair_collision(0, 3, true); // before the filters that would switch it off
        for (ObjectId o = 0; o < 4; ++o) filtered.set_collision_filter(o, filter[o].group, filter[o].mask);
        filtered.set_pair_collision(1, 2, false); // after filters that would switch it on
        filtered.set_self_collision(2, true);
        plain.set_self_collision(2, true);
        EXPECT_EQ(filtered.collision_filter(3).group, 3u);
        EXPECT_EQ(filtered.collision_filter(3).mask, 2u);
        const FrameCounts without = plain.detect().counts;
        const FrameResult& r = filtered.detect();
        expect_result(method, r, expected, tet_counts(meshes));
        EXPECT_LT(r.counts.candidates, without.candidates) << to_string(method);
    }
}

TEST(Filters, DefaultFiltersCheckEveryPairAndAGroupOfZeroNone) {
    const std::vector<TetMesh> meshes = {random_soup(500, 4.0, 1.0, 7), random_soup(500, 4.0, 1.0, 8)};
    Detector detector;
    for (const TetMesh& m : meshes) detector.add_object(m);
    EXPECT_EQ(detector.collision_filter(0).group, 1u);
    EXPECT_EQ(detector.collision_filter(0).mask, ~0u);
    const std::vector<TetPair> pairs = detector.detect().pairs;
    ASSERT_FALSE(pairs.empty());
    detector.set_collision_filter(1, 0u, ~0u);
    EXPECT_TRUE(detector.detect().pairs.empty());
    EXPECT_EQ(detector.detect().counts.candidates, 0u);
    detector.set_collision_filter(1, 1u, ~0u);
    EXPECT_EQ(detector.detect().pairs, pairs);
}

TEST(Filters, ExclusionRingsMatchTheRingsOfTheMeshOnEveryMethod) {
    // A crumpled bar touches itself between near neighbours and where it is wound over itself; a
    // second copy overlaps it, so rings
    // (which only act within one object) leave the pairs between the two alone.
    const TetMesh crumpled = test::crumpled_bar(30, 0.45, 3);
    const TetMesh other = jittered_box(4, 4, 4, 0.1, 0.45, 4, 0.3);
    const std::vector<TetPair> all = brute_force_everything({crumpled, other});
    // Up to the most rings: each pair is listed once, under its lower tet, and each method meets it
    // from either side.
    for (int rings : {1, 2, max_exclusion_rings}) {
        const auto near = ring_pairs(crumpled, rings);
        std::vector<TetPair> expected;
        std::size_t left_out = 0;
        for (const TetPair& p : all) {
            if (p.object_a == 1 && p.object_b == 1) continue; // the copy does not self-collide here
            const bool excluded = p.object_a == 0 && p.object_b == 0 && near.count({p.tet_a, p.tet_b});
            left_out += excluded;
            if (!excluded) expected.push_back(p);
        }
        ASSERT_GT(left_out, 10u) << rings;
        ASSERT_GT(std::count_if(expected.begin(), expected.end(), [](const TetPair& p) { return p.object_b == 0; }), 0)
            << "some self pairs lie beyond the rings";
        for (Method method : every_method) {
            Detector plain(with_method(method)), filtered(with_method(method));
            for (Detector* d : {&plain, &filtered}) {
                d->set_self_collision(d->add_object(crumpled), true);
                d->add_object(other);
            }
            filtered.set_self_exclusion_rings(0, rings);
            EXPECT_EQ(filtered.self_exclusion_rings(0), rings);
            const FrameResult& r = filtered.detect();
            expect_result(method, r, expected, {crumpled.num_tets(), other.num_tets()});
            if (method == Method::kdet) {
                EXPECT_LT(r.counts.candidates, plain.detect().counts.candidates);
            }
        }
    }
    // Back to shared vertices only: every self pair again.
    Detector detector;
    detector.set_self_collision(detector.add_object(crumpled), true);
    detector.add_object(other);
    const std::vector<TetPair> before = detector.detect().pairs;
    detector.set_self_exclusion_rings(0, 2);
    EXPECT_NE(detector.detect().pairs, before);
    detector.set_self_exclusion_rings(0, 0);
    EXPECT_EQ(detector.detect().pairs, before);
}

TEST(Filters, RestContactsAreNeverReportedAgainWhileNewContactsAre) {
    const TetMesh rest = jittered_box(6, 5, 4, 0.1, 0.45, 5);
    const TetMesh neighbour = jittered_box(5, 5, 4, 0.1, 0.45, 6, 0.4);
    const TetMesh moved = jittered_box(6, 5, 4, 0.1, 0.45, 7); // the same mesh, crumpled otherwise
    const std::vector<TetPair> at_rest = brute_force_everything({rest, neighbour});
    const std::vector<TetPair> later = brute_force_everything({moved, neighbour});
    std::set<TetPair> recorded;
    for (const TetPair& p : at_rest)
        if (p.object_a == 0) recorded.insert(p); // inside 0 and between 0 and 1
    std::vector<TetPair> expected;
    for (const TetPair& p : later)
        if (!(p.object_a == 1 && p.object_b == 1) && !recorded.count(p)) expected.push_back(p);
    ASSERT_GT(recorded.size(), 20u);
    ASSERT_GT(expected.size(), 20u);
    ASSERT_LT(expected.size(), later.size() - 10);

    for (Method method : every_method) {
        Detector plain(with_method(method)), filtered(with_method(method));
        for (Detector* d : {&plain, &filtered}) {
            d->set_self_collision(d->add_object(rest), true);
            d->add_object(neighbour);
        }
        std::size_t self_pairs = 0;
        for (const TetPair& p : recorded) self_pairs += p.object_b == 0;
        EXPECT_EQ(filtered.exclude_rest_contacts(0), self_pairs);
        EXPECT_EQ(filtered.exclude_rest_contacts(1, 0), recorded.size() - self_pairs);
        EXPECT_EQ(filtered.exclude_rest_contacts(0), self_pairs) << "recording again adds nothing new";
        const FrameResult& r = filtered.detect();
        if (method != Method::kdet_no_pairs) {
            EXPECT_TRUE(r.pairs.empty()) << to_string(method);
            EXPECT_LT(r.counts.candidates, plain.detect().counts.candidates) << to_string(method);
        }
        filtered.set_positions(0, moved.positions.data(), moved.num_vertices());
        expect_result(method, filtered.detect(), expected, {rest.num_tets(), neighbour.num_tets()});
    }
}

TEST(Filters, RestContactsReadPositionsGivenOnTheDeviceAndTheFrameUsesThem) {
    // On the CPU backend "device" memory is the host's: the positions wait in the staging buffer.
    const TetMesh rest = jittered_box(6, 5, 4, 0.1, 0.45, 5), moved = jittered_box(6, 5, 4, 0.1, 0.45, 7);
    Detector detector;
    detector.set_self_collision(detector.add_object(rest), true);
    ASSERT_FALSE(detector.detect().pairs.empty());
    detector.set_positions_on_device(0, PositionsView{moved.positions.data(), true, moved.num_vertices()});
    EXPECT_GT(detector.exclude_rest_contacts(0), 20u);
    EXPECT_TRUE(detector.detect().pairs.empty());
}

TEST(CudaFilters, GroupsRingsAndRestContactsMatchTheCpu) {
    std::string reason;
    if (!cuda_available(&reason)) GTEST_SKIP() << "CUDA backend not tested: " << reason;
    const TetMesh crumpled = test::crumpled_bar(30, 0.45, 3), moved = test::crumpled_bar(30, 0.45, 4);
    const TetMesh box = jittered_box(4, 4, 4, 0.1, 0.45, 4, 0.3);
    const TetMesh soup = random_soup(400, 2.0, 1.0, 5);
    const auto frames = [&](Backend backend) {
        DetectorOptions options;
        options.backend = backend;
        options.initial_candidate_capacity = 1;
        Detector detector(options);
        detector.set_self_collision(detector.add_object(crumpled), true);
        detector.set_self_collision(detector.add_object(box), true);
        detector.add_object(soup);
        detector.set_self_exclusion_rings(0, 1);
        detector.exclude_rest_contacts(1);
        detector.exclude_rest_contacts(0, 1);
        detector.set_collision_filter(1, 3u, ~0u);
        detector.set_collision_filter(2, 2u, 2u); // against object 1 only
        std::vector<std::vector<TetPair>> out{detector.detect().pairs};
        detector.set_positions(0, moved.positions.data(), moved.num_vertices());
        out.push_back(detector.detect().pairs);
        return out;
    };
    const auto gpu = frames(Backend::cuda);
    EXPECT_FALSE(gpu.back().empty());
    EXPECT_EQ(gpu, frames(Backend::cpu));
}

TEST(Filters, BadInputIsOneLineAndLeavesTheDetectorAsItWas) {
    const TetMesh mesh = jittered_box(5, 4, 4, 0.1, 0.45, 9);
    Detector detector;
    detector.set_self_collision(detector.add_object(mesh), true);
    detector.set_self_exclusion_rings(0, 1);
    const std::vector<TetPair> before = detector.detect().pairs;
    EXPECT_EQ(error_message([&] { detector.set_self_exclusion_rings(0, -1); }),
              "object 0: exclusion rings -1 out of range [0, 4]");
    EXPECT_EQ(error_message([&] { detector.set_self_exclusion_rings(0, max_exclusion_rings + 1); }),
              "object 0: exclusion rings 5 out of range [0, 4]");
    EXPECT_EQ(error_message([&] { detector.set_collision_filter(1, 1, 1); }), "object id 1 out of range (1 objects)");
    EXPECT_EQ(error_message([&] { detector.exclude_rest_contacts(0, 3); }), "object id 3 out of range (1 objects)");
    EXPECT_EQ(detector.self_exclusion_rings(0), 1);
    EXPECT_EQ(detector.detect().pairs, before);
}

} // namespace
} // namespace kdet
