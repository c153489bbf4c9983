// Scene files, the thesis scenes and recorded scenes.

#include "prepare_support.hpp"
#include "scenes/scripted_scene.hpp"
#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <ostream>
#include <string>
#include <unistd.h>

namespace kdet::test {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("kdet-scene-test-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string parse_error(const std::string& text) {
    try {
        scenes::parse_scene(text, "s.scene");
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

TEST(SceneFile, ErrorsNameFileAndLine) {
    EXPECT_EQ(parse_error("frames 3\n"), "s.scene:1: a scene file starts with 'kdet-scene 1'");
    EXPECT_EQ(parse_error("kdet-scene 2\n"), "s.scene:1: unknown scene format version '2'");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 3\nobject a\n  mesh bunny\n  colour red\n"),
              "s.scene:5: unknown statement 'colour'");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes x\n"), "s.scene:2: 'x' is not a finite decimal number");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 0x10\n"), "s.scene:2: '0x10' is not a finite decimal number");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 3\nmesh bunny\n"), "s.scene:3: 'mesh' stands before any 'object'");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 3\nobject a\n mesh bunny\n key 5 move 1 2\n"),
              "s.scene:5: 'move' needs 3 value(s)");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 3\nobject a\n mesh bunny\n key 5 bend 1\n key 2 bend 0\n"),
              "s.scene:6: keys of 'bend' must have increasing frames (2 after 5)");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 3\nobject a\n mesh bunny\ncollide a b\n"),
              "s.scene:5: no object named 'b'");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 3\nobject a\n"), "s.scene:3: object 'a' has no 'mesh' or 'file'");
    EXPECT_EQ(parse_error("kdet-scene 1\nobject a\n mesh bunny\n"), "s.scene:3: the scene sets no 'frames'");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 2\nobject a\n twist w\n"), "s.scene:4: 'w' is not an axis (x, y or z)");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 2\nobject a\n squash y\n key 1 squash 0.95\n"),
              "s.scene:5: squash 0.95 is outside (-1, 0.9)");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 2\nobject a\n squash y\n key 1 move 0 0 0 squash -1\n"),
              "s.scene:5: squash -1 is outside (-1, 0.9)");
    // Between its keys too: a curve through 0, 0.8 and 0.8 rises past 0.9 before it levels off.
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 40\nobject a\n mesh bunny\n squash y\n key 0 squash 0\n key 2 squash 0.8\n"
                          " key 39 squash 0.8\n"),
              "s.scene:8: object 'a': the squash between the keys of frames 2 and 39 reaches 0.901 at frame 10, outside "
              "(-1, 0.9): the curve through the keys overshoots them (add a key or move one)");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 10\nobject a\n mesh bunny\n key 0 bend 0\n key 9 bend 0.5\n"),
              "s.scene:5: object 'a': its bend keys need a 'bend ALONG_AXIS TOWARD_AXIS' statement");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 3\nname a\nframes 4\n"), "s.scene:4: 'frames' is given twice (first at line 2)");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 3\nobject a\n mesh bunny\n scale 2\n scale 3\n"),
              "s.scene:6: object 'a' has 'scale' twice (first at line 5)");
    EXPECT_EQ(parse_error("kdet-scene 1\nframes 3\nobject a\n file box.node\n resolution 3\n"),
              "s.scene:3: object 'a' reads a 'file': 'resolution' applies to the prepared models of 'mesh' only");
    // A byte-order mark before the header is skipped; an underflow reads as the tiny number it is.
    EXPECT_EQ(parse_error("\xEF\xBB\xBFkdet-scene 1\nframes 3\nobject a\n mesh bunny\n wobble 0.01 1e-308\n"), "no error");
}

TEST(SceneFile, MistakesFoundWhilePlayingNameFileAndLine) {
    const fs::path dir = fresh_dir("playing");
    write_tetgen(make_box_mesh(2, 2, 2, 0.1), (dir / "box").string());
    std::ofstream(dir / "far.scene") << "kdet-scene 1\nframes 3\nobject a\n file box.node\nobject b\n"
                                        " file box.node\n key 0 move 0 0 0\n key 2 move 1e300 0 0\n";
    const auto far = read_scene_file((dir / "far.scene").string());
    std::vector<float> positions;
    far->positions(1, 0, positions);
    const std::string path = (dir / "far.scene").string();
    EXPECT_EQ(error_message([&] { far->positions(1, 2, positions); }),
              path + ":5: object 'b' at frame 2 has a coordinate beyond float's range (+-3.4e38)");
    fs::create_directories(dir / "folder.scene");
    EXPECT_EQ(error_message([&] { read_scene_file((dir / "folder.scene").string()); }),
              (dir / "folder.scene").string() + ": cannot open scene file (it is a directory)");
    // A mesh that cannot be had names the statement that asked for it.
    std::ofstream(dir / "missing.scene") << "kdet-scene 1\nframes 3\nobject a\n file box.node\nobject b\n file gone.node\n";
    EXPECT_EQ(error_message([&] { read_scene_file((dir / "missing.scene").string()); }),
              (dir / "missing.scene").string() + ":6: object 'b': " + (dir / "gone.node").string() + ": cannot open file");
    std::ofstream(dir / "model.scene") << "kdet-scene 1\nframes 3\nobject a\n mesh octopus\n";
    EXPECT_EQ(error_message([&] { read_scene_file((dir / "model.scene").string()); })
                  .rfind((dir / "model.scene").string() + ":4: object 'a': unknown model 'octopus' (known models: armadillo", 0),
              0u);
    fs::remove_all(dir);
}

TEST(SceneFile, KeysInterpolateSmoothly) {
    std::vector<scenes::Key> keys = {{0, {0, 0, 0}}, {10, {1, 2, 3}}};
    // Two keys: constant speed.
    EXPECT_DOUBLE_EQ(scenes::evaluate(keys, 5)[0], 0.5);
    EXPECT_DOUBLE_EQ(scenes::evaluate(keys, 2.5)[2], 0.75);
    // Constant outside the keys; zero without keys.
    EXPECT_DOUBLE_EQ(scenes::evaluate(keys, -3)[1], 0.0);
    EXPECT_DOUBLE_EQ(scenes::evaluate(keys, 30)[1], 2.0);
    EXPECT_DOUBLE_EQ(scenes::evaluate({}, 4)[0], 0.0);
    // Through every key, and flat at a turning key between two equal neighbours.
    keys.push_back({20, {0, 0, 0}});
    EXPECT_DOUBLE_EQ(scenes::evaluate(keys, 10)[0], 1.0);
    EXPECT_LT(scenes::evaluate(keys, 9.9)[0], 1.0);
    EXPECT_LT(scenes::evaluate(keys, 10.1)[0], 1.0);
}

/// @brief A scene file of two boxes written next to their TetGen meshes.
fs::path write_box_scene(const fs::path& dir) {
    write_tetgen(make_box_mesh(6, 3, 3, 0.1), (dir / "box").string());
    std::ofstream(dir / "boxes.scene") << R"(kdet-scene 1
name boxes
frames 30
object left                 # comment
  file box.node
  rotate 0 0 10
  translate -1 0 0
  key 0 move 0 0 0
  key 20 move 0.8 0 0
  squash x
  key 0 squash 0
  key 29 squash 0.2
  bend x y
  key 0 bend 0.1
  twist x
  key 0 twist 0
  key 29 twist 30
  wobble 0.01 7
object right
  file box.node
  translate 0.5 0 0
collide left right
self left
)";
    return dir / "boxes.scene";
}

TEST(SceneFile, ResolutionIsTheOneTheMeshesWereBuiltAt) {
    SceneRequest r3;
    r3.resolution = 3;
    EXPECT_EQ(open_scene("heap", r3)->resolution(), 3);
    EXPECT_EQ(open_scene("drape")->resolution(), 1);
    EXPECT_EQ(open_scene("procedural")->resolution(), 0);
    EXPECT_EQ(open_scene("tearing", r3)->resolution(), 0);
    const fs::path dir = fresh_dir("resolution");
    EXPECT_EQ(open_scene(write_box_scene(dir).string(), r3)->resolution(), 0) << "mesh files only";
    fs::remove_all(dir);
    KDET_PREPARE_OR_SKIP("armadillo -r 2");
    SceneRequest r4;
    r4.resolution = 4;
    EXPECT_EQ(open_scene("pass_through_armadillos", r4)->resolution(), 2) << "its file fixes it";
}

TEST(SceneFile, SelfCollisionOfTheMarkedObjectsOnly) {
    // One mesh of two overlapping boxes (vertices apart: they self-collide), twice, far apart; the file
    // marks the first. SceneSelfCollision::marked (`-s scene`) checks it alone.
    const fs::path dir = fresh_dir("marked-self");
    TetMesh doubled = make_box_mesh(4, 2, 2, 0.1);
    const TetMesh second = make_box_mesh(4, 2, 2, 0.1);
    const auto offset = static_cast<std::uint32_t>(doubled.num_vertices());
    for (std::size_t i = 0; i < second.positions.size(); ++i) doubled.positions.push_back(second.positions[i] + 0.03);
    for (const std::uint32_t v : second.tets) doubled.tets.push_back(v + offset);
    write_tetgen(doubled, (dir / "doubled").string());
    std::ofstream(dir / "marked.scene") << "kdet-scene 1\nframes 1\nobject a\n  file doubled.node\nobject b\n"
                                           "  file doubled.node\n  translate 5 0 0\nself a\n";
    const auto scene = open_scene((dir / "marked.scene").string());
    const auto pairs_with = [&](SceneSelfCollision self) {
        Detector detector;
        add_scene_objects(detector, *scene, self);
        std::vector<float> xyz;
        for (std::size_t o = 0; o < 2; ++o) {
            scene->positions(o, 0, xyz);
            detector.set_positions(static_cast<ObjectId>(o), xyz.data(), xyz.size() / 3);
        }
        return detector.detect().pairs;
    };
    const std::vector<TetPair> marked = pairs_with(SceneSelfCollision::marked), every = pairs_with(SceneSelfCollision::every);
    EXPECT_TRUE(pairs_with(SceneSelfCollision::none).empty());
    ASSERT_FALSE(marked.empty());
    for (const TetPair& p : marked) EXPECT_TRUE(p.object_a == 0 && p.object_b == 0);
    std::vector<TetPair> every_in_a, every_in_b;
    for (const TetPair& p : every) (p.object_a == 0 ? every_in_a : every_in_b).push_back(p);
    EXPECT_EQ(every_in_a, marked);
    EXPECT_FALSE(every_in_b.empty());
    for (const TetPair& p : every_in_b) EXPECT_TRUE(p.object_a == 1 && p.object_b == 1);
    EXPECT_STREQ(to_string(SceneSelfCollision::marked), "scene");
    fs::remove_all(dir);
}

TEST(SceneFile, PlaysBackDeterministicallyAndMovesEveryVertex) {
    const fs::path dir = fresh_dir("boxes");
    const fs::path path = write_box_scene(dir);
    const auto one = open_scene(path.string()), two = read_scene_file(path.string());
    EXPECT_EQ(one->name(), "boxes");
    EXPECT_EQ(one->num_frames(), 30);
    ASSERT_EQ(one->num_objects(), 2u);
    EXPECT_TRUE(one->checks_pair(0, 1));
    EXPECT_TRUE(one->checks_self(0));
    EXPECT_FALSE(one->checks_self(1));
    std::vector<double> a, b, previous;
    for (int f = 0; f < one->num_frames(); ++f) {
        one->positions(0, f, a);
        two->positions(0, f, b);
        EXPECT_EQ(a, b) << "frame " << f;
        if (f > 0) {
            for (std::size_t v = 0; v < a.size() / 3; ++v) {
                EXPECT_TRUE(a[3 * v] != previous[3 * v] || a[3 * v + 1] != previous[3 * v + 1] ||
                            a[3 * v + 2] != previous[3 * v + 2])
                    << "vertex " << v << " rests at frame " << f;
            }
        }
        previous = a;
    }
    // The still object keeps its rest shape, translated.
    one->positions(1, 17, b);
    EXPECT_DOUBLE_EQ(b[0], one->rest_mesh(1).positions[0] + 0.5);
    EXPECT_THROW(one->positions(0, 30, a), Error);
    fs::remove_all(dir);
}

TEST(SceneFile, MissingMeshFileIsNamed) {
    const fs::path dir = fresh_dir("missing");
    std::ofstream(dir / "m.scene") << "kdet-scene 1\nframes 2\nobject a\n file nothing.node\n";
    try {
        read_scene_file((dir / "m.scene").string());
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("nothing"), std::string::npos) << e.what();
    }
    fs::remove_all(dir);
}

TEST(SceneRegistry, KnowsTheThesisScenes) {
    const std::vector<std::string> names = scene_names();
    for (const char* name : {"procedural", "armadillos", "buddha_and_armadillo", "bunny_and_planck",
                             "pass_through_armadillos"})
        EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    try {
        open_scene("teapots");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("known scenes: procedural, armadillos"), std::string::npos) << e.what();
    }
}

TEST(SceneRegistry, RefusesAResolutionOutsideOneToFourForEveryScene) {
    for (const std::string& name : scene_names())
        for (const int resolution : {0, 5, -1000000}) {
            SceneRequest request;
            request.resolution = resolution;
            EXPECT_EQ(error_message([&] { open_scene(name, request); }),
                      name + ": resolution " + std::to_string(resolution) + " out of range [1, 4]");
        }
}

std::string recording_error(const std::string& path) {
    try {
        read_recording(path);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

TEST(RecordedScene, BinaryRecordingPlaysBackExactly) {
    const fs::path dir = fresh_dir("recording");
    const auto scene = read_scene_file(write_box_scene(dir).string());
    const std::string path = (dir / "boxes.kdetrec").string();
    write_recording(*scene, path);
    const auto played = open_scene(path);
    ASSERT_EQ(played->num_objects(), 2u);
    EXPECT_EQ(played->num_frames(), 30);
    EXPECT_EQ(played->rest_mesh(0).tets, scene->rest_mesh(0).tets);
    EXPECT_TRUE(played->checks_pair(0, 1));
    EXPECT_TRUE(played->checks_self(0));
    EXPECT_FALSE(played->checks_self(1));
    std::vector<float> a, b;
    for (int f : {0, 13, 29}) {
        for (std::size_t o = 0; o < 2; ++o) {
            scene->positions(o, f, a);
            played->positions(o, f, b);
            EXPECT_EQ(a, b) << "object " << o << " frame " << f;
        }
    }
    // A non-finite coordinate in a later frame names the file and the frame.
    {
        std::fstream edit(path, std::ios::in | std::ios::out | std::ios::binary);
        edit.seekp(-4, std::ios::end); // the last coordinate of the last frame
        const float nan = std::numeric_limits<float>::quiet_NaN();
        edit.write(reinterpret_cast<const char*>(&nan), sizeof nan);
    }
    const auto broken = open_scene(path);
    EXPECT_EQ(error_message([&] { broken->positions(1, 29, b); }),
              path + ": frame 29, object 1: vertex " + std::to_string(scene->rest_mesh(1).num_vertices() - 1) +
                  " has a non-finite coordinate");
    // Bytes past the frames the header announces are refused, as a cut-off file is, when opened.
    const auto size = fs::file_size(path);
    fs::resize_file(path, size + 3);
    EXPECT_EQ(recording_error(path),
              path + ": byte " + std::to_string(size) + ": 3 bytes past the last of the 30 frames the header announces");
    fs::resize_file(path, fs::file_size(path) - 8);
    EXPECT_THROW(read_recording(path), Error);
    fs::remove_all(dir);
}


TEST(RecordedScene, StaticObjectsAndCollisionFiltersAreRecorded) {
    // heap: a static floor and boxes in collision groups; the recording must play back as the scene.
    const fs::path dir = fresh_dir("recorded-heap");
    const auto heap = open_scene("heap");
    const std::string path = (dir / "heap.kdetrec").string();
    write_recording(*heap, path);
    const auto played = open_scene(path);
    ASSERT_EQ(played->num_objects(), heap->num_objects());
    std::size_t static_objects = 0, filtered = 0;
    for (std::size_t o = 0; o < heap->num_objects(); ++o) {
        EXPECT_EQ(played->is_static(o), heap->is_static(o)) << o;
        EXPECT_EQ(played->checks_self(o), heap->checks_self(o)) << o;
        const CollisionFilter want = heap->collision_filter(o), got = played->collision_filter(o);
        EXPECT_EQ(got.group, want.group) << o;
        EXPECT_EQ(got.mask, want.mask) << o;
        static_objects += heap->is_static(o);
        filtered += want.group != CollisionFilter{}.group;
        for (std::size_t b = 0; b < heap->num_objects(); ++b) ASSERT_EQ(played->checks_pair(o, b), heap->checks_pair(o, b));
    }
    EXPECT_EQ(static_objects, 1u);
    EXPECT_GT(filtered, 100u);
    std::vector<float> a, b;
    for (int f : {0, 57, heap->num_frames() - 1})
        for (std::size_t o : {std::size_t{0}, std::size_t{1}, heap->num_objects() - 1}) {
            heap->positions(o, f, a);
            played->positions(o, f, b);
            EXPECT_EQ(a, b) << "object " << o << " frame " << f;
        }
    // The layout of docs/scenes.md, the static floor's positions stored once, not per frame.
    std::size_t bytes = 16 + 4, moving_floats = 0;
    for (std::size_t o = 0; o < heap->num_objects(); ++o) {
        bytes += 4 + 4 + 1 + 8 + 16 * heap->rest_mesh(o).num_tets();
        const std::size_t floats = 3 * heap->rest_mesh(o).num_vertices();
        if (heap->is_static(o)) bytes += 4 * floats;
        else moving_floats += floats;
        for (std::size_t other = o + 1; other < heap->num_objects(); ++other) bytes += heap->checks_pair(o, other) ? 8 : 0;
    }
    EXPECT_EQ(fs::file_size(path), bytes + 4 * moving_floats * static_cast<std::size_t>(heap->num_frames()));
    // Unknown flags are refused where they stand.
    {
        std::fstream edit(path, std::ios::in | std::ios::out | std::ios::binary);
        edit.seekp(24); // object 0: after the magic, the two counts and its vertex and tet counts
        edit.put(static_cast<char>(4));
    }
    EXPECT_EQ(recording_error(path), path + ": byte 24: object 0: unknown flags 4 (1: self-collision, 2: static)");
    fs::remove_all(dir);
}

TEST(RecordedScene, ASceneWhoseTetsChangeIsNotRecorded) {
    const fs::path dir = fresh_dir("recorded-tearing");
    const std::string path = (dir / "tearing.kdetrec").string();
    EXPECT_EQ(error_message([&] { write_recording(*open_scene("tearing"), path); }),
              path + ": scene tearing changes its tets from frame to frame, which a recording does not hold");
    EXPECT_FALSE(fs::exists(path));
    fs::remove_all(dir);
}

TEST(RecordedScene, CountsTheFileCannotHoldAreRefusedBeforeAnythingIsReserved) {
    // Without the check against the file's size, these counts reserve 64 GB for the tets, 103 GB for
    // the positions: std::bad_alloc (no file named) or the machine's memory, not this message.
    const fs::path dir = fresh_dir("absurd-recording");
    const auto write = [&](const std::string& name, std::uint32_t frames, std::uint32_t vertices, std::uint32_t tets) {
        std::string bytes = "KDETREC1";
        const auto put = [&](std::uint32_t v) {
            for (int i = 0; i < 4; ++i) bytes += static_cast<char>((v >> (8 * i)) & 0xff);
        };
        put(1), put(frames), put(vertices), put(tets);
        bytes += '\0';
        for (std::uint32_t corner = 0; corner < 4; ++corner) put(corner);
        put(0); // no object pairs
        const float corners[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
        bytes.append(reinterpret_cast<const char*>(corners), sizeof corners);
        const std::string path = (dir / name).string();
        std::ofstream(path, std::ios::binary) << bytes;
        return path;
    };
    const std::string sound = write("sound.kdetrec", 1, 4, 1);
    EXPECT_EQ(recording_error(sound), "no error");
    const std::string tets = write("tets.kdetrec", 1, 4, 0xffffffffu);
    EXPECT_EQ(recording_error(tets), tets + ": byte 93: file ends inside the tets of object 0");
    const std::string vertices = write("vertices.kdetrec", 1, 0xffffffffu, 1);
    EXPECT_EQ(recording_error(vertices), vertices + ": byte 93: file ends inside the last frame");
    const std::string frames = write("frames.kdetrec", 0x7fffffffu, 4, 1);
    EXPECT_EQ(recording_error(frames), frames + ": byte 93: file ends inside the last frame");
    fs::remove_all(dir);
}

TEST(RecordedScene, FolderOfVtkFrames) {
    const fs::path dir = fresh_dir("frames");
    const auto scene = read_scene_file(write_box_scene(dir).string());
    for (std::size_t o = 0; o < 2; ++o) {
        const fs::path folder = dir / "recorded" / (o == 0 ? "a" : "b");
        fs::create_directories(folder);
        for (int f = 0; f < 12; ++f) {
            TetMesh frame = scene->rest_mesh(o);
            scene->positions(o, f, frame.positions);
            write_vtk(frame, (folder / ("frame_" + std::to_string(f) + ".vtk")).string());
        }
    }
    const auto played = open_scene((dir / "recorded").string());
    ASSERT_EQ(played->num_objects(), 2u);
    ASSERT_EQ(played->num_frames(), 12);
    std::vector<double> a, b;
    // frame_10 must come after frame_9, not after frame_1.
    scene->positions(0, 10, a);
    played->positions(0, 10, b);
    EXPECT_EQ(a, b);
    // Given with a trailing '/', as shells complete it: the folder's own name all the same.
    EXPECT_EQ(open_scene((dir / "recorded").string() + "/")->name(), "recorded");

    // Frames lost or doubled, another mesh kind among them, a frame of other vertices: each named.
    const fs::path a_folder = dir / "recorded" / "a";
    fs::copy_file(a_folder / "frame_3.vtk", a_folder / "frame_03.vtk");
    EXPECT_EQ(error_message([&] { open_scene((dir / "recorded").string()); }),
              a_folder.string() + ": frame_03.vtk and frame_3.vtk are both frame 3");
    fs::remove(a_folder / "frame_03.vtk");
    fs::rename(a_folder / "frame_5.vtk", dir / "frame_5.vtk");
    EXPECT_EQ(error_message([&] { open_scene((dir / "recorded").string()); }),
              a_folder.string() + ": the frames jump from frame_4.vtk to frame_6.vtk (a frame missing?)");
    fs::rename(dir / "frame_5.vtk", a_folder / "frame_5.VTK"); // any case
    EXPECT_EQ(open_scene((dir / "recorded").string())->num_frames(), 12);
    write_tet_mesh(scene->rest_mesh(0), (a_folder / "extra.msh").string());
    EXPECT_EQ(error_message([&] { open_scene((dir / "recorded").string()); }),
              (a_folder / "extra.msh").string() + ": a frame folder holds .vtk or .node frames, not .msh");
    fs::remove(a_folder / "extra.msh");
    TetMesh grown = scene->rest_mesh(0);
    grown.positions.insert(grown.positions.end(), {9.0, 9.0, 9.0});
    write_vtk(grown, (a_folder / "frame_7.vtk").string());
    const auto uneven = open_scene((dir / "recorded").string());
    EXPECT_EQ(error_message([&] { uneven->positions(0, 7, b); }),
              (a_folder / "frame_7.vtk").string() + ": " + std::to_string(grown.num_vertices()) +
                  " vertices, but the first frame " + (a_folder / "frame_0.vtk").string() + " has " +
                  std::to_string(grown.num_vertices() - 1));
    fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// The thesis scenes, with the meshes `kdet prepare` makes.

struct ThesisCase {
    const char* scene;
    int resolution;
    std::vector<int> contact_frames;  ///< frames that must have colliding pairs
    std::size_t deforming_object;     ///< an object whose every vertex moves every frame
};

void PrintTo(const ThesisCase& c, std::ostream* out) { *out << c.scene << " resolution " << c.resolution; }

class ThesisScene : public ::testing::TestWithParam<ThesisCase> {};

TEST_P(ThesisScene, DeterministicWithContact) {
    const ThesisCase& c = GetParam();
    KDET_PREPARE_OR_SKIP("-r " + std::to_string(c.resolution));
    SceneRequest request;
    request.resolution = c.resolution;
    const auto scene = open_scene(c.scene, request), again = open_scene(c.scene, request);
    EXPECT_EQ(scene->name(), c.scene);
    EXPECT_EQ(scene->num_frames(), 160);
    ASSERT_EQ(scene->num_objects(), 2u);
    EXPECT_TRUE(scene->checks_pair(0, 1));

    Detector detector;
    for (std::size_t o = 0; o < 2; ++o) detector.add_object(scene->rest_mesh(o));
    std::vector<float> positions, repeated, previous;
    int first_contact = -1;
    for (int f = 0; f < scene->num_frames(); ++f) {
        for (std::size_t o = 0; o < 2; ++o) {
            scene->positions(o, f, positions);
            detector.set_positions(static_cast<ObjectId>(o), positions.data(), positions.size() / 3);
            if (f % 40 == 0) {
                again->positions(o, f, repeated);
                EXPECT_EQ(positions, repeated) << "frame " << f << " differs between two runs";
            }
            if (o == c.deforming_object) {
                if (f > 0) {
                    std::size_t resting = 0;
                    for (std::size_t i = 0; i < positions.size(); i += 3)
                        resting += positions[i] == previous[i] && positions[i + 1] == previous[i + 1] &&
                                   positions[i + 2] == previous[i + 2];
                    EXPECT_EQ(resting, 0u) << "vertices of object " << o << " rest at frame " << f;
                }
                previous = positions;
            }
        }
        // Detection on every 8th frame and the contact frames keeps the test short.
        const bool contact_frame =
            std::find(c.contact_frames.begin(), c.contact_frames.end(), f) != c.contact_frames.end();
        if (f % 8 != 0 && !contact_frame) continue;
        const std::size_t pairs = detector.detect().pairs.size();
        if (f == 0) {
            EXPECT_EQ(pairs, 0u) << "the objects start apart";
        }
        if (pairs > 0 && first_contact < 0) first_contact = f;
        if (contact_frame) {
            EXPECT_GT(pairs, 0u) << c.scene << " frame " << f << " should be in contact";
        }
    }
    EXPECT_GT(first_contact, 0);
}

INSTANTIATE_TEST_SUITE_P(Scenes, ThesisScene,
                         ::testing::Values(ThesisCase{"armadillos", 1, {80, 85, 90}, 0},
                                           ThesisCase{"buddha_and_armadillo", 1, {65, 95, 130, 159}, 1},
                                           ThesisCase{"bunny_and_planck", 1, {65, 95, 130, 159}, 0},
                                           ThesisCase{"pass_through_armadillos", 2, {60, 79, 100}, 1}),
                         [](const ::testing::TestParamInfo<ThesisCase>& p) { return std::string(p.param.scene); });

TEST(ThesisScenes, MissingMeshSaysWhereToLook) {
    const fs::path dir = fresh_dir("no-cache");
    const char* old = std::getenv("KDET_CACHE_DIR");
    const std::string saved = old ? old : "";
    setenv("KDET_CACHE_DIR", dir.c_str(), 1);
    try {
        open_scene("armadillos");
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  "mesh armadillo resolution 1 is not prepared; run `kdet prepare` (cache: " + dir.string() + ")");
    }
    old ? setenv("KDET_CACHE_DIR", saved.c_str(), 1) : unsetenv("KDET_CACHE_DIR");
    fs::remove_all(dir);
}

} // namespace
} // namespace kdet::test
