#pragma once
/// @file picking.hpp
/// @brief Which tet is under the cursor, and what the detector reports about it. No OpenGL: it
/// casts the camera's ray against the same triangles the renderer draws.

#include "camera.hpp"
#include "session.hpp"
#include "view_args.hpp"

#include <cstdint>
#include <optional>
#include <vector>

namespace kdet::view {

/// @brief One tet of one object.
struct TetRef {
    std::uint32_t object = 0, tet = 0;
    friend bool operator==(const TetRef& a, const TetRef& b) { return a.object == b.object && a.tet == b.tet; }
};

/// @brief The tet seen at pixel (x, y) (origin top-left) of a width x height view, as drawn with
/// @p display: a colliding tet when one is there (they are drawn over translucent surfaces; behind
/// opaque ones only when nearer), else the tet of the surface triangle hit. Parts the clipping plane
/// removes cannot be picked. Nothing when the ray meets no tet.
std::optional<TetRef> pick_tet(const ViewSession& session, const OrbitCamera& camera, float x, float y, int width,
                               int height, const DisplaySettings& display, const Bounds& scene_box);

/// @brief The query point (ViewSession::points) drawn nearest pixel (x, y) of a width x height view,
/// within @p radius pixels (the first on a tie); nothing when none is that close.
std::optional<std::size_t> pick_point(const ViewSession& session, const OrbitCamera& camera, float x, float y, int width,
                                      int height, float radius);

/// @brief The four vertices of each of @p tets at the session's positions, x y z each.
std::vector<float> vertices_of(const ViewSession& session, const std::vector<TetRef>& tets);

/// @brief Every tet the last detection flagged as colliding.
std::vector<TetRef> colliding_tets(const ViewSession& session);

/// @brief A tet that collides with the selected one, with the contact when the test gives one.
struct Partner {
    TetRef tet;
    bool has_contact = false;
    Contact contact{};
};

/// @brief Every tet the last detection pairs with @p selected (empty for kdet_no_pairs, which builds
/// no pairs).
std::vector<Partner> partners_of(const FrameResult& result, const TetRef& selected);

} // namespace kdet::view
