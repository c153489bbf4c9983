#pragma once
/// @file view_args.hpp
/// @brief The command line of `kdet view`.

#include "camera.hpp"
#include "session.hpp"

#include <kdet/options.hpp>

#include <string>

namespace kdet::view {

/// @brief How the scene is drawn; the panel changes these while the viewer runs.
struct DisplaySettings {
    float surface_opacity = 0.35f; ///< 1 draws opaque surfaces; below 1 colliding tets show through
    bool only_colliding = false;   ///< hide the surfaces, draw the colliding tets only
    bool wireframe = false;
    bool contact_normals = false;  ///< turns the detector's contacts on (wants_contacts), any test
    float normal_length = 1.0f;    ///< scale of the contact normals (1: 5% of the scene's radius)
    bool clip = false;
    int clip_axis = 0;             ///< 0 x, 1 y, 2 z
    bool clip_flip = false;        ///< keep the upper side of the plane instead of the lower
    float clip_position = 0.5f;    ///< across the scene's box along the axis, 0 to 1
};

/// @brief The clipping plane across @p scene_box as (a, b, c, d): a point is kept when
/// a x + b y + c z + d >= 0. Keeps everything when the plane is off.
std::array<float, 4> clip_plane(const DisplaySettings& display, const Bounds& scene_box);

/// @brief Where the camera starts.
struct CameraRequest {
    bool angles_given = false;
    float yaw = 0, pitch = 0;      ///< degrees, when angles_given
    float zoom = 1.0f;             ///< distance as a multiple of the framing distance
    bool focus_colliding = false;  ///< frame the colliding tets (as the F key) rather than everything
};

/// @brief Everything `kdet view` was asked to do.
struct ViewConfig {
    ViewSource source;
    DetectorOptions options;
    SceneSelfCollision self = SceneSelfCollision::none; ///< --self, --self-scene
    int exclusion_rings = 0;       ///< with self: Detector::set_self_exclusion_rings of every object
    std::string resolution_flag;   ///< --res or -r when given (checked against the scene once open)
    int frame = 0;                 ///< 0-based frame to show first (checked when the scene is open)
    std::string screenshot;        ///< headless: draw frame `frame` into this PNG and exit
    bool profile = false;          ///< headless: draw every frame once and print the times
    int width = 1280, height = 800;
    bool panel = false;            ///< draw the side panel into the screenshot too
    int samples = 4;               ///< multisampling per pixel (1 turns it off)
    std::string points;            ///< query points file (read_points), located after each detection
    double within = 0;             ///< LocateOptions::within for the points
    DisplaySettings display;
    CameraRequest camera;
    bool help = false;
};

/// @brief Parses `argv[first..argc)`; throws cli::UsageError naming the flag and what it accepts.
ViewConfig parse_view_args(int argc, char** argv, int first);

/// @brief What the mouse and the keys do, in one paragraph (the panel shows it too).
const char* controls_help();

/// @brief The text of `kdet view --help`.
std::string view_help();

} // namespace kdet::view
