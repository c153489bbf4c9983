#include "view_args.hpp"

#include "cli_args.hpp"
#include "commands.hpp"

#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <cfloat>
#include <cstdio>
#include <filesystem>

namespace kdet::view {

namespace {

const char* help_text = R"(usage: kdet view [SCENE | A [B]] [options]

Shows a scene or meshes in a window and runs collision detection on every frame: boundary surfaces
in one colour per object, colliding tetrahedra highlighted, a side panel with every setting, the
counts, stage times and memory, a frame-time plot and a benchmark button.

SCENE is anything `kdet bench` opens: procedural (default), a thesis scene, a .scene file, a
.kdetrec recording or a folder of per-frame meshes. A [B] are mesh files as in `kdet collide`.

scene options:
  --self               self-collision of every object (as `kdet bench -s yes`)
  --self-scene         self-collision of the objects the scene marks (a scene file's `self`
                       lines; as `kdet bench -s scene`)
  --exclusion-rings K  with --self or --self-scene, also leave out tets within K mesh edges of
                       each other (0-4, as `kdet collide --exclusion-rings`; the panel's slider
                       changes it)
  --res N, -r N        resolution 1-4 of the thesis scenes (default 1)
  --tets N             tetrahedra of the procedural scene (default 100000)
  --scene-frames N     frames of the procedural scene (default 120)
  --frame N            first frame shown (0-based, default 0)
  --allow-degenerate   accept zero-volume tetrahedra in mesh files
  --points FILE        query points (`x y z` lines, or a mesh file's vertices) located in every
                       frame as `kdet locate` does: points in a tet white, the tets holding them
                       green, points given the nearest tet by --within orange, the rest magenta;
                       a click on a point shows it alone with its tets
  --within D           with --points: a point no tet holds gets the nearest tet within D

detector options:
)";

const char* controls = "left drag orbits, right or middle drag (or shift + left) pans, the wheel zooms, a click "
                       "selects a tet (the panel lists the tets it collides with); space plays and pauses, left/right "
                       "step a frame, R resets the camera, F frames the colliding tets, P saves a screenshot, W "
                       "wireframe, C clipping plane, H colliding tets only, N contact normals, Tab hides the panel, "
                       "Esc quits.";

/// @brief @p text broken into lines of at most @p width characters, each after @p indent.
std::string wrapped(const std::string& text, std::size_t width, const std::string& indent) {
    std::string out, line;
    std::size_t start = 0;
    while (start < text.size()) {
        std::size_t end = text.find(' ', start);
        if (end == std::string::npos) end = text.size();
        const std::string word = text.substr(start, end - start);
        if (!line.empty() && indent.size() + line.size() + 1 + word.size() > width) {
            out += indent + line + "\n";
            line.clear();
        }
        line += (line.empty() ? "" : " ") + word;
        start = end + 1;
    }
    return out + indent + line + "\n";
}

const char* display_help = R"(
display options (the panel changes them too):
  --opacity A          surface opacity 0-1 (default 0.35; below 1 colliding tets show through)
  --only-colliding     draw the colliding tetrahedra only
  --wireframe          draw the surface's edges
  --clip AXIS          clipping plane across x, y or z (-x, -y, -z keep the other side)
  --clip-at T          position of the plane across the scene's box, 0-1 (default 0.5)
  --normals            contact normals as short lines (turns the detector's contacts on)
  --camera YAW,PITCH   view direction in degrees (default 35,25)
  --zoom F             camera distance as a multiple of the framing distance (default 1)
  --focus WHAT         start framed on the colliding tetrahedra (colliding, as the F key) or on
                       the whole scene (all, the default)

headless (no window; needs an X display: run under xvfb-run on a machine without one):
  --screenshot FILE    draw frame --frame into a PNG and exit
  --size WxH           picture or window size in pixels (default 1280x800)
  --panel              draw the side panel into the screenshot too
  --samples N          multisampling: 1, 2, 4 (default) or 8
  --profile            draw every frame once off-screen; print per-frame times of detection and
                       drawing, and their medians
  --help               this text
)";

float parse_float(const std::string& flag, const std::string& text, float lo, float hi) {
    char range[64];
    std::snprintf(range, sizeof range, "a number in [%g, %g]", static_cast<double>(lo), static_cast<double>(hi));
    return static_cast<float>(parse_number(flag, text, lo, hi, range));
}

void parse_size(const std::string& text, ViewConfig& config) {
    const auto x = text.find('x');
    try {
        if (x == std::string::npos) throw Error("");
        config.width = static_cast<int>(parse_integer("--size", text.substr(0, x), 16, 8192));
        config.height = static_cast<int>(parse_integer("--size", text.substr(x + 1), 16, 8192));
    } catch (const Error&) {
        throw cli::UsageError("invalid value '" + text + "' for --size: expected WxH, e.g. 1280x800 (16 to 8192 each)");
    }
}

void parse_camera(const std::string& text, CameraRequest& camera) {
    const auto comma = text.find(',');
    if (comma == std::string::npos)
        throw cli::UsageError("invalid value '" + text + "' for --camera: expected YAW,PITCH in degrees, e.g. 35,25");
    camera.yaw = parse_float("--camera", text.substr(0, comma), -360.0f, 360.0f);
    camera.pitch = parse_float("--camera", text.substr(comma + 1), -89.0f, 89.0f);
    camera.angles_given = true;
}

} // namespace

std::array<float, 4> clip_plane(const DisplaySettings& display, const Bounds& scene_box) {
    std::array<float, 4> plane = {0, 0, 0, 1};
    if (!display.clip || scene_box.empty()) return plane;
    const float lo[3] = {scene_box.lo.x, scene_box.lo.y, scene_box.lo.z};
    const float hi[3] = {scene_box.hi.x, scene_box.hi.y, scene_box.hi.z};
    const int a = std::clamp(display.clip_axis, 0, 2);
    const float at = lo[a] + display.clip_position * (hi[a] - lo[a]);
    const float side = display.clip_flip ? 1.0f : -1.0f; // kept: side * (x - at) >= 0
    plane[static_cast<std::size_t>(a)] = side;
    plane[3] = -side * at;
    return plane;
}

const char* controls_help() { return controls; }

std::string view_help() {
    return std::string(help_text) + cli::detector_options_help(front_end_view) + display_help + "\nmouse and keys:\n" +
           wrapped(controls, 100, "  ");
}

ViewConfig parse_view_args(int argc, char** argv, int first) {
    ViewConfig config;
    std::vector<std::string> positionals;
    std::string procedural_flag;
    bool within_given = false;
    cli::CommandLine parser("view");
    parser.positionals(2, positionals);
    parser.flag("--help", config.help);
    bool every = false, marked = false;
    parser.flag("--self", every);
    parser.flag("--self-scene", marked);
    parser.option("--exclusion-rings", "K", [&](const std::string& v) {
        config.exclusion_rings = static_cast<int>(parse_integer("--exclusion-rings", v, 0, max_exclusion_rings));
    });
    parser.flag("--allow-degenerate", config.source.read_options.allow_degenerate);
    parser.detector_options(config.options, front_end_view);
    const auto resolution = [&](const std::string& flag, const std::string& v) {
        config.source.request.resolution = static_cast<int>(parse_integer(flag, v, 1, 4));
        config.resolution_flag = flag;
    };
    parser.option("--res", "N", [&](const std::string& v) { resolution("--res", v); });
    parser.option("-r", "N", [&](const std::string& v) { resolution("-r", v); });
    parser.option("--tets", "N", [&](const std::string& v) {
        config.source.request.procedural.total_tets = static_cast<std::size_t>(parse_integer("--tets", v, 100, 20000000));
        if (procedural_flag.empty()) procedural_flag = "--tets";
    });
    parser.option("--scene-frames", "N", [&](const std::string& v) {
        config.source.request.procedural.frames = static_cast<int>(parse_integer("--scene-frames", v, 1, 100000));
        if (procedural_flag.empty()) procedural_flag = "--scene-frames";
    });
    parser.option("--frame", "N", [&](const std::string& v) {
        config.frame = static_cast<int>(parse_integer("--frame", v, 0, 1000000));
    });
    parser.option("--screenshot", "FILE", [&](const std::string& v) {
        if (v.empty()) throw cli::UsageError("invalid value '' for --screenshot: expected a file name");
        config.screenshot = v;
    });
    parser.option("--points", "FILE", [&](const std::string& v) {
        if (v.empty()) throw cli::UsageError("invalid value '' for --points: expected a file name");
        config.points = v;
    });
    parser.option("--within", "D", [&](const std::string& v) {
        config.within = parse_number("--within", v, 0.0, DBL_MAX, "a finite distance >= 0");
        within_given = true;
    });
    parser.flag("--profile", config.profile);
    parser.option("--size", "WxH", [&](const std::string& v) { parse_size(v, config); });
    parser.flag("--panel", config.panel);
    parser.option("--samples", "N", [&](const std::string& v) {
        config.samples = std::stoi(parse_choice("--samples", v, {"1", "2", "4", "8"}));
    });
    parser.option("--opacity", "A", [&](const std::string& v) {
        config.display.surface_opacity = parse_float("--opacity", v, 0.0f, 1.0f);
    });
    parser.flag("--only-colliding", config.display.only_colliding);
    parser.flag("--wireframe", config.display.wireframe);
    parser.flag("--normals", config.display.contact_normals);
    parser.option("--clip", "AXIS", [&](const std::string& v) {
        const std::string axis = parse_choice("--clip", v, {"x", "y", "z", "-x", "-y", "-z"});
        config.display.clip = true;
        config.display.clip_flip = axis[0] == '-';
        config.display.clip_axis = axis.back() - 'x';
    });
    parser.option("--clip-at", "T", [&](const std::string& v) {
        config.display.clip_position = parse_float("--clip-at", v, 0.0f, 1.0f);
    });
    parser.option("--camera", "YAW,PITCH", [&](const std::string& v) { parse_camera(v, config.camera); });
    parser.option("--zoom", "F", [&](const std::string& v) { config.camera.zoom = parse_float("--zoom", v, 0.01f, 100.0f); });
    parser.option("--focus", "colliding|all", [&](const std::string& v) {
        config.camera.focus_colliding = parse_choice("--focus", v, {"colliding", "all"}) == "colliding";
    });
    parser.parse(argc, argv, first);
    if (config.help) return config;

    if (positionals.size() == 1 && names_a_scene(positionals[0])) {
        config.source.scene = positionals[0];
    } else {
        // One word that names no file (nor a TetGen NAME.node) is more likely a mistyped scene: the
        // registry's message names the known ones, as kdet bench's does.
        std::error_code ignored;
        if (positionals.size() == 1 && !std::filesystem::exists(positionals[0], ignored) &&
            std::filesystem::path(positionals[0]).extension().empty() &&
            !std::filesystem::exists(positionals[0] + ".node", ignored)) {
            try {
                open_scene(positionals[0]);
            } catch (const Error& e) {
                throw cli::UsageError(std::string("view: ") + e.what());
            }
        }
        config.source.meshes = positionals;
    }
    const bool procedural = config.source.meshes.empty() && config.source.scene == "procedural";
    if (!procedural_flag.empty() && !procedural)
        throw cli::UsageError("view: " + procedural_flag + " applies to the procedural scene only");
    if (!config.screenshot.empty() && config.profile)
        throw cli::UsageError("view: --screenshot and --profile are two different runs; give one");
    if (within_given && config.points.empty()) throw cli::UsageError("view: --within applies to --points only");
    if (every && marked) throw cli::UsageError("view: --self and --self-scene are two choices; give one");
    if (marked && !config.source.meshes.empty())
        throw cli::UsageError("view: --self-scene follows a scene's marks, and mesh files have none (use --self)");
    config.self = every ? SceneSelfCollision::every : marked ? SceneSelfCollision::marked : SceneSelfCollision::none;
    if (config.exclusion_rings > 0 && config.self == SceneSelfCollision::none)
        throw cli::UsageError("view: --exclusion-rings acts within an object: it needs --self or --self-scene");
    if (config.panel && config.screenshot.empty()) throw cli::UsageError("view: --panel applies to --screenshot only");
    return config;
}

} // namespace kdet::view
