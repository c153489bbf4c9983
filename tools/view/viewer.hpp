#pragma once
/// @file viewer.hpp
/// @brief The viewer's window: GLFW for the window and input, Dear ImGui for the panel, the
/// Renderer for the scene; the interactive loop and the headless runs (screenshot, profile).

#include "bench_job.hpp"
#include "camera.hpp"
#include "renderer.hpp"
#include "session.hpp"
#include "view_args.hpp"

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

struct GLFWwindow;

namespace kdet::view {

/// @brief Whether the detector computes contacts (DetectorOptions::contacts): while the viewer shows
/// them, as normals or as the selected tet's depths, under any narrow-phase test; off otherwise, since
/// they cost a 44-axis SAT per colliding pair.
bool wants_contacts(const DisplaySettings& display, bool tet_selected);

/// @brief One window (visible, or hidden for headless runs) with its OpenGL context and ImGui.
class Viewer {
public:
    /// @brief Opens the window; throws kdet::Error when no window or OpenGL 3.3 context can be made.
    Viewer(ViewSession& session, const ViewConfig& config, bool visible);
    ~Viewer();
    Viewer(const Viewer&) = delete;
    Viewer& operator=(const Viewer&) = delete;

    /// @brief The interactive loop, until the window closes.
    void run();
    /// @brief Draws the current frame off-screen (with the panel if asked) into a PNG.
    void screenshot(const std::string& path, int width, int height, bool with_panel);
    /// @brief Draws every frame of the scene once off-screen, timing detection and drawing; prints
    /// one line per frame and the medians to stdout.
    void profile(int width, int height);

    /// @brief The camera as the viewer set it up for a picture of this size (for tests and scripts).
    const OrbitCamera& camera() const { return camera_; }

private:
    struct History {
        static constexpr int size = 240;
        std::vector<float> detect_ms = std::vector<float>(size, 0.0f), draw_ms = std::vector<float>(size, 0.0f);
        int next = 0, count = 0;
        void add(float detect, float draw);
    };

    /// @brief Width / height of the window's part that shows the scene.
    float scene_aspect() const;
    void reset_camera(float aspect);
    void frame_colliding(float aspect);
    /// @brief GLFW's key callback: keeps the keys meant for the viewer until the next frame, so that
    /// a press and release between two frames still counts.
    static void on_key(GLFWwindow* window, int key, int scancode, int action, int mods);
    void handle_key(int key);
    void handle_input(int scene_height);
    void apply(const DetectorOptions& options);
    /// @brief Turns the detector's contacts on or off as wants_contacts() says (a new detector when
    /// that changes).
    void sync_contacts();
    void open_source(const ViewSource& source);
    void draw_panel(float width, float height);
    void panel_scene();
    void panel_playback();
    void panel_detection();
    void panel_display();
    void panel_results();
    void panel_benchmark();
    void panel_selection();
    /// @brief Picks the tet under the cursor after a click (a press and release without a drag).
    void handle_click(int scene_x, int scene_width, int scene_height);
    void save_window_screenshot(int width, int height);
    void set_status(const std::string& text);
    /// @brief Runs ImGui for one frame of the given size, with the panel when it is shown.
    void build_ui(int width, int height, bool with_panel);

    ViewSession& session_;
    ViewConfig config_;
    GLFWwindow* window_ = nullptr;
    std::unique_ptr<Renderer> renderer_;
    OrbitCamera camera_;
    Bounds scene_box_;            ///< the box the camera and the clipping plane were set up with
    bool panel_shown_ = true;
    bool playing_ = false, loop_ = true;
    bool screenshot_requested_ = false;
    std::vector<int> pending_keys_;
    std::optional<TetRef> selected_;
    std::optional<std::size_t> selected_point_; ///< a query point clicked: only its tets are shown located
    std::vector<Partner> partners_;      ///< of the selected tet, in the shown frame
    std::uint64_t selection_version_ = 0; ///< the session's result version partners_ belong to
    std::uint64_t selection_topology_ = 0; ///< the session's topology version when the tet was picked
    int bench_runs_ = 3;
    std::string bench_dir_ = "exports/benchmark_data";
    std::unique_ptr<BenchJob> bench_job_;
    std::string bench_outcome_;
    std::string open_path_;
    std::string status_;
    std::chrono::steady_clock::time_point status_time_{};
    History history_;
    float last_draw_ms_ = 0;      ///< the scene's drawing in the last frame, until the driver finished
    bool draw_measured_ = false;
};

} // namespace kdet::view
