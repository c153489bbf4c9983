#pragma once
/// @file camera.hpp
/// @brief The viewer's orbit camera and the little vector algebra it needs. No OpenGL here: the
/// tests project points with exactly the matrices the renderer draws with.

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

namespace kdet::view {

struct Vec3 {
    float x = 0, y = 0, z = 0;
    friend Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
    friend Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
    friend Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
};

float dot(Vec3 a, Vec3 b);
Vec3 cross(Vec3 a, Vec3 b);
float length(Vec3 a);
Vec3 normalize(Vec3 a);

/// @brief A 4x4 matrix in OpenGL's column-major order: element (row r, column c) is m[c * 4 + r].
struct Mat4 {
    std::array<float, 16> m{};
    static Mat4 identity();
    friend Mat4 operator*(const Mat4& a, const Mat4& b);
    /// @brief The point p (w = 1) transformed, as x y z w.
    std::array<float, 4> apply(Vec3 p) const;
};

/// @brief An axis-aligned box that grows to hold points; empty until the first point.
struct Bounds {
    Vec3 lo{1, 1, 1}, hi{-1, -1, -1};
    bool empty() const { return lo.x > hi.x; }
    void add(Vec3 p);
    /// @brief Adds every point of an x y z array.
    void add(const std::vector<float>& xyz);
    Vec3 center() const;
    float radius() const; ///< half the diagonal; 0 for an empty box
};

/// @brief A camera that orbits a target point: yaw about the world's y axis, pitch above the
/// horizon, at a distance, with a perspective lens. Screen pixels have their origin top-left.
class OrbitCamera {
public:
    static constexpr float default_yaw = 35.0f;
    static constexpr float default_pitch = 25.0f;
    static constexpr float fov_y_degrees = 40.0f;

    /// @brief Looks from the current direction at the centre of the box around @p point_sets (each
    /// x y z per point), as close as the points allow: they all lie inside the middle 90% of a view
    /// of aspect ratio @p aspect (width / height). No points leave the camera unchanged.
    void frame(const std::vector<std::vector<float>>& point_sets, float aspect);
    void set_angles(float yaw_degrees, float pitch_degrees);
    /// @brief Moves the camera along its view direction: distance *= factor.
    void zoom(float factor);
    /// @brief Orbits by screen-space drags in pixels (a full viewport height turns 180 degrees).
    void orbit(float dx_pixels, float dy_pixels, int viewport_height);
    /// @brief Moves the target with the picture, so that a point at the target follows the cursor.
    void pan(float dx_pixels, float dy_pixels, int viewport_height);

    Vec3 eye() const;
    Vec3 target() const { return target_; }
    float yaw() const { return yaw_; }
    float pitch() const { return pitch_; }
    float distance() const { return distance_; }
    Mat4 view() const;
    Mat4 projection(float aspect) const;

    /// @brief The ray from the eye through pixel (x, y) (origin top-left) of a width x height view:
    /// origin and unit direction.
    std::array<Vec3, 2> ray(float x, float y, int width, int height) const;

    /// @brief Pixel coordinates (x right, y down, in [0, width] x [0, height] when visible) of a
    /// point, or nothing when it lies behind the camera.
    std::optional<std::array<float, 2>> project(Vec3 p, int width, int height) const;

private:
    /// @brief Unit vectors along the view, to the right and up on screen.
    std::array<Vec3, 3> basis() const;

    Vec3 target_{0, 0, 0};
    Vec3 scene_center_{0, 0, 0}; ///< with scene_radius_, sets the clipping planes
    float yaw_ = default_yaw, pitch_ = default_pitch;
    float distance_ = 3.0f;
    float scene_radius_ = 1.0f;
};

} // namespace kdet::view
