// The scenes of issue 46 built in code (heap, drape, graded) and the scene file's `static` statement: the
// scenes are deterministic, their static objects never move, and a frame's pairs with the static
// objects placed once equal those with every object moving (which tests/test_pipeline.cpp holds to
// brute force), minus the pairs of two static objects; heap's collision filters leave out what brute
// force with the same filters leaves out.

#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace kdet {
namespace {

namespace fs = std::filesystem;
using test::error_message;

/// The pairs of `frames` of `scene`, the scene's static objects static (placed once and kept), or every
/// object moving with the static-static pairs removed afterwards; self-collision of every object as `self`.
std::vector<std::vector<TetPair>> pairs_of(const Scene& scene, const std::vector<int>& frames, bool self, bool use_static) {
    Detector detector;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        const ObjectId id = detector.add_object(scene.rest_mesh(o));
        detector.set_self_collision(id, self && !(scene.is_static(o) && use_static));
        detector.set_static(id, use_static && scene.is_static(o));
    }
    std::vector<std::vector<TetPair>> out;
    std::vector<float> xyz;
    for (int frame : frames) {
        for (std::size_t o = 0; o < scene.num_objects(); ++o) {
            if (use_static && scene.is_static(o) && frame != frames.front()) continue;
            scene.positions(o, frame, xyz);
            detector.set_positions(static_cast<ObjectId>(o), xyz.data(), xyz.size() / 3);
        }
        std::vector<TetPair> kept;
        for (const TetPair& p : detector.detect().pairs)
            if (!(scene.is_static(p.object_a) && scene.is_static(p.object_b))) kept.push_back(p);
        out.push_back(kept);
    }
    return out;
}

void expect_static_placement_changes_nothing(const Scene& scene, const std::vector<int>& frames, bool self) {
    const auto placed = pairs_of(scene, frames, self, true), moving = pairs_of(scene, frames, self, false);
    for (std::size_t i = 0; i < frames.size(); ++i) {
        EXPECT_TRUE(placed[i] == moving[i]) << scene.name() << " frame " << frames[i] << ": " << placed[i].size() << " vs "
                                            << moving[i].size() << " pairs";
        EXPECT_GT(moving[i].size(), 0u) << scene.name() << " frame " << frames[i];
    }
}

void expect_static_objects_still(const Scene& scene) {
    std::vector<double> first, later;
    bool any = false;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        if (!scene.is_static(o)) continue;
        any = true;
        scene.positions(o, 0, first);
        scene.positions(o, scene.num_frames() - 1, later);
        EXPECT_EQ(first, later) << scene.name() << " object " << o;
    }
    EXPECT_TRUE(any) << scene.name();
}

TEST(GeneratedScenes, HeapFallsOntoAStaticFloor) {
    const auto heap = open_scene("heap");
    EXPECT_EQ(heap->name(), "heap");
    ASSERT_EQ(heap->num_objects(), 126u);
    EXPECT_TRUE(heap->is_static(0));
    EXPECT_FALSE(heap->is_static(1));
    expect_static_objects_still(*heap);
    // Bodies move while they fall: the top layer's first body is higher at the start than at the end.
    std::vector<double> start, end;
    heap->positions(125, 0, start);
    heap->positions(125, heap->num_frames() - 1, end);
    EXPECT_GT(start[1], end[1] + 1.0);
    expect_static_placement_changes_nothing(*heap, {40, 119}, false);
    EXPECT_EQ(error_message([] { make_heap_scene(5); }), "heap: resolution 5 out of range [1, 4]");
}

TEST(GeneratedScenes, DrapeWrapsAStaticBallAndFoldsOnItself) {
    const auto drape = open_scene("drape");
    ASSERT_EQ(drape->num_objects(), 2u);
    EXPECT_TRUE(drape->is_static(0));
    EXPECT_TRUE(drape->checks_self(1));
    EXPECT_EQ(drape->rest_mesh(1).num_tets(), 40u * 40u * 6u);
    expect_static_objects_still(*drape);
    // The sheet lies on the ball from frame 30 on, and its folds touch themselves at the end.
    expect_static_placement_changes_nothing(*drape, {60, 119}, true);
    Detector detector;
    const ObjectId sheet = detector.add_object(drape->rest_mesh(1));
    detector.set_self_collision(sheet, true);
    std::vector<float> xyz;
    drape->positions(1, 119, xyz);
    detector.set_positions(sheet, xyz.data(), xyz.size() / 3);
    EXPECT_GT(detector.detect().pairs.size(), 100u) << "the folded sheet collides with itself";
    drape->positions(1, 40, xyz);
    detector.set_positions(sheet, xyz.data(), xyz.size() / 3);
    EXPECT_EQ(detector.detect().pairs.size(), 0u) << "the sheet lying on the ball does not";
}

TEST(GeneratedScenes, GradedSizesSpanThreeDecades) {
    const auto graded = open_scene("graded");
    ASSERT_EQ(graded->num_objects(), 2u);
    EXPECT_TRUE(graded->is_static(0));
    const TetMesh& block = graded->rest_mesh(0);
    double smallest = 1e300, largest = 0;
    for (std::size_t t = 0; t < block.num_tets(); ++t) {
        double longest = 0;
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j) {
                double d2 = 0;
                for (int a = 0; a < 3; ++a) {
                    const double d = block.positions[3 * block.tets[4 * t + i] + a] - block.positions[3 * block.tets[4 * t + j] + a];
                    d2 += d * d;
                }
                longest = std::max(longest, std::sqrt(d2));
            }
        smallest = std::min(smallest, longest);
        largest = std::max(largest, longest);
    }
    EXPECT_GE(largest / smallest, 1000.0);
    expect_static_objects_still(*graded);
    expect_static_placement_changes_nothing(*graded, {50, 59, 70}, true);
}

/// The pairs of `scene` at `frame` found by `method`, its objects added as add_scene_objects does.
std::vector<TetPair> scene_pairs(const Scene& scene, int frame, Method method, bool filters) {
    DetectorOptions options;
    options.method = method;
    Detector detector(options);
    if (filters) {
        add_scene_objects(detector, scene, false);
    } else {
        for (std::size_t o = 0; o < scene.num_objects(); ++o) detector.add_object(scene.rest_mesh(o));
    }
    std::vector<float> xyz;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        scene.positions(o, frame, xyz);
        detector.set_positions(static_cast<ObjectId>(o), xyz.data(), xyz.size() / 3);
    }
    return detector.detect().pairs;
}

TEST(GeneratedScenes, HeapFiltersLeaveOutPairsWithinALayer) {
    const auto heap = open_scene("heap");
    EXPECT_EQ(heap->collision_filter(0).group, CollisionFilter{}.group) << "the floor";
    EXPECT_EQ(heap->collision_filter(0).mask, CollisionFilter{}.mask);
    const int frame = heap->num_frames() - 1; // every layer at rest on the one below
    const std::vector<TetPair> filtered = scene_pairs(*heap, frame, Method::kdet, true);
    EXPECT_EQ(filtered, scene_pairs(*heap, frame, Method::brute_force_loop, true));
    // The same as every pair with the filters' rule applied afterwards.
    std::vector<TetPair> kept;
    std::size_t floor = 0, layers = 0, same_layer = 0;
    for (const TetPair& p : scene_pairs(*heap, frame, Method::kdet, false)) {
        const CollisionFilter a = heap->collision_filter(p.object_a), b = heap->collision_filter(p.object_b);
        if ((a.group & b.mask) != 0 && (b.group & a.mask) != 0) {
            kept.push_back(p);
            (p.object_a == 0 ? floor : layers) += 1;
        } else {
            same_layer += a.group == b.group;
        }
    }
    EXPECT_EQ(filtered, kept);
    EXPECT_GT(floor, 0u) << "the bottom layer lies in the floor";
    EXPECT_GT(layers, 0u) << "layers press on each other";
    EXPECT_GT(same_layer, 0u) << "bodies side by side in a layer overlap, and the filters leave them out";
}

TEST(GeneratedScenes, SameFramesEveryTime) {
    for (const char* name : {"heap", "drape", "graded"}) {
        const auto a = open_scene(name), b = open_scene(name);
        std::vector<float> pa, pb;
        for (std::size_t o : {std::size_t{0}, a->num_objects() - 1}) {
            a->positions(o, 77, pa);
            b->positions(o, 77, pb);
            EXPECT_EQ(pa, pb) << name;
        }
        EXPECT_NE(std::find(scene_names().begin(), scene_names().end(), name), scene_names().end());
    }
}

TEST(GeneratedScenes, SceneFileStaticObjects) {
    const fs::path dir = fs::temp_directory_path() / "kdet-static-scene";
    fs::create_directories(dir);
    write_tet_mesh(make_box_mesh(4, 4, 1, 0.25), (dir / "floor.node").string());
    write_tet_mesh(make_box_mesh(2, 2, 2, 0.1), (dir / "box.node").string());
    std::ofstream(dir / "s.scene") << "kdet-scene 1\nframes 10\nobject floor\n  file floor.node\n  static\n"
                                      "object box\n  file box.node\n  key 0 move 0.3 0.3 0.3\n  key 9 move 0.3 0.3 0\n";
    const auto scene = read_scene_file((dir / "s.scene").string());
    EXPECT_TRUE(scene->is_static(0));
    EXPECT_FALSE(scene->is_static(1));
    expect_static_placement_changes_nothing(*scene, {9}, false);
    std::ofstream(dir / "bad.scene") << "kdet-scene 1\nframes 10\nobject floor\n  file floor.node\n  static\n"
                                        "  key 0 move 0 0 1\n";
    EXPECT_EQ(error_message([&] { read_scene_file((dir / "bad.scene").string()); }),
              (dir / "bad.scene").string() + ":3: object 'floor' is static but has keys or a wobble: a static object never moves");
    fs::remove_all(dir);
}

} // namespace
} // namespace kdet
