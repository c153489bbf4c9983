// The viewer's pictures and OpenGL buffers. These tests need an X display with OpenGL 3.3 (ctest runs
// them under xvfb-run with Mesa's software renderer); without one they report skipped, with the reason.
// Pictures are made by `kdet view --screenshot` and read back with libpng; where colliding tets must
// appear is computed here from the same camera and the library's own detection.

#include "camera.hpp"
#include "png_file.hpp"
#include "png_reader.hpp"
#include "renderer.hpp"
#include "run_command.hpp"
#include "session.hpp"
#include "view_test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/io.hpp>
#include <kdet/scenes.hpp>

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>

namespace kdet::view {
namespace {

using test::Picture;

// ---- the display ----

std::string glfw_error;

/// @brief Why OpenGL cannot run here, or empty when it can; on success a hidden window's OpenGL 3.3
/// context stays current for the rest of the process.
const std::string& gl_unavailable() {
    static const std::string reason = [] {
        const char* display = std::getenv("DISPLAY");
        if (!display || !*display)
            return std::string("no X display (DISPLAY is not set): ctest runs these tests under xvfb-run, which "
                               "scripts/install-deps.sh installs with package xvfb");
        glfwSetErrorCallback([](int, const char* text) { glfw_error = text ? text : "?"; });
        if (!glfwInit()) return "GLFW cannot open display " + std::string(display) + ": " + glfw_error;
        glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
        glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
        glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
        glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
        glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
        GLFWwindow* window = glfwCreateWindow(64, 64, "kdet view test", nullptr, nullptr);
        if (!window) return "no OpenGL 3.3 context on display " + std::string(display) + ": " + glfw_error;
        glfwMakeContextCurrent(window);
        return std::string();
    }();
    return reason;
}

#define REQUIRE_GL()                                                                                                   \
    if (!gl_unavailable().empty()) GTEST_SKIP() << gl_unavailable()

/// @brief Where the pictures go.
std::filesystem::path picture_dir() {
    static const std::filesystem::path dir = test::temp_dir("pictures");
    return dir;
}

using Outcome = kdet::test::CommandOutcome;

Outcome run_command(const std::string& command_line) { return kdet::test::run_command(command_line + " 2>&1"); }

/// @brief `kdet view ARGS --screenshot FILE`, read back.
Picture screenshot(const std::string& arguments, const std::string& name) {
    const std::string path = (picture_dir() / (name + ".png")).string();
    std::filesystem::remove(path);
    const Outcome r = run_command(std::string(KDET_CLI_PATH) + " view " + arguments + " --screenshot " + path);
    EXPECT_EQ(r.exit_code, 0) << r.out;
    if (r.exit_code != 0) return {};
    return test::read_png(path);
}

// ---- what the pixels are ----

bool is_highlight(const std::uint8_t* p) { return p[0] >= 60 && p[0] > 1.7 * p[1] && p[0] > 1.7 * p[2]; }

/// @brief A surface pixel: a cool colour, well away from the grey background.
bool is_surface(const std::uint8_t* p) { return std::max(p[1], p[2]) > p[0] + 35; }

bool is_normal_line(const std::uint8_t* p) { return p[0] > 230 && p[1] > 130 && p[1] < 175 && p[2] > 180 && p[2] < 225; }

std::size_t count(const Picture& picture, const std::function<bool(const std::uint8_t*)>& kind) {
    std::size_t n = 0;
    for (int y = 0; y < picture.height; ++y)
        for (int x = 0; x < picture.width; ++x) n += kind(picture.at(x, y)) ? 1 : 0;
    return n;
}

/// @brief Empty when @p picture looks like a rendered scene: a background that is not black, and
/// some surface. Otherwise what is wrong.
std::string picture_problem(const Picture& picture) {
    if (picture.width == 0) return "no picture";
    const double pixels = static_cast<double>(picture.width) * picture.height;
    double brightness = 0;
    for (std::uint8_t v : picture.rgb) brightness += v;
    brightness /= 3 * pixels;
    if (brightness < 20) return "black (mean brightness " + std::to_string(brightness) + ")";
    const std::size_t objects = count(picture, is_surface) + count(picture, is_highlight);
    if (static_cast<double>(objects) < 0.01 * pixels) return "almost no object pixels (" + std::to_string(objects) + ")";
    if (static_cast<double>(objects) > 0.9 * pixels) return "objects cover the whole picture: no background";
    return {};
}

// ---- where colliding tets must appear ----

/// @brief Pixels covered by the projections of the colliding tets of each object (positions as
/// the viewer draws them), seen through the camera the viewer sets up for a picture of this size.
/// `kept(p)` says which points survive a clipping plane: a tet counts when any vertex is kept.
struct Coverage {
    int width, height;
    std::vector<std::uint8_t> covered;
    std::size_t tets = 0;
    bool at(int x, int y) const {
        return x >= 0 && y >= 0 && x < width && y < height && covered[static_cast<std::size_t>(y * width + x)];
    }
    /// @brief Whether any pixel within @p radius of (x, y) is covered.
    bool near(int x, int y, int radius) const {
        for (int dy = -radius; dy <= radius; ++dy)
            for (int dx = -radius; dx <= radius; ++dx)
                if (at(x + dx, y + dy)) return true;
        return false;
    }
    /// @brief Whether every pixel within @p radius of (x, y) is covered.
    bool inside(int x, int y, int radius) const {
        for (int dy = -radius; dy <= radius; ++dy)
            for (int dx = -radius; dx <= radius; ++dx)
                if (!at(x + dx, y + dy)) return false;
        return true;
    }
};

void fill_triangle(Coverage& c, const std::array<float, 2>& a, const std::array<float, 2>& b, const std::array<float, 2>& d) {
    const float area = (b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0]);
    if (area == 0) return;
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a[0], b[0], d[0]}))));
    const int x1 = std::min(c.width - 1, static_cast<int>(std::ceil(std::max({a[0], b[0], d[0]}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a[1], b[1], d[1]}))));
    const int y1 = std::min(c.height - 1, static_cast<int>(std::ceil(std::max({a[1], b[1], d[1]}))));
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            const float px = static_cast<float>(x) + 0.5f, py = static_cast<float>(y) + 0.5f;
            const float w0 = ((b[0] - px) * (d[1] - py) - (b[1] - py) * (d[0] - px)) / area;
            const float w1 = ((d[0] - px) * (a[1] - py) - (d[1] - py) * (a[0] - px)) / area;
            if (w0 >= 0 && w1 >= 0 && w0 + w1 <= 1) c.covered[static_cast<std::size_t>(y * c.width + x)] = 1;
        }
}

/// @brief The camera `kdet view` sets up for a picture of @p width x @p height of @p positions,
/// looking from (yaw, pitch).
OrbitCamera camera_for(const std::vector<std::vector<float>>& positions, int width, int height,
                       float yaw = OrbitCamera::default_yaw, float pitch = OrbitCamera::default_pitch) {
    OrbitCamera camera;
    camera.set_angles(yaw, pitch);
    camera.frame(positions, static_cast<float>(width) / static_cast<float>(height));
    return camera;
}

Coverage colliding_coverage(const Scene& scene, int frame, int width, int height,
                            float yaw = OrbitCamera::default_yaw, float pitch = OrbitCamera::default_pitch,
                            const std::function<bool(Vec3)>& kept = [](Vec3) { return true; }) {
    std::vector<std::vector<float>> positions(scene.num_objects());
    Detector detector;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        scene.positions(o, frame, positions[o]);
        detector.add_object(scene.rest_mesh(o));
        detector.set_positions(static_cast<ObjectId>(o), positions[o].data(), positions[o].size() / 3);
    }
    const FrameResult& result = detector.detect();
    const OrbitCamera camera = camera_for(positions, width, height, yaw, pitch);
    Coverage c{width, height, std::vector<std::uint8_t>(static_cast<std::size_t>(width * height), 0)};
    for (std::size_t o = 0; o < scene.num_objects(); ++o)
        for (std::size_t t = 0; t < result.colliding[o].size(); ++t) {
            if (!result.colliding[o][t]) continue;
            std::array<std::array<float, 2>, 4> corner{};
            bool any_kept = false;
            for (int k = 0; k < 4; ++k) {
                const std::size_t v = scene.rest_mesh(o).tets[4 * t + static_cast<std::size_t>(k)];
                const Vec3 p{positions[o][3 * v], positions[o][3 * v + 1], positions[o][3 * v + 2]};
                any_kept = any_kept || kept(p);
                corner[static_cast<std::size_t>(k)] = *camera.project(p, width, height);
            }
            if (!any_kept) continue;
            ++c.tets;
            for (int skip = 0; skip < 4; ++skip) {
                std::array<std::array<float, 2>, 3> tri{};
                for (int k = 0, n = 0; k < 4; ++k)
                    if (k != skip) tri[static_cast<std::size_t>(n++)] = corner[static_cast<std::size_t>(k)];
                fill_triangle(c, tri[0], tri[1], tri[2]);
            }
        }
    return c;
}

/// @brief Checks that highlight pixels lie where colliding tets project and that the projections
/// are highlighted, both with a margin of a pixel or two for antialiased edges.
void expect_highlights_match(const Picture& picture, const Coverage& expected) {
    ASSERT_EQ(picture.width, expected.width);
    ASSERT_EQ(picture.height, expected.height);
    std::size_t highlight = 0, stray = 0, interior = 0, interior_highlight = 0;
    for (int y = 0; y < picture.height; ++y)
        for (int x = 0; x < picture.width; ++x) {
            const bool h = is_highlight(picture.at(x, y));
            if (h) {
                ++highlight;
                if (!expected.near(x, y, 2)) ++stray;
            }
            if (expected.inside(x, y, 2)) {
                ++interior;
                if (h) ++interior_highlight;
            }
        }
    ASSERT_GT(expected.tets, 0u);
    ASSERT_GT(highlight, 0u) << "no highlight pixels although " << expected.tets << " tets collide";
    EXPECT_LE(stray, highlight / 500) << stray << " of " << highlight << " highlight pixels lie where no colliding tet projects";
    ASSERT_GT(interior, 0u);
    EXPECT_GE(interior_highlight, interior * 97 / 100)
        << "only " << interior_highlight << " of " << interior << " pixels inside the colliding tets' projections are highlighted";
}

std::string procedural_arguments(std::size_t tets, int frames) {
    return "procedural --tets " + std::to_string(tets) + " --scene-frames " + std::to_string(frames);
}

// ---- pictures ----

TEST(ViewPicture, BlankAndBlackPicturesFailTheChecks) {
    Picture black{64, 48, std::vector<std::uint8_t>(64 * 48 * 3, 0)};
    EXPECT_NE(picture_problem(black), "");
    Picture grey{64, 48, std::vector<std::uint8_t>(64 * 48 * 3, 90)};
    EXPECT_NE(picture_problem(grey), "");
    Picture red = grey;
    for (std::size_t i = 0; i < red.rgb.size(); i += 3) red.rgb[i] = 240;
    EXPECT_NE(picture_problem(red), "");
    EXPECT_EQ(picture_problem(Picture{}), "no picture");
}

TEST(ViewPicture, CollidingTetsAreHighlightedWhereTheyProject) {
    REQUIRE_GL();
    const auto scene = open_scene("procedural", SceneRequest{1, ProceduralSceneOptions{6000, 41}});
    const Picture picture = screenshot(procedural_arguments(6000, 41) + " --frame 20 --size 640x400", "colliding");
    ASSERT_EQ(picture.width, 640);
    ASSERT_EQ(picture.height, 400);
    EXPECT_EQ(picture_problem(picture), "");
    expect_highlights_match(picture, colliding_coverage(*scene, 20, 640, 400));
}

TEST(ViewPicture, NoHighlightWithoutCollisions) {
    REQUIRE_GL();
    const auto scene = open_scene("procedural", SceneRequest{1, ProceduralSceneOptions{6000, 41}});
    ASSERT_EQ(colliding_coverage(*scene, 0, 320, 200).tets, 0u) << "frame 0 of the procedural scene is apart";
    const Picture picture = screenshot(procedural_arguments(6000, 41) + " --frame 0 --size 320x200", "apart");
    EXPECT_EQ(picture_problem(picture), "");
    EXPECT_EQ(count(picture, is_highlight), 0u);
}

TEST(ViewPicture, InteriorCollisionsShowThroughTheSurface) {
    REQUIRE_GL();
    const ViewSource source = test::nested_boxes();
    const auto scene = open_view_source(source);
    const std::string files = source.meshes[0] + " " + source.meshes[1];
    const Picture translucent = screenshot(files + " --size 480x360", "nested");
    EXPECT_EQ(picture_problem(translucent), "");
    expect_highlights_match(translucent, colliding_coverage(*scene, 0, 480, 360));
    // Drawn opaque, the big box hides them: what made them visible is the translucent surface.
    const Picture opaque = screenshot(files + " --size 480x360 --opacity 1", "nested_opaque");
    EXPECT_EQ(picture_problem(opaque), "");
    EXPECT_EQ(count(opaque, is_highlight), 0u);
}

TEST(ViewPicture, TheClippingPlaneOpensTheMesh) {
    REQUIRE_GL();
    const ViewSource source = test::nested_boxes();
    const auto scene = open_view_source(source);
    const std::string files = source.meshes[0] + " " + source.meshes[1] + " --size 480x360 --opacity 1";
    struct Cut {
        const char* flag;
        float yaw;
        std::function<bool(Vec3)> kept;
    };
    // The scene's box is [0, 8] along z: the plane at 0.5 keeps z <= 4 (or z >= 4 flipped), which
    // cuts the small box; each side is looked at from where the plane opens it.
    const Cut cuts[] = {{"z", 20.0f, [](Vec3 p) { return p.z <= 4.0f; }},
                        {"-z", 200.0f, [](Vec3 p) { return p.z >= 4.0f; }}};
    for (const Cut& cut : cuts) {
        SCOPED_TRACE(cut.flag);
        const std::string view = files + " --camera " + std::to_string(cut.yaw) + ",50";
        const Picture clipped = screenshot(view + " --clip " + cut.flag + " --clip-at 0.5", "clipped");
        EXPECT_EQ(picture_problem(clipped), "");
        const Coverage kept = colliding_coverage(*scene, 0, 480, 360, cut.yaw, 50, cut.kept);
        std::size_t highlight = 0, stray = 0;
        for (int y = 0; y < clipped.height; ++y)
            for (int x = 0; x < clipped.width; ++x)
                if (is_highlight(clipped.at(x, y))) {
                    ++highlight;
                    if (!kept.near(x, y, 2)) ++stray;
                }
        EXPECT_GT(highlight, 500u) << "the cut opens the big box onto the colliding tets";
        EXPECT_LE(stray, highlight / 500) << "highlight pixels of tets the plane removed";
        // Without the plane the same view shows none of them.
        const Picture closed = screenshot(view, "closed");
        EXPECT_EQ(count(closed, is_highlight), 0u);
    }
}

TEST(ViewPicture, OptionsChosenBeforeTheFirstDetection) {
    REQUIRE_GL();
    // Every hash and a brute-force method, set on the command line before anything was detected,
    // highlight the same tets.
    const auto scene = open_scene("procedural", SceneRequest{1, ProceduralSceneOptions{3000, 21}});
    const Coverage expected = colliding_coverage(*scene, 10, 320, 240);
    for (const char* options : {"--hash morton", "--hash fnv-1a", "--hash simple", "--method brute_force_loop --threads 1",
                                "--method kdet_no_pairs", "--test gjk"}) {
        const Picture picture = screenshot(procedural_arguments(3000, 21) + " --frame 10 --size 320x240 " + options, "option");
        SCOPED_TRACE(options);
        expect_highlights_match(picture, expected);
    }
}

TEST(ViewPicture, DisplayModes) {
    REQUIRE_GL();
    const std::string base = procedural_arguments(4000, 21) + " --frame 10 --size 400x300";
    const Picture plain = screenshot(base, "plain");
    const std::size_t plain_surface = count(plain, is_surface);
    // Only the colliding tets: no surface left, the same highlights.
    const Picture only = screenshot(base + " --only-colliding", "only");
    EXPECT_LT(count(only, is_surface), plain_surface / 50);
    EXPECT_NEAR(static_cast<double>(count(only, is_highlight)), static_cast<double>(count(plain, is_highlight)),
                0.02 * static_cast<double>(count(plain, is_highlight)));
    // Wireframe: dark edges over the surfaces.
    const auto dark = [](const std::uint8_t* p) { return p[0] < 40 && p[1] < 45 && p[2] < 55; };
    const Picture wire = screenshot(base + " --wireframe", "wire");
    EXPECT_GT(count(wire, dark), count(plain, dark) + 1000);
    // Contact normals: pink lines with --normals only, whatever the test (contacts are an option).
    const Picture normals = screenshot(base + " --test sat_mtv --normals", "normals");
    EXPECT_GT(count(normals, is_normal_line), 200u);
    EXPECT_EQ(count(plain, is_normal_line), 0u);
    const Picture other_test = screenshot(base + " --test gjk --normals", "other_test");
    EXPECT_GT(count(other_test, is_normal_line), 200u) << "--normals turns contacts on under any test";
    // The panel: a darker column at the left with text, the scene beside it.
    const Picture panel = screenshot(base + " --size 900x600 --panel", "panel");
    ASSERT_EQ(panel.width, 900);
    std::size_t panel_bright = 0, panel_highlight = 0;
    for (int y = 0; y < panel.height; ++y)
        for (int x = 0; x < 380; ++x) {
            const std::uint8_t* p = panel.at(x, y);
            panel_bright += p[0] > 200 && p[1] > 200 && p[2] > 200;
            panel_highlight += is_highlight(p);
        }
    EXPECT_GT(panel_bright, 2000u) << "the panel's text";
    EXPECT_EQ(panel_highlight, 0u) << "the scene is drawn beside the panel, not under it";
    EXPECT_GT(count(panel, is_highlight), 1000u);
}

TEST(ViewCommand, FrameOutOfRangeAndOneLineErrors) {
    const Outcome far = run_command(std::string(KDET_CLI_PATH) + " view --tets 1000 --scene-frames 5 --frame 5");
    EXPECT_EQ(far.exit_code, 2) << far.out;
    EXPECT_NE(far.out.find("kdet view: invalid value '5' for --frame: scene 'procedural' has frames 0 to 4"),
              std::string::npos)
        << far.out;
    const Outcome missing = run_command(std::string(KDET_CLI_PATH) + " view no_such_mesh.mesh --screenshot x.png");
    EXPECT_EQ(missing.exit_code, 1) << missing.out;
    EXPECT_NE(missing.out.find("no_such_mesh.mesh"), std::string::npos) << missing.out;
    // A resolution the scene is not built at would only mislabel what is drawn.
    const Outcome resolution = run_command(std::string(KDET_CLI_PATH) + " view tearing --res 3 --screenshot x.png");
    EXPECT_EQ(resolution.exit_code, 2) << resolution.out;
    EXPECT_NE(resolution.out.find("kdet view: invalid value '3' for --res: scene 'tearing' has no resolution"), std::string::npos)
        << resolution.out;
    for (const Outcome& r : {far, missing, resolution}) EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    // Without a display the window cannot open: one line that says how to draw without one.
    const Outcome no_display =
        run_command("env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(KDET_CLI_PATH) + " view --tets 1000 --screenshot x.png");
    EXPECT_EQ(no_display.exit_code, 1) << no_display.out;
    EXPECT_NE(no_display.out.find("xvfb-run"), std::string::npos) << no_display.out;
    EXPECT_EQ(std::count(no_display.out.begin(), no_display.out.end(), '\n'), 1) << no_display.out;
}

// ---- OpenGL buffers, in this process ----

TEST(ViewRenderer, EveryKindOfThingHasAColourOfItsOwn) {
    // Objects, colliding tets, margin tets, the tets holding query points, the points by status, the
    // contact normals and a picked tet with its partners: no two kinds near enough to be confused.
    struct Kind {
        std::string name;
        Color color;
    };
    std::vector<Kind> kinds{{"colliding", highlight_color()}, {"margin", margin_color()}, {"located", located_color()},
                            {"normals", normal_color()},     {"selected", selected_color()}, {"partners", partner_color()}};
    for (int status = 0; status < 3; ++status) kinds.push_back({"point " + std::to_string(status), point_color(status)});
    const auto distance = [](Color a, Color b) {
        return std::sqrt((a.r - b.r) * (a.r - b.r) + (a.g - b.g) * (a.g - b.g) + (a.b - b.b) * (a.b - b.b));
    };
    for (std::size_t i = 0; i < kinds.size(); ++i)
        for (std::size_t j = i + 1; j < kinds.size(); ++j) {
            if (kinds[i].name == "selected" && kinds[j].name == "point 0") continue; // one tet and dots: told apart by shape
            EXPECT_GT(distance(kinds[i].color, kinds[j].color), 0.3f) << kinds[i].name << " and " << kinds[j].name;
        }
    for (std::size_t object = 0; object < 6; ++object) {
        for (const Kind& kind : kinds)
            EXPECT_GT(distance(object_color(object), kind.color), 0.3f) << "object " << object << " and " << kind.name;
        for (std::size_t other = 0; other < object; ++other)
            EXPECT_GT(distance(object_color(object), object_color(other)), 0.15f) << "objects " << object << " and " << other;
    }
}

TEST(ViewRenderer, VertexBuffersAreUpdatedInPlace) {
    REQUIRE_GL();
    ViewSession session(test::procedural(8000, 31), DetectorOptions{}, SceneSelfCollision::none);
    Renderer renderer;
    OffscreenTarget target(160, 120, 1);
    const auto play = [&] {
        for (int f = 0; f < session.num_frames(); ++f) {
            session.set_frame(f);
            session.update();
            renderer.update(session);
            target.bind();
            renderer.draw(camera_for(session.positions(), 160, 120), 0, 0, 160, 120, DisplaySettings{}, Bounds{});
        }
    };
    play();
    const BufferStats first = renderer.stats();
    // Per object: vertices, surface indices, colliding-tet indices.
    EXPECT_EQ(first.live_buffers, 6u);
    EXPECT_EQ(first.position_uploads, 2u * 31u);
    EXPECT_LE(first.allocations, 4u + 2u * 8u) << "index buffers grow geometrically, a few times at most";
    play();
    const BufferStats second = renderer.stats();
    EXPECT_EQ(second.allocations, first.allocations) << "a second pass through the animation allocates nothing";
    EXPECT_EQ(second.position_uploads, 2u * 2u * 31u);
    EXPECT_EQ(second.bytes, first.bytes);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(ViewRenderer, ATornMeshIsDrawnAsItsTetsChange) {
    REQUIRE_GL();
    ViewSource source;
    source.scene = "tearing";
    ViewSession session(source, DetectorOptions{}, SceneSelfCollision::none);
    Renderer renderer;
    OffscreenTarget target(200, 150, 1);
    const auto picture = [&](const Renderer& r) {
        target.bind();
        r.draw(camera_for(session.positions(), 200, 150), 0, 0, 200, 150, DisplaySettings{}, Bounds{});
        return target.read_rgb();
    };
    std::vector<std::uint32_t> tets;
    std::size_t previous = 0;
    for (int frame : {0, 30, 60, 90, 119, 45}) {
        session.set_frame(frame);
        session.update();
        renderer.update(session);
        // The surface drawn is that of this frame's tets, not the slab as it was.
        TetMesh torn = session.scene().rest_mesh(0);
        session.scene().tets(0, frame, tets);
        torn.tets = tets;
        const std::size_t triangles = analyse_faces(torn).boundary.size() / 3;
        EXPECT_EQ(renderer.surface_triangles(0), triangles) << "frame " << frame;
        if (frame != 0) {
            EXPECT_NE(triangles, previous) << "the tear changes the surface by frame " << frame;
        }
        previous = triangles;
        // A renderer made for this frame alone draws the same picture as the one that followed the tear.
        Renderer fresh;
        fresh.update(session);
        EXPECT_TRUE(picture(renderer) == picture(fresh)) << "frame " << frame;
    }
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(ViewRenderer, TheSelectionIsDrawnOverEverything) {
    REQUIRE_GL();
    ViewSession session(test::nested_boxes(), DetectorOptions{}, SceneSelfCollision::none);
    session.update();
    Renderer renderer;
    renderer.update(session);
    OffscreenTarget target(240, 180, 1);
    DisplaySettings opaque;
    opaque.surface_opacity = 1.0f; // the selected tet lies inside the big box
    const auto picture = [&] {
        target.bind();
        renderer.draw(camera_for(session.positions(), 240, 180), 0, 0, 240, 180, opaque, Bounds{});
        return target.read_rgb();
    };
    const std::vector<std::uint8_t> before = picture();
    const std::vector<TetRef> colliding = colliding_tets(session);
    ASSERT_FALSE(colliding.empty());
    std::vector<TetRef> shown = {colliding.front()};
    for (const Partner& p : partners_of(session.result(), colliding.front())) shown.push_back(p.tet);
    renderer.select(session, shown);
    const std::vector<std::uint8_t> selected = picture();
    // Pixels that the selection turned white-grey (it is lit, so not pure white).
    std::size_t grey = 0;
    for (std::size_t i = 0; i < selected.size(); i += 3) {
        const int r = selected[i], g = selected[i + 1], b = selected[i + 2];
        const bool changed = r != before[i] || g != before[i + 1] || b != before[i + 2];
        grey += changed && r > 90 && std::abs(r - g) < 12 && std::abs(g - b) < 12;
    }
    EXPECT_GT(grey, 20u) << "the selected tet shows through the opaque box";
    renderer.select(session, {});
    EXPECT_EQ(picture(), before);
}

TEST(ViewRenderer, FiftySwitchesKeepBuffersAndMemoryBounded) {
    REQUIRE_GL();
    const std::vector<ViewSource> sources = {test::procedural(6000, 9), test::octopus_pair(), test::procedural(2000, 9)};
    const std::vector<Method> methods = {Method::kdet, Method::brute_force_loop, Method::kdet_no_pairs};
    ViewSession session(sources[0], DetectorOptions{}, SceneSelfCollision::none);
    Renderer renderer;
    OffscreenTarget target(200, 150, 4);
    std::vector<std::size_t> bytes_of(sources.size(), 0), detector_of(sources.size() * methods.size(), 0);
    std::size_t resident_after_warm_up = 0, most_resident = 0;
    for (int k = 0; k < 50; ++k) {
        const std::size_t s = static_cast<std::size_t>(k) % sources.size(), m = static_cast<std::size_t>(k / 3) % methods.size();
        DetectorOptions options;
        options.method = methods[m];
        session.set_options(options);
        session.open(sources[s]);
        session.set_frame(4);
        session.update();
        renderer.update(session);
        target.bind();
        renderer.draw(camera_for(session.positions(), 200, 150), 0, 0, 200, 150, DisplaySettings{}, Bounds{});
        glFinish();
        // Buffers of the old scene are gone: what is held depends on the scene alone.
        EXPECT_EQ(renderer.stats().live_buffers, 2u * 3u);
        if (bytes_of[s] == 0) bytes_of[s] = renderer.stats().bytes;
        EXPECT_LE(renderer.stats().bytes, bytes_of[s] * 2) << "switch " << k;
        std::size_t& detector = detector_of[s * methods.size() + m];
        if (detector == 0) detector = session.detector_memory();
        EXPECT_EQ(session.detector_memory(), detector) << "switch " << k;
        if (k == 17) resident_after_warm_up = resident_bytes();
        most_resident = std::max(most_resident, resident_bytes());
    }
    ASSERT_GT(resident_after_warm_up, 0u);
    EXPECT_LT(most_resident, resident_after_warm_up + (48u << 20))
        << "resident set grew from " << resident_after_warm_up << " to " << most_resident << " bytes";
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// ---- query points ----

/// @brief Pixels of @p rgb within a few levels of @p color, which is drawn unlit.
std::size_t count_color(const std::vector<std::uint8_t>& rgb, Color color) {
    const float want[3] = {color.r * 255.0f, color.g * 255.0f, color.b * 255.0f};
    std::size_t n = 0;
    for (std::size_t i = 0; i < rgb.size(); i += 3) {
        bool close = true;
        for (std::size_t k = 0; k < 3; ++k) close = close && std::abs(static_cast<float>(rgb[i + k]) - want[k]) < 4.0f;
        n += close;
    }
    return n;
}

/// @brief Pixels of the tets that hold points: green well above red and blue.
std::size_t count_located(const std::vector<std::uint8_t>& rgb) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < rgb.size(); i += 3) n += rgb[i + 1] > rgb[i] + 40 && rgb[i + 1] > rgb[i + 2] + 60;
    return n;
}

/// @brief @p session drawn by @p renderer into all of @p target with the default display.
std::vector<std::uint8_t> draw_session(const Renderer& renderer, const OffscreenTarget& target, const ViewSession& session) {
    target.bind();
    renderer.draw(camera_for(session.positions(), target.width(), target.height()), 0, 0, target.width(), target.height(),
                  DisplaySettings{}, Bounds{});
    return target.read_rgb();
}

TEST(ViewRenderer, QueryPointsAndTheirTetsAreDrawn) {
    REQUIRE_GL();
    const test::BoxAndPoints b = test::box_and_points();
    ViewSession session(b.source, DetectorOptions{}, SceneSelfCollision::none);
    session.update();
    Renderer renderer;
    renderer.update(session);
    OffscreenTarget target(240, 180, 1);
    const auto picture = [&] { return draw_session(renderer, target, session); };
    const std::vector<std::uint8_t> before = picture();
    session.set_points(b.points, 0.5);
    session.update();
    renderer.update(session);
    const PointCounts counts = count_points(session.located());
    EXPECT_EQ(renderer.point_counts()[0], counts.held);
    EXPECT_EQ(renderer.point_counts()[1], counts.near);
    EXPECT_EQ(renderer.point_counts()[2], counts.missed);
    const std::vector<std::uint8_t> after = picture();
    for (int status = 0; status < 3; ++status) {
        EXPECT_EQ(count_color(before, point_color(status)), 0u) << status;
        EXPECT_GT(count_color(after, point_color(status)), 100u) << status;
    }
    EXPECT_EQ(count_located(before), 0u);
    EXPECT_GT(count_located(after), 1000u) << "the tets that hold points";
    session.set_points({}, 0.0);
    session.update();
    renderer.update(session);
    EXPECT_EQ(picture(), before);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

/// @brief Pixels of the tets within the margin only: yellow, red and green well above blue.
std::size_t count_margin(const std::vector<std::uint8_t>& rgb) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < rgb.size(); i += 3) n += rgb[i] > rgb[i + 2] + 80 && rgb[i + 1] > rgb[i + 2] + 70;
    return n;
}

TEST(ViewRenderer, TheTetsWithinTheMarginOnlyHaveTheirOwnColour) {
    REQUIRE_GL();
    DetectorOptions options;
    options.margin = 0.02f;
    ViewSession session(test::procedural(4000, 21), options, SceneSelfCollision::none);
    session.set_frame(9);
    session.update();
    Renderer renderer;
    renderer.update(session);
    OffscreenTarget target(320, 240, 1);
    const std::vector<std::uint8_t> with_margin = draw_session(renderer, target, session);
    session.set_options(DetectorOptions{});
    session.update();
    renderer.update(session);
    const std::vector<std::uint8_t> without = draw_session(renderer, target, session);
    const Picture shown{320, 240, with_margin};
    EXPECT_GT(count_margin(with_margin), 100u);
    EXPECT_GT(count(shown, is_highlight), 100u) << "the overlapping tets stay red";
    EXPECT_EQ(count_margin(without), 0u);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(ViewRenderer, ASelectedPointShowsOnlyItsTets) {
    REQUIRE_GL();
    const test::BoxAndPoints b = test::box_and_points();
    ViewSession session(b.source, DetectorOptions{}, SceneSelfCollision::none);
    session.set_points(b.points, 0.5);
    session.update();
    Renderer renderer;
    renderer.update(session);
    OffscreenTarget target(240, 180, 1);
    const OrbitCamera camera = camera_for(session.positions(), 240, 180);
    const auto picture = [&](const std::string& name) {
        target.bind();
        renderer.draw(camera, 0, 0, 240, 180, DisplaySettings{}, Bounds{});
        std::vector<std::uint8_t> rgb = target.read_rgb();
        write_png((picture_dir() / (name + ".png")).string(), 240, 180, rgb);
        return rgb;
    };
    const std::vector<std::uint8_t> every = picture("points_every");
    // A random point inside the box that one tet holds, picked where it is drawn.
    const LocateResult& located = session.located();
    std::size_t chosen = located.point_count;
    for (std::size_t p = b.box.num_vertices(); p < located.point_count && chosen == located.point_count; ++p)
        if (located.offsets[p + 1] - located.offsets[p] == 1 && located.distances[located.offsets[p]] == 0) chosen = p;
    ASSERT_LT(chosen, located.point_count);
    const Vec3 at{static_cast<float>(b.points[3 * chosen]), static_cast<float>(b.points[3 * chosen + 1]),
                  static_cast<float>(b.points[3 * chosen + 2])};
    const auto pixel = camera.project(at, 240, 180);
    ASSERT_TRUE(pixel.has_value());
    const auto picked = pick_point(session, camera, (*pixel)[0], (*pixel)[1], 240, 180, 0.5f);
    ASSERT_TRUE(picked.has_value());
    EXPECT_EQ(*picked, chosen) << "no other point projects within half a pixel of it";
    EXPECT_FALSE(pick_point(session, camera, -50, -50, 240, 180, 6).has_value());

    renderer.select_point(session, chosen);
    EXPECT_EQ(renderer.point_counts()[0], 1u) << "the chosen point alone";
    EXPECT_EQ(renderer.point_counts()[1] + renderer.point_counts()[2], 0u);
    const std::vector<std::uint8_t> one = picture("points_one");
    EXPECT_GT(count_located(one), 0u) << "the chosen point's tet";
    EXPECT_LT(count_located(one) * 4, count_located(every)) << "one tet among many";
    // A point no tet holds but one within the distance: its nearest tet.
    std::size_t near = located.point_count;
    for (std::size_t p = 0; p < located.point_count && near == located.point_count; ++p)
        if (point_status(located, p) == 1) near = p;
    ASSERT_LT(near, located.point_count);
    renderer.select_point(session, near);
    EXPECT_EQ(renderer.point_counts()[1], 1u);
    EXPECT_GT(count_located(picture("points_near")), 0u);
    renderer.select_point(session, std::nullopt);
    EXPECT_EQ(picture("points_every_again"), every);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(ViewCommand, PointsInAScreenshotAndBadPointsFiles) {
    REQUIRE_GL();
    const test::BoxAndPoints b = test::box_and_points();
    const auto dir = test::temp_dir("points_command");
    const std::string points = (dir / "points.txt").string(), bad = (dir / "bad.txt").string();
    {
        std::FILE* file = std::fopen(points.c_str(), "w");
        for (std::size_t i = 0; i < b.points.size(); i += 3)
            std::fprintf(file, "%.17g %.17g %.17g\n", b.points[i], b.points[i + 1], b.points[i + 2]);
        std::fclose(file);
        file = std::fopen(bad.c_str(), "w");
        std::fprintf(file, "1 2 3\n1 2\n");
        std::fclose(file);
    }
    const PointCounts want = count_points(locate(b.box, b.points, LocateOptions{0.5, true}));
    const std::string png = (picture_dir() / "points.png").string();
    const std::string view = std::string(KDET_CLI_PATH) + " view " + b.source.meshes[0];
    const Outcome shot = run_command(view + " --points " + points + " --within 0.5 --size 320x240 --screenshot " + png);
    ASSERT_EQ(shot.exit_code, 0) << shot.out;
    EXPECT_NE(shot.out.find("points: " + std::to_string(want.held) + " in a tet, " + std::to_string(want.near) +
                            " near one, " + std::to_string(want.missed) + " without"),
              std::string::npos)
        << shot.out;
    const Picture picture = test::read_png(png);
    EXPECT_GT(count_color(picture.rgb, point_color(2)), 0u) << "points without a tet";
    EXPECT_GT(count_located(picture.rgb), 0u);

    const Outcome malformed = run_command(view + " --points " + bad + " --screenshot " + png);
    EXPECT_EQ(malformed.exit_code, 1) << malformed.out;
    EXPECT_NE(malformed.out.find("bad.txt:2"), std::string::npos) << malformed.out;
    EXPECT_EQ(std::count(malformed.out.begin(), malformed.out.end(), '\n'), 1) << malformed.out;
}

} // namespace
} // namespace kdet::view
