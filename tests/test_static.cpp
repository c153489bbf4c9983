// Static objects (Detector::set_static): every frame's pairs equal brute force on the same objects with
// the pairs of two static objects (and static self-collision) left out, whatever the tets' sizes, as
// objects turn static and moving again and static objects are moved by set_positions.

#include "filter_support.hpp"
#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/locate.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>

#include <iterator>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace kdet {
namespace {

using test::error_message;
using test::jittered_box;
using test::moved;
using test::random_soup;

/// The objects of one frame: meshes at their current positions, which are static, which self-collide.
struct Objects {
    std::vector<TetMesh> meshes;
    std::vector<bool> is_static;
    std::vector<bool> self;
};

/// Brute force on every pair (within `margin`), without static flags, then the pairs static objects
/// cannot report removed.
std::vector<TetPair> oracle(const Objects& s, float margin = 0.0f) {
    DetectorOptions options;
    options.method = Method::brute_force_loop;
    options.margin = margin;
    Detector detector(options);
    for (std::size_t o = 0; o < s.meshes.size(); ++o)
        detector.set_self_collision(detector.add_object(s.meshes[o]), s.self[o]);
    std::vector<TetPair> kept;
    for (const TetPair& p : detector.detect().pairs)
        if (!(s.is_static[p.object_a] && s.is_static[p.object_b])) kept.push_back(p);
    return kept;
}

/// Adds the meshes (positions as given) with their flags.
void add_all(Detector& detector, const Objects& s) {
    for (std::size_t o = 0; o < s.meshes.size(); ++o) {
        const ObjectId id = detector.add_object(s.meshes[o]);
        detector.set_self_collision(id, s.self[o]);
        detector.set_static(id, s.is_static[o]);
    }
}

/// A mix of moving and static soups and meshes whose tet sizes differ by up to 100 times either way.
Objects random_setup(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> coin(0, 1);
    Objects s;
    // A fine static block, coarse and fine soups, and a few tets 100 times the fine ones' size.
    s.meshes.push_back(make_box_mesh(6, 6, 6, 0.17));
    s.meshes.push_back(random_soup(300, 1.0, 2.0, seed * 7 + 1));
    s.meshes.push_back(random_soup(200, 1.0, 0.5, seed * 7 + 2));
    s.meshes.push_back(moved(random_soup(6, 0.5, 0.0, seed * 7 + 3), 0.3, 0.3, 0.3, 0.3));
    s.meshes.push_back(moved(make_box_mesh(3, 3, 3, 0.01), 0.2, 0.5, 0.45, 0.5));
    for (std::size_t o = 0; o < s.meshes.size(); ++o) {
        s.is_static.push_back(coin(rng) != 0);
        s.self.push_back(coin(rng) != 0);
    }
    return s;
}

/// Checks the detector's next frame against the oracle (within `margin`); returns the pairs found.
std::size_t expect_pairs(Detector& detector, const Objects& s, const std::string& what, float margin = 0.0f) {
    const std::vector<TetPair> expected = oracle(s, margin);
    const FrameResult& r = detector.detect();
    EXPECT_EQ(r.pairs.size(), expected.size()) << what;
    EXPECT_TRUE(r.pairs == expected) << what;
    return expected.size();
}

TEST(Static, RandomMixesEqualBruteForce) {
    std::size_t pairs = 0;
    for (unsigned seed = 1; seed <= 8; ++seed) {
        const Objects s = random_setup(seed);
        for (Method method : {Method::kdet, Method::brute_force_pairs}) {
            DetectorOptions options;
            options.method = method;
            Detector detector(options);
            add_all(detector, s);
            pairs += expect_pairs(detector, s, "seed " + std::to_string(seed) + ", method " + to_string(method));
        }
    }
    EXPECT_GT(pairs, 1000u);
}

TEST(Static, PairsWithinAMarginEqualBruteForce) {
    // Margins below the finest tets' size and several times it: a moving tet must find every static tet
    // within the margin, whichever of them is larger and however far the grown boxes reach.
    std::size_t pairs = 0, without_margin = 0;
    for (unsigned seed = 1; seed <= 2; ++seed) {
        const Objects s = random_setup(seed);
        without_margin += oracle(s).size();
        for (float margin : {0.004f, 0.05f}) {
            DetectorOptions options;
            options.margin = margin;
            Detector detector(options);
            add_all(detector, s);
            pairs += expect_pairs(detector, s, "seed " + std::to_string(seed) + ", margin " + std::to_string(margin), margin);
        }
    }
    EXPECT_GT(pairs, 2 * without_margin);
}

TEST(Static, SizesDifferingHundredTimesBothWays) {
    // A block of tets about 0.03 across against one tet about 3 across that cuts through it, the
    // block static and the tet moving, then the other way round: each side the larger once.
    for (bool big_moves : {true, false}) {
        Objects s;
        s.meshes.push_back(make_box_mesh(12, 12, 12, 0.015));
        s.meshes.push_back(random_soup(1, 1.0, 0.0, 5));
        s.meshes[1].positions = {0.1, 0.1, -1.0, 2.0, 0.1, 0.0, 0.1, 2.0, 0.0, 0.1, 0.1, 2.0};
        s.is_static = {!big_moves, big_moves};
        s.self = {!big_moves, big_moves};
        Detector detector;
        add_all(detector, s);
        EXPECT_GT(expect_pairs(detector, s, big_moves ? "big tet moving" : "big tet static"), 100u);
    }
}

TEST(Static, TogglingAndMovingStaticObjects) {
    Objects s = random_setup(99);
    s.is_static = {true, false, true, false, true};
    Detector detector;
    add_all(detector, s);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> shift(-0.15, 0.15);
    std::size_t pairs = 0;
    for (int frame = 0; frame < 10; ++frame) {
        const std::string what = "frame " + std::to_string(frame);
        pairs += expect_pairs(detector, s, what);
        // Move one object (static or not) by set_positions, and turn another static or moving.
        const std::size_t mover = static_cast<std::size_t>(frame) % s.meshes.size();
        s.meshes[mover] = moved(s.meshes[mover], 0.1, shift(rng), shift(rng), shift(rng));
        detector.set_positions(static_cast<ObjectId>(mover), s.meshes[mover].positions.data(), s.meshes[mover].num_vertices());
        const std::size_t toggled = static_cast<std::size_t>(frame * 3 + 1) % s.meshes.size();
        if (frame % 3 == 2) {
            s.is_static[toggled] = !s.is_static[toggled];
            detector.set_static(static_cast<ObjectId>(toggled), s.is_static[toggled]);
            EXPECT_EQ(detector.is_static(static_cast<ObjectId>(toggled)), s.is_static[toggled]);
        }
    }
    EXPECT_GT(pairs, 1000u);
}

TEST(Static, StaticObjectsKeepTheirPlaceAcrossFrames) {
    // A moving body passing through a static block: the static block is placed once, the body moves.
    Objects s;
    s.meshes.push_back(make_box_mesh(10, 10, 10, 0.1));
    s.meshes.push_back(moved(make_torus_mesh(0.3, 0.1, 800), 0.0, -0.3, 0.5, 0.5));
    s.is_static = {true, false};
    s.self = {false, true};
    Detector detector;
    add_all(detector, s);
    for (int frame = 0; frame < 6; ++frame) {
        EXPECT_GT(expect_pairs(detector, s, "frame " + std::to_string(frame)), 0u);
        s.meshes[1] = moved(s.meshes[1], 0.2, 0.25, 0.0, 0.0);
        detector.set_positions(1, s.meshes[1].positions.data(), s.meshes[1].num_vertices());
    }
}

TEST(Static, AllStaticReportsNothing) {
    Objects s = random_setup(4);
    s.is_static.assign(s.meshes.size(), true);
    Detector detector;
    add_all(detector, s);
    EXPECT_TRUE(detector.detect().pairs.empty());
    EXPECT_TRUE(oracle(s).empty());
}

TEST(Static, BadObjectIdIsAnError) {
    Detector detector;
    detector.add_object(make_box_mesh(1, 1, 1, 1.0));
    EXPECT_EQ(error_message([&] { detector.set_static(3, true); }), "object id 3 out of range (1 objects)");
    EXPECT_EQ(error_message([&] { (void)detector.is_static(1); }), "object id 1 out of range (1 objects)");
    EXPECT_FALSE(detector.is_static(0));
}

/// Static objects with filters and topology changes, as plain data: each object's mesh and whether
/// it is still there, static, self-colliding; the object pairs the groups turn off; the tet pairs
/// excluded (rings, rest contacts).
struct Filtered {
    std::vector<TetMesh> meshes;
    std::vector<bool> present, is_static, self;
    std::set<std::pair<std::uint32_t, std::uint32_t>> off;
    std::set<TetPair> excluded;

    /// Brute force on the objects still there, every pair on, filtered here.
    std::vector<TetPair> oracle() const {
        std::vector<TetMesh> there;
        std::vector<std::uint32_t> id;
        for (std::uint32_t o = 0; o < meshes.size(); ++o)
            if (present[o]) {
                there.push_back(meshes[o]);
                id.push_back(o);
            }
        std::vector<TetPair> kept;
        for (TetPair p : test::brute_force_everything(there)) {
            p.object_a = id[p.object_a];
            p.object_b = id[p.object_b];
            if (p.object_a == p.object_b && !self[p.object_a]) continue;
            if ((is_static[p.object_a] && is_static[p.object_b]) || off.count({p.object_a, p.object_b}) || excluded.count(p))
                continue;
            kept.push_back(p);
        }
        return kept;
    }
    /// Forgets the excluded pairs naming object o's tets (its tets changed or it was removed).
    void forget(std::uint32_t o) {
        for (auto p = excluded.begin(); p != excluded.end();) p = p->object_a == o || p->object_b == o ? excluded.erase(p) : std::next(p);
    }
};

/// Every other tet of `mesh` but each third (its vertices kept).
std::vector<std::uint32_t> thinned(const TetMesh& mesh) {
    std::vector<std::uint32_t> tets;
    for (std::size_t t = 0; t < mesh.num_tets(); ++t)
        if (t % 3 != 2) tets.insert(tets.end(), mesh.tets.begin() + 4 * t, mesh.tets.begin() + 4 * t + 4);
    return tets;
}

TEST(Static, FiltersRestContactsAndTopologyChangesWithAStaticObjectEqualBruteForce) {
    // A static block stored first (so the pipeline stores its tets behind the moving ones'), a moving
    // block crumpled into it, a moving soup across both that the groups keep off the static block.
    Filtered s;
    s.meshes = {jittered_box(6, 5, 4, 0.1, 0.45, 5), jittered_box(5, 5, 4, 0.1, 0.45, 6, 0.4), random_soup(150, 1.0, 1.0, 11)};
    s.present = {true, true, true};
    s.is_static = {true, false, false};
    s.self = {true, true, true};
    s.off = {{0, 2}};
    for (Method method : {Method::kdet, Method::brute_force_pairs}) {
        Filtered f = s;
        DetectorOptions options;
        options.method = method;
        Detector detector(options);
        for (std::uint32_t o = 0; o < f.meshes.size(); ++o) {
            detector.add_object(f.meshes[o]);
            detector.set_self_collision(o, f.self[o]);
            detector.set_static(o, f.is_static[o]);
        }
        detector.set_collision_filter(0, 1u, ~2u);
        detector.set_collision_filter(2, 2u, ~0u);
        detector.set_self_exclusion_rings(1, 1);
        for (const auto& [t, u] : test::ring_pairs(f.meshes[1], 1)) f.excluded.insert(TetPair{1, t, 1, u});
        std::size_t pairs = 0;
        const auto check = [&](const std::string& what) {
            const std::vector<TetPair> expected = f.oracle();
            const FrameResult& r = detector.detect();
            EXPECT_EQ(r.pairs.size(), expected.size()) << to_string(method) << ": " << what;
            EXPECT_TRUE(r.pairs == expected) << to_string(method) << ": " << what;
            pairs += expected.size();
        };
        // Rest contacts between the moving block and the static one, recorded where they lie now.
        const auto record_rest_contacts = [&] {
            std::set<TetPair> rest;
            for (const TetPair& p : f.oracle())
                if (p.object_a == 0 && p.object_b == 1) rest.insert(p);
            EXPECT_GT(rest.size(), 20u);
            EXPECT_EQ(detector.exclude_rest_contacts(1, 0), rest.size());
            f.excluded.insert(rest.begin(), rest.end());
        };
        check("at first");
        record_rest_contacts();
        check("rest contacts excluded");
        f.meshes[1] = jittered_box(5, 5, 4, 0.1, 0.45, 16, 0.35);
        detector.set_positions(1, f.meshes[1].positions.data(), f.meshes[1].num_vertices());
        check("the moving block moved");
        const std::vector<std::uint32_t> tets0 = thinned(f.meshes[0]);
        detector.set_tets(0, tets0.data(), tets0.size() / 4);
        f.meshes[0].tets = tets0;
        f.forget(0);
        check("the static block's tets set");
        record_rest_contacts();
        check("rest contacts recorded again");
        const std::vector<std::uint32_t> tets2 = thinned(f.meshes[2]);
        detector.set_tets(2, tets2.data(), tets2.size() / 4);
        f.meshes[2].tets = tets2;
        detector.set_static(2, true);
        f.is_static[2] = true;
        check("the soup's tets set, then the soup static");
        detector.remove_object(0);
        f.present[0] = false;
        f.forget(0);
        check("the static block removed");
        detector.set_static(2, false);
        f.is_static[2] = false;
        check("the soup moving again");
        EXPECT_GT(pairs, 500u) << to_string(method);
    }
}

TEST(Static, LocateFindsTheTetsOfStaticObjects) {
    // The static object is stored behind the moving one: each object's tets and all of them are
    // located as in a detector without static objects.
    const std::vector<TetMesh> meshes = {jittered_box(5, 5, 4, 0.1, 0.3, 5), jittered_box(5, 5, 4, 0.1, 0.3, 6, 0.3)};
    std::vector<double> points;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> x(0.0, 0.8), yz(0.0, 0.4); // the blocks' union
    for (int p = 0; p < 500; ++p) points.insert(points.end(), {x(rng), yz(rng), yz(rng)});
    const PositionsView view{points.data(), true, points.size() / 3};
    Detector plain, with_static;
    for (Detector* d : {&plain, &with_static})
        for (const TetMesh& m : meshes) d->add_object(m);
    with_static.set_static(0, true);
    with_static.detect();
    for (ObjectId object : {ObjectId{0}, ObjectId{1}, all_objects}) {
        const LocateResult expected = plain.locate(view, object);
        const LocateResult& r = with_static.locate(view, object);
        EXPECT_GT(expected.hit_count, 100u) << object;
        EXPECT_EQ(r.offsets, expected.offsets) << object;
        EXPECT_EQ(r.objects, expected.objects) << object;
        EXPECT_EQ(r.tets, expected.tets) << object;
        EXPECT_EQ(r.barycentrics, expected.barycentrics) << object;
    }
}

TEST(Static, CudaEqualsCpu) {
    std::string reason;
    if (!cuda_available(&reason)) GTEST_SKIP() << "CUDA backend not tested: " << reason;
    for (unsigned seed = 1; seed <= 6; ++seed) {
        const Objects s = random_setup(seed);
        DetectorOptions gpu;
        gpu.backend = Backend::cuda;
        Detector cpu_detector, gpu_detector(gpu);
        add_all(cpu_detector, s);
        add_all(gpu_detector, s);
        const FrameResult& a = cpu_detector.detect();
        const FrameResult& b = gpu_detector.detect();
        EXPECT_TRUE(a.pairs == b.pairs) << "seed " << seed;
        EXPECT_EQ(a.colliding, b.colliding) << "seed " << seed;
    }
}

} // namespace
} // namespace kdet
