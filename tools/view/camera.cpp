#include "camera.hpp"

#include <algorithm>
#include <cmath>

namespace kdet::view {

namespace {

constexpr float pi = 3.14159265358979f;

float radians(float degrees) { return degrees * pi / 180.0f; }

} // namespace

float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

float length(Vec3 a) { return std::sqrt(dot(a, a)); }

Vec3 normalize(Vec3 a) {
    const float l = length(a);
    return l > 0 ? a * (1.0f / l) : a;
}

Mat4 Mat4::identity() {
    Mat4 i;
    i.m[0] = i.m[5] = i.m[10] = i.m[15] = 1.0f;
    return i;
}

Mat4 operator*(const Mat4& a, const Mat4& b) {
    Mat4 out;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
            float sum = 0;
            for (int k = 0; k < 4; ++k) sum += a.m[k * 4 + r] * b.m[c * 4 + k];
            out.m[c * 4 + r] = sum;
        }
    return out;
}

std::array<float, 4> Mat4::apply(Vec3 p) const {
    std::array<float, 4> out{};
    for (int r = 0; r < 4; ++r) out[r] = m[r] * p.x + m[4 + r] * p.y + m[8 + r] * p.z + m[12 + r];
    return out;
}

void Bounds::add(Vec3 p) {
    if (empty()) {
        lo = hi = p;
        return;
    }
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
}

void Bounds::add(const std::vector<float>& xyz) {
    for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) add(Vec3{xyz[i], xyz[i + 1], xyz[i + 2]});
}

Vec3 Bounds::center() const { return empty() ? Vec3{} : (lo + hi) * 0.5f; }

float Bounds::radius() const { return empty() ? 0.0f : 0.5f * length(hi - lo); }

void OrbitCamera::frame(const std::vector<std::vector<float>>& point_sets, float aspect) {
    Bounds box;
    for (const std::vector<float>& xyz : point_sets) box.add(xyz);
    if (box.empty()) return;
    target_ = box.center();
    scene_center_ = target_;
    // A flat or single-point box still gets a visible extent.
    scene_radius_ = std::max(box.radius(), 1e-3f * std::max({std::abs(target_.x), std::abs(target_.y),
                                                             std::abs(target_.z), 1.0f}));
    // The closest distance at which every point lies inside 90% of the view: a point at (x, y)
    // across and z towards the camera needs distance >= z + |x| / tan(half width).
    const float tan_y = 0.9f * std::tan(radians(fov_y_degrees) * 0.5f);
    const float tan_x = tan_y * std::max(aspect, 1e-3f);
    const auto [forward, right, up] = basis();
    float distance = 1e-3f * scene_radius_;
    for (const std::vector<float>& xyz : point_sets)
        for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) {
            const Vec3 offset = Vec3{xyz[i], xyz[i + 1], xyz[i + 2]} - target_;
            const float towards = -dot(offset, forward);
            distance = std::max({distance, towards + std::abs(dot(offset, right)) / tan_x,
                                 towards + std::abs(dot(offset, up)) / tan_y});
        }
    distance_ = distance;
}

void OrbitCamera::set_angles(float yaw_degrees, float pitch_degrees) {
    yaw_ = std::fmod(yaw_degrees, 360.0f);
    pitch_ = std::clamp(pitch_degrees, -89.0f, 89.0f);
}

void OrbitCamera::zoom(float factor) {
    distance_ = std::clamp(distance_ * factor, 1e-4f * scene_radius_, 1e3f * scene_radius_);
}

void OrbitCamera::orbit(float dx_pixels, float dy_pixels, int viewport_height) {
    const float degrees_per_pixel = 180.0f / static_cast<float>(std::max(viewport_height, 1));
    set_angles(yaw_ - dx_pixels * degrees_per_pixel, pitch_ + dy_pixels * degrees_per_pixel);
}

void OrbitCamera::pan(float dx_pixels, float dy_pixels, int viewport_height) {
    // World units per pixel at the target's depth.
    const float scale = 2.0f * distance_ * std::tan(radians(fov_y_degrees) * 0.5f) /
                        static_cast<float>(std::max(viewport_height, 1));
    const auto [forward, right, up] = basis();
    target_ = target_ - right * (dx_pixels * scale) + up * (dy_pixels * scale);
}

std::array<Vec3, 3> OrbitCamera::basis() const {
    const Vec3 forward = normalize(target_ - eye());
    const Vec3 right = normalize(cross(forward, Vec3{0, 1, 0}));
    return {forward, right, cross(right, forward)};
}

Vec3 OrbitCamera::eye() const {
    const float yaw = radians(yaw_), pitch = radians(pitch_);
    const Vec3 direction{std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw)};
    return target_ + direction * distance_;
}

Mat4 OrbitCamera::view() const {
    const Vec3 from = eye();
    const auto [forward, right, up] = basis();
    Mat4 v = Mat4::identity();
    const Vec3 rows[3] = {right, up, forward * -1.0f};
    for (int r = 0; r < 3; ++r) {
        v.m[0 * 4 + r] = rows[r].x;
        v.m[1 * 4 + r] = rows[r].y;
        v.m[2 * 4 + r] = rows[r].z;
        v.m[3 * 4 + r] = -dot(rows[r], from);
    }
    return v;
}

Mat4 OrbitCamera::projection(float aspect) const {
    // The clipping planes hug the scene's bounding sphere wherever the camera is.
    const float to_scene = length(scene_center_ - eye());
    const float far_plane = to_scene + 2.0f * scene_radius_;
    const float near_plane = std::max(to_scene - 2.0f * scene_radius_, 1e-3f * far_plane);
    const float f = 1.0f / std::tan(radians(fov_y_degrees) * 0.5f);
    Mat4 p;
    p.m[0] = f / std::max(aspect, 1e-6f);
    p.m[5] = f;
    p.m[10] = (far_plane + near_plane) / (near_plane - far_plane);
    p.m[11] = -1.0f;
    p.m[14] = 2.0f * far_plane * near_plane / (near_plane - far_plane);
    return p;
}

std::array<Vec3, 2> OrbitCamera::ray(float x, float y, int width, int height) const {
    const float tan_y = std::tan(radians(fov_y_degrees) * 0.5f);
    const float aspect = static_cast<float>(width) / static_cast<float>(std::max(height, 1));
    const float ndc_x = 2.0f * x / static_cast<float>(std::max(width, 1)) - 1.0f;
    const float ndc_y = 1.0f - 2.0f * y / static_cast<float>(std::max(height, 1));
    const Vec3 from = eye();
    const auto [forward, right, up] = basis();
    return {from, normalize(forward + right * (ndc_x * tan_y * aspect) + up * (ndc_y * tan_y))};
}

std::optional<std::array<float, 2>> OrbitCamera::project(Vec3 p, int width, int height) const {
    const Mat4 clip = projection(static_cast<float>(width) / static_cast<float>(std::max(height, 1))) * view();
    const std::array<float, 4> c = clip.apply(p);
    if (c[3] <= 0) return std::nullopt;
    const float x = c[0] / c[3], y = c[1] / c[3];
    return std::array<float, 2>{(x + 1.0f) * 0.5f * static_cast<float>(width),
                                (1.0f - y) * 0.5f * static_cast<float>(height)};
}

} // namespace kdet::view
