// The viewer's parts that need no display: boundary surfaces, the camera, the command line, the
// session (settings changed at any time, switching many times) and the benchmark button.

#include "bench_job.hpp"
#include "camera.hpp"
#include "cli_args.hpp"
#include "picking.hpp"
#include "session.hpp"
#include "surface.hpp"
#include "view_args.hpp"
#include "view_test_support.hpp"
#include "viewer.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/option_table.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <thread>

namespace kdet::view {
namespace {

using test::octopus_pair;
using test::procedural;
using test::temp_dir;

// ---- boundary surfaces ----

/// @brief Signed volume enclosed by outward triangles (divergence theorem); positive when they face out.
double enclosed_volume(const TetMesh& mesh, const std::vector<std::uint32_t>& triangles) {
    double volume = 0;
    const double* p = mesh.positions.data();
    for (std::size_t t = 0; t < triangles.size(); t += 3) {
        const double* a = p + 3 * triangles[t];
        const double* b = p + 3 * triangles[t + 1];
        const double* c = p + 3 * triangles[t + 2];
        volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0;
    }
    return volume;
}

TEST(ViewSurface, BoxBoundaryIsClosedAndFacesOutward) {
    const TetMesh box = make_box_mesh(3, 2, 4, 0.5);
    const std::vector<std::uint32_t> triangles = analyse_faces(box).boundary;
    // Two triangles per boundary square of the 3x2x4 grid.
    EXPECT_EQ(triangles.size() / 3, 2u * 2u * (3 * 2 + 2 * 4 + 3 * 4));
    // Closed and consistently oriented: every directed edge appears once, and its reverse once.
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (std::size_t t = 0; t < triangles.size(); t += 3)
        for (int k = 0; k < 3; ++k) ++edges[{triangles[t + k], triangles[t + (k + 1) % 3]}];
    for (const auto& [edge, count] : edges) {
        EXPECT_EQ(count, 1);
        EXPECT_EQ(edges.count({edge.second, edge.first}), 1u);
    }
    EXPECT_NEAR(enclosed_volume(box, triangles), 1.5 * 1.0 * 2.0, 1e-9);
}

TEST(ViewSurface, FacesOutwardWhateverTheTetOrientation) {
    TetMesh two;
    two.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1};
    two.tets = {0, 1, 2, 3, 0, 2, 1, 4}; // one positive, one negative; they share face 0 1 2
    const MeshFaces faces = analyse_faces(two);
    const std::vector<std::uint32_t>& triangles = faces.boundary;
    EXPECT_EQ(triangles.size(), 6u * 3u);
    EXPECT_NEAR(enclosed_volume(two, triangles), 2.0 / 6.0, 1e-12);
    std::set<std::array<std::uint32_t, 3>> distinct;
    for (std::size_t t = 0; t < triangles.size(); t += 3) {
        std::array<std::uint32_t, 3> f = {triangles[t], triangles[t + 1], triangles[t + 2]};
        std::sort(f.begin(), f.end());
        distinct.insert(f);
    }
    EXPECT_EQ(distinct.count({0, 1, 2}), 0u) << "the shared face is interior";
    // Face 0 of tet 0 and face 0 of tet 1 are the shared one (vertices 0 1 2 of each).
    EXPECT_EQ(faces.neighbour, (std::vector<std::uint32_t>{1, no_tet, no_tet, no_tet, 0, no_tet, no_tet, no_tet}));
}

TEST(ViewSurface, TorusSurfaceEnclosesItsTets) {
    ProceduralScene scene(ProceduralSceneOptions{3000, 2});
    const TetMesh& torus = scene.rest_mesh(0);
    double volume = 0;
    for (std::size_t t = 0; t < torus.num_tets(); ++t) {
        const std::uint32_t* v = &torus.tets[4 * t];
        double e[3][3];
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) e[k][a] = torus.positions[3 * v[k + 1] + a] - torus.positions[3 * v[0] + a];
        volume += std::abs(e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                           e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) / 6.0;
    }
    EXPECT_NEAR(enclosed_volume(torus, analyse_faces(torus).boundary), volume, 1e-9 * volume);
}

TEST(ViewSurface, FlaggedRegionIsTheSurfaceOfTheFlaggedTets) {
    const TetMesh box = make_box_mesh(4, 3, 2, 1.0);
    const MeshFaces faces = analyse_faces(box);
    std::size_t interior = 0;
    for (const std::uint32_t n : faces.neighbour) interior += n != no_tet;
    EXPECT_EQ(interior + faces.boundary.size() / 3, 4 * box.num_tets()) << "every face is interior or boundary";
    // Neighbours are mutual and share three vertices.
    for (std::size_t t = 0; t < box.num_tets(); ++t)
        for (int k = 0; k < 4; ++k) {
            const std::uint32_t n = faces.neighbour[4 * t + static_cast<std::size_t>(k)];
            if (n == no_tet) continue;
            EXPECT_EQ(std::count(faces.neighbour.begin() + 4 * n, faces.neighbour.begin() + 4 * n + 4, t), 1);
            std::set<std::uint32_t> a(&box.tets[4 * t], &box.tets[4 * t] + 4), b(&box.tets[4 * n], &box.tets[4 * n] + 4);
            std::vector<std::uint32_t> shared;
            std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(shared));
            EXPECT_EQ(shared.size(), 3u);
        }
    // Every tet flagged: the region's surface is the whole boundary.
    std::vector<std::uint8_t> all(box.num_tets(), 1), one(box.num_tets(), 0), none(box.num_tets(), 0);
    std::vector<std::uint32_t> region;
    append_flagged_region(box, faces, all, region);
    EXPECT_EQ(region.size(), faces.boundary.size());
    // One tet: its four faces.
    one[7] = 1;
    region.clear();
    append_flagged_region(box, faces, one, region);
    EXPECT_EQ(region.size(), 12u);
    EXPECT_EQ(std::set<std::uint32_t>(region.begin(), region.end()), std::set<std::uint32_t>(&box.tets[28], &box.tets[32]));
    region.clear();
    append_flagged_region(box, faces, none, region);
    EXPECT_TRUE(region.empty());
}

// ---- camera ----

TEST(ViewCamera, FramingKeepsEveryPointInsideAndFillsTheView) {
    const std::vector<std::vector<float>> points = {{-1, 0, 0, 3, 1, 0.5f, 0, -2, 1}, {2, 2, -1, 0.5f, 0, 0}};
    for (const float aspect : {0.5f, 1.0f, 1.6f, 3.0f}) {
        OrbitCamera camera;
        camera.set_angles(50, -20);
        camera.frame(points, aspect);
        const int height = 400, width = static_cast<int>(aspect * 400.0f);
        const float w = static_cast<float>(width), h = static_cast<float>(height);
        float widest = 0;
        for (const auto& set : points)
            for (std::size_t i = 0; i < set.size(); i += 3) {
                const auto p = camera.project(Vec3{set[i], set[i + 1], set[i + 2]}, width, height);
                ASSERT_TRUE(p.has_value());
                EXPECT_GE((*p)[0], 0.049f * w);
                EXPECT_LE((*p)[0], 0.951f * w);
                EXPECT_GE((*p)[1], 0.049f * h);
                EXPECT_LE((*p)[1], 0.951f * h);
                widest = std::max({widest, std::abs((*p)[0] / w - 0.5f) * 2, std::abs((*p)[1] / h - 0.5f) * 2});
            }
        EXPECT_GT(widest, 0.89f) << "aspect " << aspect << ": some point reaches the 90% margin";
        EXPECT_FLOAT_EQ(camera.yaw(), 50.0f);
    }
}

TEST(ViewCamera, TargetProjectsToTheCentreAndMovesAsAsked) {
    OrbitCamera camera;
    camera.frame({{0, 0, 0, 2, 2, 2}}, 1.0f);
    const Vec3 target = camera.target();
    auto centre = camera.project(target, 200, 100);
    ASSERT_TRUE(centre.has_value());
    EXPECT_NEAR((*centre)[0], 100.0f, 1e-3f);
    EXPECT_NEAR((*centre)[1], 50.0f, 1e-3f);
    const float distance = camera.distance();
    camera.zoom(0.5f);
    EXPECT_FLOAT_EQ(camera.distance(), 0.5f * distance);
    EXPECT_NEAR(length(camera.eye() - target), camera.distance(), 1e-4f);
    // Panning right by 40 pixels moves the old target 40 pixels to the right on screen.
    camera.pan(40, 0, 100);
    const auto moved = camera.project(target, 200, 100);
    EXPECT_NEAR((*moved)[0], 140.0f, 0.05f);
    EXPECT_NEAR((*moved)[1], 50.0f, 0.05f);
    // Orbiting by half the viewport height turns 90 degrees; pitch stops short of the poles.
    camera.orbit(50, 0, 100);
    EXPECT_FLOAT_EQ(camera.yaw(), OrbitCamera::default_yaw - 90.0f);
    camera.orbit(0, 1000, 100);
    EXPECT_FLOAT_EQ(camera.pitch(), 89.0f);
    // A point behind the camera does not project.
    EXPECT_FALSE(camera.project(camera.eye() + (camera.eye() - camera.target()), 200, 100).has_value());
}

TEST(ViewCamera, RaysGoThroughTheirPixels) {
    OrbitCamera camera;
    camera.set_angles(-60, 35);
    camera.frame({{0, 0, 0, 1, 2, 3}}, 1.5f);
    for (const auto& [x, y] : {std::pair{150.0f, 100.0f}, std::pair{3.0f, 190.0f}, std::pair{297.0f, 1.0f}}) {
        const auto [origin, direction] = camera.ray(x, y, 300, 200);
        EXPECT_NEAR(length(direction), 1.0f, 1e-5f);
        EXPECT_NEAR(length(origin - camera.eye()), 0.0f, 1e-5f);
        const auto p = camera.project(origin + direction * (2.0f * camera.distance()), 300, 200);
        ASSERT_TRUE(p.has_value());
        EXPECT_NEAR((*p)[0], x, 1e-2f);
        EXPECT_NEAR((*p)[1], y, 1e-2f);
    }
}

// ---- command line ----

ViewConfig parse(std::vector<std::string> words) {
    words.insert(words.begin(), {"kdet", "view"});
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    return parse_view_args(static_cast<int>(argv.size()), argv.data(), 2);
}

std::string usage_error(std::vector<std::string> words) {
    try {
        parse(std::move(words));
    } catch (const cli::UsageError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
        return message;
    }
    ADD_FAILURE() << "no UsageError";
    return {};
}

TEST(ViewArgs, DefaultsShowTheProceduralScene) {
    const ViewConfig c = parse({});
    EXPECT_EQ(c.source.scene, "procedural");
    EXPECT_TRUE(c.source.meshes.empty());
    EXPECT_EQ(c.frame, 0);
    EXPECT_TRUE(c.screenshot.empty());
    EXPECT_EQ(c.width, 1280);
    EXPECT_EQ(c.height, 800);
    EXPECT_LT(c.display.surface_opacity, 1.0f) << "colliding tets inside a mesh are visible by default";
}

TEST(ViewArgs, ScenesMeshesAndEveryFlag) {
    const ViewConfig c = parse({"armadillos", "--res", "3", "--self", "--method", "brute_force_pairs", "--test", "sat_mtv",
                                "--hash", "morton", "--backend", "cpu", "--threads", "2", "--frame", "7", "--screenshot",
                                "out.png", "--size", "640x360", "--panel", "--samples", "1", "--opacity", "0.5",
                                "--only-colliding", "--wireframe", "--normals", "--clip", "-y", "--clip-at", "0.25",
                                "--camera", "10,-30", "--zoom", "2", "--focus", "colliding"});
    EXPECT_EQ(c.source.scene, "armadillos");
    EXPECT_EQ(c.source.request.resolution, 3);
    EXPECT_EQ(c.self, SceneSelfCollision::every);
    EXPECT_EQ(c.options.method, Method::brute_force_pairs);
    EXPECT_EQ(c.options.narrow_phase, NarrowPhase::sat_mtv);
    EXPECT_EQ(c.options.hash, HashFunction::morton);
    EXPECT_EQ(c.options.threads, 2);
    EXPECT_EQ(c.frame, 7);
    EXPECT_EQ(c.screenshot, "out.png");
    EXPECT_EQ(c.width, 640);
    EXPECT_EQ(c.height, 360);
    EXPECT_TRUE(c.panel);
    EXPECT_EQ(c.samples, 1);
    EXPECT_FLOAT_EQ(c.display.surface_opacity, 0.5f);
    EXPECT_TRUE(c.display.only_colliding && c.display.wireframe && c.display.contact_normals && c.display.clip);
    EXPECT_EQ(c.display.clip_axis, 1);
    EXPECT_TRUE(c.display.clip_flip);
    EXPECT_FLOAT_EQ(c.display.clip_position, 0.25f);
    EXPECT_TRUE(c.camera.angles_given);
    EXPECT_FLOAT_EQ(c.camera.yaw, 10.0f);
    EXPECT_FLOAT_EQ(c.camera.pitch, -30.0f);
    EXPECT_FLOAT_EQ(c.camera.zoom, 2.0f);
    EXPECT_TRUE(c.camera.focus_colliding);

    const ViewConfig meshes = parse({"a.mesh", "b.msh"});
    EXPECT_EQ(meshes.source.meshes, (std::vector<std::string>{"a.mesh", "b.msh"}));
    EXPECT_EQ(parse({"bunny.mesh", "--self"}).source.meshes, (std::vector<std::string>{"bunny.mesh"}));
    EXPECT_EQ(parse({"x.scene"}).source.scene, "x.scene");
    EXPECT_EQ(parse({"run.kdetrec"}).source.scene, "run.kdetrec");
    EXPECT_EQ(parse({std::filesystem::temp_directory_path().string()}).source.scene,
              std::filesystem::temp_directory_path().string());
    EXPECT_EQ(parse({"--tets", "5000", "--scene-frames", "9"}).source.request.procedural.total_tets, 5000u);
    EXPECT_EQ(parse({"--self", "--exclusion-rings", "2"}).exclusion_rings, 2);
}

TEST(ViewArgs, MistakesAreOneLineErrors) {
    EXPECT_NE(usage_error({"--size", "10x10"}).find("--size"), std::string::npos);
    EXPECT_NE(usage_error({"--size", "big"}).find("WxH"), std::string::npos);
    EXPECT_NE(usage_error({"--clip", "w"}).find("x, y, z"), std::string::npos);
    EXPECT_NE(usage_error({"--opacity", "2"}).find("--opacity: expected a number in [0, 1]"), std::string::npos);
    EXPECT_NE(usage_error({"--exclusion-rings", "1"}).find("needs --self"), std::string::npos);
    EXPECT_EQ(usage_error({"--self", "--self-scene"}), "view: --self and --self-scene are two choices; give one");
    EXPECT_EQ(usage_error({"armadilos"}).rfind("view: unknown scene 'armadilos' (known scenes: procedural, ", 0), 0u);
    EXPECT_EQ(parse({"drape", "--self-scene", "--exclusion-rings", "1"}).self, SceneSelfCollision::marked);
    EXPECT_EQ(usage_error({"a.mesh", "b.mesh", "--self-scene"}),
              "view: --self-scene follows a scene's marks, and mesh files have none (use --self)");
    EXPECT_NE(usage_error({"--self", "--exclusion-rings", "5"}).find("--exclusion-rings"), std::string::npos);
    EXPECT_NE(usage_error({"--camera", "10"}).find("YAW,PITCH"), std::string::npos);
    EXPECT_NE(usage_error({"--panel"}).find("--screenshot"), std::string::npos);
    EXPECT_NE(usage_error({"armadillos", "--tets", "5000"}).find("procedural scene only"), std::string::npos);
    EXPECT_NE(usage_error({"a.mesh", "--scene-frames", "5"}).find("procedural scene only"), std::string::npos);
    EXPECT_NE(usage_error({"--screenshot", "a.png", "--profile"}).find("--profile"), std::string::npos);
    EXPECT_NE(usage_error({"--method", "fast"}).find("--method"), std::string::npos);
    EXPECT_NE(usage_error({"a", "b", "c"}).find("unexpected argument 'c'"), std::string::npos);
    EXPECT_NE(usage_error({"--bogus"}).find("unknown option '--bogus'"), std::string::npos);
}

TEST(ViewArgs, EveryDetectorOptionOfTheTableIsReadAndRefusedAsTheLibraryDoes) {
    std::size_t shown = 0;
    for (const OptionInfo& o : option_table()) {
        if (!o.shown_on(front_end_view)) continue;
        SCOPED_TRACE(o.name);
        ++shown;
        const std::string good = o.unset_by_default() ? std::to_string(o.min) : o.default_text();
        EXPECT_EQ(o.text(parse({o.flag, good}).options), good);
        const std::string bad = o.type == OptionType::choice ? "nope"
                                : o.type == OptionType::real ? "-1"
                                                             : std::to_string(o.max + 1);
        std::string expected;
        try {
            DetectorOptions options;
            o.parse(bad, options, o.flag);
        } catch (const Error& e) {
            expected = e.what();
        }
        EXPECT_EQ(usage_error({o.flag, bad}), "view: " + expected);
    }
    EXPECT_GE(shown, 7u);
}

// ---- session ----

/// @brief The pairs a Detector of its own finds in @p scene at @p frame, every object pair checked.
std::vector<TetPair> reference_pairs(const Scene& scene, int frame, bool self) {
    Detector detector(DetectorOptions{});
    std::vector<float> xyz;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        const ObjectId id = detector.add_object(scene.rest_mesh(o));
        detector.set_self_collision(id, self);
        scene.positions(o, frame, xyz);
        detector.set_positions(id, xyz.data(), xyz.size() / 3);
    }
    return detector.detect().pairs;
}

TEST(ViewSession, ATornMeshFollowsTheScenesTetsFrameByFrame) {
    ViewSource source;
    source.scene = "tearing";
    ViewSession session(source, DetectorOptions{}, SceneSelfCollision::none);
    const Scene& scene = session.scene();
    ASSERT_TRUE(scene.changes_tets());
    std::vector<std::uint32_t> tets;
    std::size_t previous = scene.rest_mesh(0).num_tets() + 1;
    // Forward through the tear, then back to an earlier frame: the tets grow again.
    for (int frame : {0, 17, 50, 95, 119, 40}) {
        session.set_frame(frame);
        const std::uint64_t topology = session.topology_version();
        ASSERT_TRUE(session.update());
        scene.tets(0, frame, tets);
        EXPECT_EQ(session.mesh(0).tets, tets) << "frame " << frame;
        if (frame != 40) {
            EXPECT_LT(tets.size() / 4, previous) << "the slab loses tets by frame " << frame;
        }
        if (frame != 0) {
            EXPECT_GT(session.topology_version(), topology) << "frame " << frame;
        }
        previous = tets.size() / 4;
        TetMesh torn = scene.rest_mesh(0);
        torn.tets = tets;
        EXPECT_EQ(session.faces()[0].boundary, analyse_faces(torn).boundary) << "frame " << frame;
        // The detector's pairs are those of a detector given this frame's tets from the start.
        Detector reference(DetectorOptions{});
        std::vector<float> xyz;
        for (std::size_t o = 0; o < scene.num_objects(); ++o) {
            TetMesh mesh = scene.rest_mesh(o);
            scene.tets(o, frame, mesh.tets);
            const ObjectId id = reference.add_object(mesh);
            scene.positions(o, frame, xyz);
            reference.set_positions(id, xyz.data(), xyz.size() / 3);
        }
        EXPECT_EQ(session.result().pairs, reference.detect().pairs) << "frame " << frame;
    }
    EXPECT_EQ(session.mesh(1).tets, scene.rest_mesh(1).tets) << "the box keeps its tets";
}

TEST(ViewSession, ShowsTheDetectorsPairsForTheFrame) {
    ViewSession session(procedural(4000, 21), DetectorOptions{}, SceneSelfCollision::none);
    EXPECT_FALSE(session.has_result());
    EXPECT_EQ(session.detector_memory(), 0u) << "no detector before the first detection";
    session.set_frame(10);
    EXPECT_TRUE(session.update());
    EXPECT_FALSE(session.update()) << "nothing changed";
    const std::vector<TetPair> expected = reference_pairs(session.scene(), 10, false);
    ASSERT_FALSE(expected.empty());
    EXPECT_EQ(session.result().pairs, expected);
    EXPECT_GT(session.detector_memory(), 0u);
    ASSERT_EQ(session.positions().size(), 2u);
    std::vector<float> xyz;
    session.scene().positions(1, 10, xyz);
    EXPECT_EQ(session.positions()[1], xyz);
    EXPECT_EQ(session.faces().size(), 2u);
    session.set_frame(1000);
    EXPECT_EQ(session.frame(), 20) << "clamped";
}

/// Each object's tets in the pairs of a fresh detector with `options` at `frame`.
std::vector<std::vector<std::uint8_t>> tets_in_pairs(const Scene& scene, int frame, const DetectorOptions& options) {
    Detector detector(options);
    add_scene_objects(detector, scene, false);
    std::vector<float> xyz;
    std::vector<std::vector<std::uint8_t>> tets(scene.num_objects());
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        scene.positions(o, frame, xyz);
        detector.set_positions(static_cast<ObjectId>(o), xyz.data(), xyz.size() / 3);
        tets[o].assign(scene.rest_mesh(o).num_tets(), 0);
    }
    for (const TetPair& p : detector.detect().pairs) tets[p.object_a][p.tet_a] = tets[p.object_b][p.tet_b] = 1;
    return tets;
}

TEST(ViewSession, TheTetsWithinTheMarginOnlyAreThoseOfAFreshDetector) {
    // With a margin the viewer colours the tets of pairs within it that do not overlap, unless they
    // overlap another tet: a margin detector's tets minus a margin-0 detector's.
    DetectorOptions options;
    options.margin = 0.02f;
    ViewSession session(procedural(4000, 21), options, SceneSelfCollision::none);
    session.set_frame(9);
    session.update();
    EXPECT_FALSE(session.options().distances) << "the user's options are shown as set";
    const auto within = tets_in_pairs(session.scene(), 9, options);
    const auto overlapping = tets_in_pairs(session.scene(), 9, DetectorOptions{});
    ASSERT_EQ(session.margin_tets().size(), 2u);
    std::size_t margin_only = 0, overlap = 0;
    for (std::size_t o = 0; o < 2; ++o) {
        ASSERT_EQ(session.margin_tets()[o].size(), within[o].size());
        for (std::size_t t = 0; t < within[o].size(); ++t) {
            const bool expected = within[o][t] && !overlapping[o][t];
            EXPECT_EQ(session.margin_tets()[o][t] != 0, expected) << "object " << o << " tet " << t;
            margin_only += expected;
            overlap += overlapping[o][t];
        }
    }
    EXPECT_GT(margin_only, 20u);
    EXPECT_GT(overlap, 20u);
    EXPECT_GT(session.margin_pairs(), 0u);
    EXPECT_LT(session.margin_pairs(), session.result().pairs.size());
    // Without a margin there is nothing to colour.
    session.set_options(DetectorOptions{});
    session.update();
    EXPECT_TRUE(session.margin_tets().empty());
    EXPECT_EQ(session.margin_pairs(), 0u);
}

TEST(ViewSession, EveryOptionChangesBeforeTheFirstDetection) {
    // The thesis's demo failed when the hash changed before anything was detected.
    const ViewSource source = procedural(3000, 11);
    const auto scene = open_view_source(source);
    const std::vector<TetPair> expected = reference_pairs(*scene, 5, false);
    const std::vector<TetPair> expected_self = reference_pairs(*scene, 5, true);
    ASSERT_FALSE(expected.empty());
    // Every hash, every method that builds pairs, the exact tests (sat_no_edges and fast may
    // report more or fewer pairs: docs/narrow-phase.md).
    std::vector<DetectorOptions> variants;
    for (const std::string& name : option_names<HashFunction>()) {
        DetectorOptions o;
        ASSERT_TRUE(parse(name, o.hash));
        variants.push_back(o);
    }
    for (const std::string& name : option_names<Method>()) {
        DetectorOptions o;
        ASSERT_TRUE(parse(name, o.method));
        if (o.method != Method::kdet_no_pairs) variants.push_back(o);
    }
    for (const NarrowPhase t : {NarrowPhase::sat_mtv, NarrowPhase::gjk}) {
        DetectorOptions o;
        o.narrow_phase = t;
        o.contacts = t == NarrowPhase::sat_mtv;
        variants.push_back(o);
    }
    DetectorOptions threads;
    threads.threads = 1;
    threads.bucket_capacity = 4;
    variants.push_back(threads);
    for (const DetectorOptions& options : variants) {
        ViewSession session(source, DetectorOptions{}, SceneSelfCollision::none);
        session.set_options(options);
        session.set_frame(5);
        session.update();
        EXPECT_EQ(session.result().pairs, expected) << to_string(options.hash) << " " << to_string(options.method);
        EXPECT_EQ(session.options().hash, options.hash);
        EXPECT_EQ(session.result().contacts.size(), options.contacts ? expected.size() : 0u);
    }
    ViewSession session(source, DetectorOptions{}, SceneSelfCollision::none);
    session.set_self(SceneSelfCollision::every);
    session.set_frame(5);
    session.update();
    EXPECT_EQ(session.result().pairs, expected_self);

    // kdet_no_pairs flags the same tets and builds no pairs.
    DetectorOptions flags_only;
    flags_only.method = Method::kdet_no_pairs;
    session.set_self(SceneSelfCollision::none);
    session.set_options(flags_only);
    session.update();
    EXPECT_TRUE(session.result().pairs.empty());
    std::size_t flagged = 0;
    for (const auto& object : session.result().colliding) flagged += static_cast<std::size_t>(std::count(object.begin(), object.end(), 1));
    std::set<std::pair<std::uint32_t, std::uint32_t>> tets;
    for (const TetPair& p : expected) {
        tets.insert({p.object_a, p.tet_a});
        tets.insert({p.object_b, p.tet_b});
    }
    EXPECT_EQ(flagged, tets.size());
}

TEST(ViewSession, FiftySwitchesOfSceneAndMethodKeepMemoryBounded) {
    const std::vector<ViewSource> sources = {procedural(6000, 9), octopus_pair(), procedural(2000, 9)};
    const std::vector<Method> methods = {Method::kdet, Method::brute_force_loop, Method::kdet_no_pairs};
    const std::vector<HashFunction> hashes = {HashFunction::morton, HashFunction::djb2};
    ViewSession session(sources[0], DetectorOptions{}, SceneSelfCollision::none);
    std::map<std::string, std::size_t> memory_of; // the detector's bytes for each setting
    std::size_t resident_after_warm_up = 0, most_resident = 0;
    for (int k = 0; k < 50; ++k) {
        const std::size_t s = static_cast<std::size_t>(k) % sources.size();
        DetectorOptions options;
        options.method = methods[static_cast<std::size_t>(k / 3) % methods.size()];
        options.hash = hashes[static_cast<std::size_t>(k) % hashes.size()];
        if (k % 2 == 0) {
            session.open(sources[s]);
            session.set_options(options);
        } else {
            session.set_options(options); // the other order, too
            session.open(sources[s]);
        }
        session.set_frame(4);
        session.update();
        const std::string key = std::to_string(s) + to_string(options.method) + to_string(options.hash);
        const auto [known, first_time] = memory_of.emplace(key, session.detector_memory());
        if (!first_time) {
            EXPECT_EQ(session.detector_memory(), known->second) << "switch " << k << ": " << key;
        }
        EXPECT_GT(session.detector_memory(), 0u);
        if (k == 11) resident_after_warm_up = resident_bytes();
        most_resident = std::max(most_resident, resident_bytes());
    }
    ASSERT_GT(resident_after_warm_up, 0u) << "this system does not report the resident set";
    // Every source and setting has been used by switch 11; later switches may not add more than
    // allocator slack.
    EXPECT_LT(most_resident, resident_after_warm_up + (48u << 20))
        << "resident set grew from " << resident_after_warm_up << " to " << most_resident << " bytes";
}

TEST(ViewSession, OpensEveryKindOfSource) {
    // What `kdet view` takes: a scene file, a recording, a folder of frames, mesh files; each shows
    // the pairs of a Detector of its own.
    const auto dir = temp_dir("sources");
    write_tetgen(make_box_mesh(3, 3, 3, 1.0), (dir / "box").string());
    std::ofstream(dir / "two.scene") << "kdet-scene 1\nframes 4\nobject a\n  file box.node\nobject b\n  file box.node\n"
                                        "  translate 1.5 0.5 0\n  key 0 move 0 0 0\n  key 3 move 1 0 0\n";
    ViewSource scene_file;
    scene_file.scene = (dir / "two.scene").string();
    write_recording(*open_view_source(procedural(2000, 5)), (dir / "run.kdetrec").string());
    ViewSource recording;
    recording.scene = (dir / "run.kdetrec").string();
    std::filesystem::create_directories(dir / "frames");
    for (int f = 0; f < 3; ++f) {
        TetMesh frame = make_box_mesh(2, 2, 2, 1.0);
        for (std::size_t i = 0; i < frame.positions.size(); i += 3) frame.positions[i] += 0.1 * f;
        write_vtk(frame, (dir / "frames" / ("frame_" + std::to_string(f) + ".vtk")).string());
    }
    ViewSource folder;
    folder.scene = (dir / "frames").string();
    for (const ViewSource& source : {scene_file, recording, folder, octopus_pair()}) {
        SCOPED_TRACE(source.meshes.empty() ? source.scene : source.meshes[0]);
        ViewSession session(source, DetectorOptions{}, SceneSelfCollision::every);
        session.set_frame(session.num_frames() - 1);
        session.update();
        EXPECT_EQ(session.result().pairs, reference_pairs(session.scene(), session.frame(), true));
        EXPECT_EQ(session.faces().size(), session.scene().num_objects());
    }
    EXPECT_EQ(ViewSession(scene_file, DetectorOptions{}, SceneSelfCollision::none).num_frames(), 4);
    EXPECT_EQ(ViewSession(folder, DetectorOptions{}, SceneSelfCollision::none).num_frames(), 3);
}

TEST(ViewSession, AFailedOpenKeepsTheSceneShown) {
    ViewSession session(procedural(2000, 5), DetectorOptions{}, SceneSelfCollision::none);
    session.update();
    const std::uint64_t version = session.scene_version();
    ViewSource missing;
    missing.scene = "no_such_folder/missing.scene";
    EXPECT_THROW(session.open(missing), Error);
    ViewSource unknown;
    unknown.meshes = {"no_such_mesh.mesh"};
    EXPECT_THROW(session.open(unknown), Error);
    EXPECT_EQ(session.scene().name(), "procedural");
    EXPECT_EQ(session.scene_version(), version);
    session.set_frame(2);
    EXPECT_TRUE(session.update());
}

// ---- picking ----

TEST(ViewPicking, PicksWhatIsDrawnAtThePixel) {
    DetectorOptions options;
    options.narrow_phase = NarrowPhase::sat_mtv;
    options.contacts = true;
    ViewSession session(test::nested_boxes(), options, SceneSelfCollision::none);
    session.update();
    OrbitCamera camera;
    camera.frame(session.positions(), 1.0f);
    Bounds box;
    for (const auto& xyz : session.positions()) box.add(xyz);
    // The centre of the small box, seen through the big one.
    const auto centre = camera.project(Vec3{4.37f, 4.37f, 4.37f}, 400, 400);
    ASSERT_TRUE(centre.has_value());
    DisplaySettings translucent;
    const auto hit = pick_tet(session, camera, (*centre)[0], (*centre)[1], 400, 400, translucent, box);
    ASSERT_TRUE(hit.has_value());
    EXPECT_TRUE(session.result().colliding[hit->object][hit->tet]) << "colliding tets are drawn over the surface";
    // Opaque, the big box's surface is in front: the tet of that surface triangle.
    DisplaySettings opaque;
    opaque.surface_opacity = 1.0f;
    const auto outside = pick_tet(session, camera, (*centre)[0], (*centre)[1], 400, 400, opaque, box);
    ASSERT_TRUE(outside.has_value());
    EXPECT_EQ(outside->object, 0u);
    EXPECT_FALSE(session.result().colliding[0][outside->tet]);
    const auto& boundary_tets = session.faces()[0].boundary_tet;
    EXPECT_NE(std::find(boundary_tets.begin(), boundary_tets.end(), outside->tet), boundary_tets.end());
    // Opaque but opened by the clipping plane halfway along z, seen from +z: the colliding tets again.
    opaque.clip = true;
    opaque.clip_axis = 2;
    const auto opened = pick_tet(session, camera, (*centre)[0], (*centre)[1], 400, 400, opaque, box);
    ASSERT_TRUE(opened.has_value());
    EXPECT_TRUE(session.result().colliding[opened->object][opened->tet]);
    // The corner of the picture shows the background.
    EXPECT_FALSE(pick_tet(session, camera, 1, 1, 400, 400, translucent, box).has_value());

    // What the panel lists: the tets the detector pairs with the picked one, with their contacts.
    const std::vector<Partner> partners = partners_of(session.result(), *hit);
    ASSERT_FALSE(partners.empty());
    std::size_t expected = 0;
    for (const TetPair& p : session.result().pairs)
        expected += (p.object_a == hit->object && p.tet_a == hit->tet) || (p.object_b == hit->object && p.tet_b == hit->tet);
    EXPECT_EQ(partners.size(), expected);
    for (const Partner& p : partners) {
        EXPECT_NE(p.tet.object, hit->object);
        EXPECT_TRUE(session.result().colliding[p.tet.object][p.tet.tet]);
        EXPECT_TRUE(p.has_contact);
        EXPECT_GE(p.contact.depth, 0.0f);
    }
    const std::vector<float> corners = vertices_of(session, {*hit});
    EXPECT_EQ(corners.size(), 12u);
}

// ---- benchmark button ----

struct CsvShape {
    std::vector<std::string> keys; ///< header keys in order
    std::string columns;
    std::size_t rows = 0;
};

CsvShape shape_of(const std::filesystem::path& path) {
    CsvShape shape;
    std::ifstream in(path);
    std::string line;
    bool in_header = true;
    while (std::getline(in, line)) {
        if (in_header && line.rfind("frame", 0) != 0 && line.rfind("run, frame", 0) != 0) {
            shape.keys.push_back(line.substr(0, line.find(", ")));
        } else if (in_header) {
            shape.columns = line;
            in_header = false;
        } else {
            ++shape.rows;
        }
    }
    return shape;
}

TEST(ViewSession, ContactsOfAnyTestWhenTheViewerShowsThem) {
    DisplaySettings normals;
    normals.contact_normals = true;
    EXPECT_TRUE(wants_contacts(normals, false));
    EXPECT_TRUE(wants_contacts(DisplaySettings{}, true)) << "a selected tet lists its partners' depths";
    EXPECT_FALSE(wants_contacts(DisplaySettings{}, false));
    for (const NarrowPhase t : {NarrowPhase::sat, NarrowPhase::sat_no_edges, NarrowPhase::sat_mtv, NarrowPhase::gjk,
                                NarrowPhase::fast, NarrowPhase::exact}) {
        DetectorOptions options;
        options.narrow_phase = t;
        options.contacts = true;
        ViewSession session(test::nested_boxes(), options, SceneSelfCollision::none);
        session.update();
        const FrameResult& r = session.result();
        ASSERT_FALSE(r.pairs.empty()) << to_string(t);
        EXPECT_EQ(r.contacts.size(), r.pairs.size()) << to_string(t);
        const std::vector<Partner> partners = partners_of(r, TetRef{r.pairs[0].object_a, r.pairs[0].tet_a});
        ASSERT_FALSE(partners.empty());
        for (const Partner& p : partners) EXPECT_TRUE(p.has_contact) << to_string(t);
    }
}

TEST(ViewBenchmark, WritesTheFilesOfKdetBench) {
    const ViewSource source = procedural(1500, 6);
    DetectorOptions options;
    options.narrow_phase = NarrowPhase::sat_mtv;
    options.contacts = true; // as the viewer sets it to draw normals; kdet bench runs without
    options.hash = HashFunction::fnv1a;
    ViewSession session(source, options, SceneSelfCollision::every);
    const auto dir = temp_dir("bench");
    BenchJob job(session.source(), bench_config_of(session, 2, (dir / "view").string()));
    while (!job.finished()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ASSERT_TRUE(job.succeeded()) << job.outcome();
    EXPECT_FLOAT_EQ(job.progress(), 1.0f);
    const cli::BenchFiles files = job.files();
    EXPECT_NE(job.outcome().find(files.averages), std::string::npos);

#ifdef KDET_CLI_PATH
    const std::string command = std::string(KDET_CLI_PATH) + " bench procedural --tets 1500 --scene-frames 6 -n 2 -s yes " +
                                "-o sat_mtv -h fnv-1a --quiet -d " + (dir / "bench").string() + " >/dev/null 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
    for (const auto& [viewer_file, suffix] : {std::pair{files.averages, std::string(".csv")}, std::pair{files.runs, std::string("_runs.csv")}}) {
        const std::filesystem::path ours(viewer_file);
        std::filesystem::path theirs;
        for (const auto& entry : std::filesystem::directory_iterator(dir / "bench"))
            if (entry.path().filename() == ours.filename()) theirs = entry.path();
        ASSERT_FALSE(theirs.empty()) << "kdet bench wrote no file named " << ours.filename() << suffix;
        const CsvShape a = shape_of(ours), b = shape_of(theirs);
        EXPECT_EQ(a.keys, b.keys);
        EXPECT_EQ(a.columns, b.columns);
        EXPECT_EQ(a.rows, b.rows);
        EXPECT_EQ(a.rows, suffix == ".csv" ? 6u : 12u);
    }
#endif
}

TEST(ViewBenchmark, StopsWithoutWritingFiles) {
    ViewSession session(procedural(20000, 120), DetectorOptions{}, SceneSelfCollision::none);
    const auto dir = temp_dir("stopped");
    BenchJob job(session.source(), bench_config_of(session, 20, dir.string()));
    job.stop();
    while (!job.finished()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_FALSE(job.succeeded());
    EXPECT_NE(job.outcome().find("stopped"), std::string::npos) << job.outcome();
    EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(ViewBenchmark, ReportsAnErrorInOneLine) {
    ViewSession session(procedural(1000, 3), DetectorOptions{}, SceneSelfCollision::none);
    const auto dir = temp_dir("blocked");
    std::ofstream(dir / "file") << "x";
    BenchJob job(session.source(), bench_config_of(session, 1, (dir / "file" / "below").string()));
    while (!job.finished()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_FALSE(job.succeeded());
    EXPECT_NE(job.outcome().find("benchmark failed"), std::string::npos) << job.outcome();
    EXPECT_EQ(job.outcome().find('\n'), std::string::npos);
}

} // namespace
} // namespace kdet::view

namespace kdet::view {
namespace {

// ---- query points ----

TEST(ViewPoints, TheSessionLocatesAsKdetLocate) {
    const test::BoxAndPoints b = test::box_and_points();
    ViewSession session(b.source, DetectorOptions{}, SceneSelfCollision::none);
    session.set_points(b.points, 0.5);
    session.update();
    const LocateResult expected = locate(b.box, b.points, LocateOptions{0.5, true});
    const LocateResult& got = session.located();
    EXPECT_EQ(got.offsets, expected.offsets);
    EXPECT_EQ(got.tets, expected.tets);
    EXPECT_EQ(got.distances, expected.distances);
    const PointCounts counts = count_points(got), want = count_points(expected);
    EXPECT_EQ(counts.held, want.held);
    EXPECT_EQ(counts.near, want.near);
    EXPECT_EQ(counts.missed, want.missed);
    EXPECT_GT(counts.held, b.box.num_vertices()); // every vertex, and random points inside
    EXPECT_GT(counts.near, 0u);
    EXPECT_GT(counts.missed, 0u);
    EXPECT_EQ(counts.held + counts.near + counts.missed, b.points.size() / 3);

    // Without a distance the near points have no tet; without points nothing is located.
    const std::uint64_t version = session.result_version();
    session.set_points(b.points, 0.0);
    EXPECT_TRUE(session.update());
    EXPECT_GT(session.result_version(), version);
    const PointCounts exact = count_points(session.located());
    EXPECT_EQ(exact.held, counts.held);
    EXPECT_EQ(exact.near, 0u);
    EXPECT_EQ(exact.missed, counts.near + counts.missed);
    session.set_points({}, 0.0);
    session.update();
    EXPECT_EQ(session.located().point_count, 0u);
}

TEST(ViewPoints, LocatedAgainOnlyWhenTheTetsOrPointsMove) {
    const test::BoxAndPoints b = test::box_and_points();
    ViewSession session(b.source, DetectorOptions{}, SceneSelfCollision::none);
    session.set_points(b.points, 0.5);
    session.update();
    const std::uint64_t located = session.located_version();
    const std::vector<std::uint64_t> offsets = session.located().offsets;
    EXPECT_GT(located, 0u);
    // Detecting again with other settings at the same positions keeps the points' answer.
    DetectorOptions options;
    options.margin = 0.01f;
    session.set_options(options);
    EXPECT_TRUE(session.update());
    EXPECT_EQ(session.located_version(), located);
    EXPECT_EQ(session.located().offsets, offsets);
    EXPECT_FALSE(session.update());
    // New points are located, and so is everything when another scene opens.
    session.set_points(b.points, 0.0);
    session.update();
    EXPECT_EQ(session.located_version(), located + 1);
    session.open(b.source);
    session.update();
    EXPECT_EQ(session.located_version(), located + 2);
    EXPECT_EQ(session.located().point_count, b.points.size() / 3);
}

TEST(ViewPoints, PointsFlags) {
    std::vector<std::string> args = {"kdet", "view", "box.mesh", "--points", "p.txt", "--within", "0.25"};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    const ViewConfig config = parse_view_args(static_cast<int>(argv.size()), argv.data(), 2);
    EXPECT_EQ(config.points, "p.txt");
    EXPECT_EQ(config.within, 0.25);
    for (const std::vector<std::string>& bad : {std::vector<std::string>{"--within", "0.5"},
                                                std::vector<std::string>{"--within", "0"},
                                                std::vector<std::string>{"--points", "p.txt", "--within", "-1"},
                                                std::vector<std::string>{"--points", "p.txt", "--within", "x"}}) {
        std::vector<std::string> line = {"kdet", "view", "box.mesh"};
        line.insert(line.end(), bad.begin(), bad.end());
        std::vector<char*> v;
        for (std::string& a : line) v.push_back(a.data());
        EXPECT_THROW(parse_view_args(static_cast<int>(v.size()), v.data(), 2), cli::UsageError) << bad.front();
    }
}

} // namespace
} // namespace kdet::view
