#pragma once
/// @file renderer.hpp
/// @brief Draws a ViewSession with OpenGL 3.3 core: boundary surfaces, colliding tets (those within
/// the margin only in a colour of their own), wireframe, clipping plane and contact normals. It only reads the session's positions and results.

#include "camera.hpp"
#include "picking.hpp"
#include "session.hpp"
#include "view_args.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace kdet::view {

/// @brief RGB colour, components 0 to 1.
struct Color {
    float r, g, b;
};

/// @brief The surface colour of object @p object (a palette of cool colours that repeats).
Color object_color(std::size_t object);
/// @brief The colour of colliding tets: the only red in the picture.
Color highlight_color();
/// @brief With a margin, the colour of the tets within it only (ViewSession::margin_tets).
Color margin_color();

/// @brief Query points: held by a tet, given the nearest tet within the distance, or without a tet.
Color point_color(int status);
/// @brief The tets that hold query points.
Color located_color();
/// @brief The contact normals' lines: pink, apart from the red and yellow tets they lie over.
Color normal_color();
/// @brief The tet picked with a click: white.
Color selected_color();
/// @brief The tets the picked one collides with: teal.
Color partner_color();

/// @brief At most this many contact normals are drawn (an even sample of the colliding pairs).
constexpr std::size_t max_contact_lines = 1500;

/// @brief Counts that show how the renderer uses its buffers.
struct BufferStats {
    std::size_t allocations = 0;      ///< glBufferData calls: buffers made or grown
    std::size_t position_uploads = 0; ///< in-place glBufferSubData updates of vertex positions
    std::size_t live_buffers = 0;
    std::size_t bytes = 0;            ///< bytes held by live buffers
};

/// @brief The OpenGL side of the viewer. Needs a current OpenGL 3.3 core context for its whole life.
class Renderer {
public:
    Renderer();
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    /// @brief Uploads what changed in @p session since the last call: a new scene makes new
    /// buffers (sized once for its meshes), new positions are written into the vertex buffers in
    /// place, new results refill the index buffer of the colliding tets (grown only when too small).
    void update(const ViewSession& session);

    /// @brief Draws into the bound framebuffer, inside the viewport (x, y, width, height) in pixels
    /// from the lower left. `scene_box` places the clipping plane.
    void draw(const OrbitCamera& camera, int x, int y, int width, int height, const DisplaySettings& display,
              const Bounds& scene_box) const;

    /// @brief Shows @p tets (the selected tet first, then its partners) over everything else, at the
    /// session's current positions; an empty list clears the selection.
    void select(const ViewSession& session, const std::vector<TetRef>& tets);
    /// @brief Shows only query point @p point and its tets (those that hold it, or its nearest within
    /// the distance) in the located colour; nothing: every point and the tets of those a tet holds.
    void select_point(const ViewSession& session, std::optional<std::size_t> point);

    const BufferStats& stats() const { return stats_; }
    /// @brief Boundary triangles of @p object the surface buffers hold: those of the session's
    /// mesh(object) as of the last update().
    std::size_t surface_triangles(std::size_t object) const { return objects_.at(object).surface_count / 3; }
    /// @brief Contact normals the last update() prepared (0 without contacts).
    std::size_t contact_lines() const { return contacts_.vertices / 2; }
    /// @brief Query points the last update() prepared, per status of point_status().
    const std::array<std::size_t, 3>& point_counts() const { return point_counts_; }

private:
    /// @brief The surface of a region of flagged tets: indices into the object's vertex buffer.
    struct Region {
        unsigned array = 0, indices = 0;
        std::size_t count = 0; ///< indices drawn
        std::size_t capacity = 0;
    };

    struct ObjectBuffers {
        unsigned positions = 0;       ///< vertex buffer, x y z float per vertex
        unsigned surface_array = 0, surface_indices = 0;
        std::size_t surface_count = 0;   ///< indices drawn
        std::size_t surface_capacity = 0;
        Region highlight; ///< the colliding tets
        Region margin;    ///< the tets within the margin only
        Region located;   ///< the tets that hold query points
        std::size_t vertex_bytes = 0;
    };

    /// @brief Vertices drawn without indices: position and offset (6 floats) each.
    struct Stream {
        unsigned array = 0, buffer = 0;
        std::size_t capacity = 0; ///< floats
        std::size_t vertices = 0;
    };

    unsigned make_buffer(unsigned target, std::size_t bytes, const void* data, unsigned usage);
    /// @brief Writes @p vertices into the stream's buffer, which grows geometrically when too small.
    void upload_stream(Stream& stream, const std::vector<float>& vertices);
    void release_buffer(unsigned& buffer, std::size_t bytes);
    void release_scene();
    void load_scene(const ViewSession& session);
    /// @brief Refills the surface index buffers after the session's tets changed.
    void upload_surfaces(const ViewSession& session);
    void upload_highlights(const ViewSession& session);
    /// @brief Refills @p region from @p flags (one per tet; empty flags clear it).
    void upload_region(const ViewSession& session, std::size_t object, Region& region, const std::vector<std::uint8_t>& flags);
    /// @brief Refills the points' stream and each object's located region, for selected_point_ alone
    /// when there is one.
    void upload_points(const ViewSession& session);
    void upload_contacts(const ViewSession& session);
    void draw_objects(bool surfaces, Region ObjectBuffers::*region) const;

    unsigned mesh_program_ = 0, background_program_ = 0, empty_array_ = 0;
    Stream contacts_, selection_, points_;
    std::array<std::size_t, 3> point_counts_{}; ///< points_ holds the missed, then the near, then the held
    std::optional<std::size_t> selected_point_;
    std::vector<ObjectBuffers> objects_;
    std::uint64_t scene_version_ = 0, positions_version_ = 0, result_version_ = 0, topology_version_ = 0;
    float scene_radius_ = 1.0f;
    std::vector<std::uint32_t> scratch_indices_;
    std::vector<float> scratch_vertices_;
    BufferStats stats_;
};

/// @brief A framebuffer of its own, with multisampling, for pictures without a window.
class OffscreenTarget {
public:
    /// @brief Throws kdet::Error when the driver cannot make it.
    OffscreenTarget(int width, int height, int samples);
    ~OffscreenTarget();
    OffscreenTarget(const OffscreenTarget&) = delete;
    OffscreenTarget& operator=(const OffscreenTarget&) = delete;

    /// @brief Binds it for drawing; the viewport covers it.
    void bind() const;
    /// @brief The picture as RGB bytes, rows from the top.
    std::vector<std::uint8_t> read_rgb() const;
    int width() const { return width_; }
    int height() const { return height_; }

private:
    int width_, height_, samples_;
    unsigned draw_framebuffer_ = 0, resolve_framebuffer_ = 0;
    unsigned color_ = 0, depth_ = 0, resolved_color_ = 0;
};

/// @brief The bound framebuffer's pixels in (x, y, width, height) as RGB rows from the top.
std::vector<std::uint8_t> read_framebuffer_rgb(int x, int y, int width, int height);

} // namespace kdet::view
