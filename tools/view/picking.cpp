#include "picking.hpp"

#include "surface.hpp"

#include <algorithm>
#include <limits>

namespace kdet::view {

namespace {

/// @brief Distance along the ray to triangle (a, b, c), both sides, or nothing.
std::optional<float> hit_triangle(Vec3 origin, Vec3 direction, Vec3 a, Vec3 b, Vec3 c) {
    const Vec3 e1 = b - a, e2 = c - a;
    const Vec3 p = cross(direction, e2);
    const float det = dot(e1, p);
    if (std::abs(det) < 1e-12f) return std::nullopt;
    const float inv = 1.0f / det;
    const Vec3 s = origin - a;
    const float u = dot(s, p) * inv;
    if (u < 0.0f || u > 1.0f) return std::nullopt;
    const Vec3 q = cross(s, e1);
    const float v = dot(direction, q) * inv;
    if (v < 0.0f || u + v > 1.0f) return std::nullopt;
    const float t = dot(e2, q) * inv;
    if (t <= 0.0f) return std::nullopt;
    return t;
}

struct Hit {
    float distance = std::numeric_limits<float>::infinity();
    TetRef tet;
    bool found() const { return distance < std::numeric_limits<float>::infinity(); }
};

class RayCaster {
public:
    RayCaster(const ViewSession& session, std::array<Vec3, 2> ray, const DisplaySettings& display, const Bounds& box)
        : session_(session), origin_(ray[0]), direction_(ray[1]), plane_(clip_plane(display, box)) {}

    /// @brief Keeps the nearest kept hit of triangle (a, b, c) of object @p o's positions.
    void triangle(std::uint32_t o, std::uint32_t tet, const std::uint32_t* v, Hit& best) const {
        const std::vector<float>& p = session_.positions()[o];
        const auto at = [&](std::uint32_t i) { return Vec3{p[3 * i], p[3 * i + 1], p[3 * i + 2]}; };
        const std::optional<float> t = hit_triangle(origin_, direction_, at(v[0]), at(v[1]), at(v[2]));
        if (!t || *t >= best.distance) return;
        const Vec3 q = origin_ + direction_ * *t;
        if (plane_[0] * q.x + plane_[1] * q.y + plane_[2] * q.z + plane_[3] < 0.0f) return;
        best.distance = *t;
        best.tet = TetRef{o, tet};
    }

private:
    const ViewSession& session_;
    Vec3 origin_, direction_;
    std::array<float, 4> plane_;
};

} // namespace

std::optional<TetRef> pick_tet(const ViewSession& session, const OrbitCamera& camera, float x, float y, int width,
                               int height, const DisplaySettings& display, const Bounds& scene_box) {
    const RayCaster cast(session, camera.ray(x, y, width, height), display, scene_box);
    const Scene& scene = session.scene();
    Hit colliding, surface;
    for (const TetRef& ref : colliding_tets(session)) {
        const std::uint32_t* v = &session.mesh(ref.object).tets[4 * static_cast<std::size_t>(ref.tet)];
        for (const auto& corners : tet_face_vertices) {
            const std::uint32_t face[3] = {v[corners[0]], v[corners[1]], v[corners[2]]};
            cast.triangle(ref.object, ref.tet, face, colliding);
        }
    }
    if (!display.only_colliding) {
        for (std::uint32_t o = 0; o < scene.num_objects(); ++o) {
            const MeshFaces& faces = session.faces()[o];
            for (std::size_t k = 0; k < faces.boundary_tet.size(); ++k)
                cast.triangle(o, faces.boundary_tet[k], &faces.boundary[3 * k], surface);
        }
    }
    // Translucent surfaces let colliding tets show through; opaque ones hide what lies behind them.
    const bool see_through = display.only_colliding || display.surface_opacity < 1.0f;
    if (colliding.found() && (see_through || colliding.distance <= surface.distance)) return colliding.tet;
    if (surface.found()) return surface.tet;
    return std::nullopt;
}

std::optional<std::size_t> pick_point(const ViewSession& session, const OrbitCamera& camera, float x, float y, int width,
                                      int height, float radius) {
    const std::vector<double>& xyz = session.points();
    std::optional<std::size_t> best;
    float best_d2 = radius * radius;
    for (std::size_t p = 0; 3 * p < xyz.size(); ++p) {
        const Vec3 at{static_cast<float>(xyz[3 * p]), static_cast<float>(xyz[3 * p + 1]), static_cast<float>(xyz[3 * p + 2])};
        const auto pixel = camera.project(at, width, height);
        if (!pixel) continue;
        const float dx = (*pixel)[0] - x, dy = (*pixel)[1] - y, d2 = dx * dx + dy * dy;
        if (d2 < best_d2 || (!best && d2 <= best_d2)) {
            best_d2 = d2;
            best = p;
        }
    }
    return best;
}

std::vector<float> vertices_of(const ViewSession& session, const std::vector<TetRef>& tets) {
    std::vector<float> points;
    points.reserve(12 * tets.size());
    for (const TetRef& t : tets) {
        const std::uint32_t* v = &session.mesh(t.object).tets[4 * static_cast<std::size_t>(t.tet)];
        const std::vector<float>& p = session.positions()[t.object];
        for (int k = 0; k < 4; ++k) points.insert(points.end(), {p[3 * v[k]], p[3 * v[k] + 1], p[3 * v[k] + 2]});
    }
    return points;
}

std::vector<TetRef> colliding_tets(const ViewSession& session) {
    std::vector<TetRef> tets;
    const FrameResult& result = session.result();
    for (std::uint32_t o = 0; o < result.colliding.size(); ++o)
        for (std::uint32_t t = 0; t < result.colliding[o].size(); ++t)
            if (result.colliding[o][t]) tets.push_back(TetRef{o, t});
    return tets;
}

std::vector<Partner> partners_of(const FrameResult& result, const TetRef& selected) {
    std::vector<Partner> partners;
    for (std::size_t k = 0; k < result.pairs.size(); ++k) {
        const TetPair& p = result.pairs[k];
        Partner partner;
        if (p.object_a == selected.object && p.tet_a == selected.tet) {
            partner.tet = TetRef{p.object_b, p.tet_b};
        } else if (p.object_b == selected.object && p.tet_b == selected.tet) {
            partner.tet = TetRef{p.object_a, p.tet_a};
        } else {
            continue;
        }
        if (k < result.contacts.size()) {
            partner.has_contact = true;
            partner.contact = result.contacts[k];
        }
        partners.push_back(partner);
    }
    return partners;
}

} // namespace kdet::view
