/// @file scripted_scene.cpp
/// @brief ScriptedScene: keyframed rigid motion plus smooth deformations of every object.

#include "scenes/scripted_scene.hpp"

#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/prepare.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

namespace kdet::scenes {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;

using Vec = std::array<double, 3>;
using Matrix = std::array<Vec, 3>;  // rows

/// @brief Rotation by @p degrees about x, then y, then z.
Matrix rotation(const Vec& degrees) {
    const double cx = std::cos(degrees[0] * kDegree), sx = std::sin(degrees[0] * kDegree);
    const double cy = std::cos(degrees[1] * kDegree), sy = std::sin(degrees[1] * kDegree);
    const double cz = std::cos(degrees[2] * kDegree), sz = std::sin(degrees[2] * kDegree);
    // Rz * Ry * Rx
    return {Vec{cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx},
            Vec{sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx}, Vec{-sy, cy * sx, cy * cx}};
}

Matrix multiply(const Matrix& a, const Matrix& b) {
    Matrix m{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) m[i][j] += a[i][k] * b[k][j];
    return m;
}

/// @brief Everything about one object at one frame that does not depend on the vertex.
struct Pose {
    Matrix rotation{};
    Vec translation{};
    double bend = 0.0, twist = 0.0, squash = 0.0, wobble_phase = 0.0;
};

double channel(const ObjectSpec& object, Channel c, double frame) {
    return evaluate(object.keys[static_cast<std::size_t>(c)], frame)[0];
}

} // namespace

ScriptedScene::ScriptedScene(SceneSpec spec, int resolution, const std::string& base_dir, bool user_file)
    : spec_(std::move(spec)) {
    bool follows_request = false;
    for (const ObjectSpec& object : spec_.objects) {
        try {
            if (!object.model.empty()) {
                const int used = object.resolution != 0 ? object.resolution : resolution;
                follows_request = follows_request || object.resolution == 0;
                if (resolution_ == 0) resolution_ = used;
                meshes_.push_back(prepared_mesh(object.model, used));
            } else {
                const std::filesystem::path path = std::filesystem::path(base_dir) / object.file;
                meshes_.push_back(read_tet_mesh(path.string()));
            }
        } catch (const Error& e) {
            if (!user_file) throw;
            throw Error(spec_.source + ":" + std::to_string(object.mesh_line) + ": object '" + object.name + "': " + e.what());
        }
        const TetMesh& mesh = meshes_.back();
        Vec lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
        for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
            lo[i % 3] = std::min(lo[i % 3], mesh.positions[i]);
            hi[i % 3] = std::max(hi[i % 3], mesh.positions[i]);
        }
        RestFrame rest;
        for (int a = 0; a < 3; ++a) {
            rest.centre[a] = 0.5 * (lo[a] + hi[a]);
            rest.half[a] = 0.5 * (hi[a] - lo[a]);
        }
        rest_.push_back(rest);
    }
    if (follows_request) resolution_ = resolution;
}

std::string ScriptedScene::name() const { return spec_.name; }

std::size_t ScriptedScene::num_objects() const { return spec_.objects.size(); }

int ScriptedScene::num_frames() const { return spec_.frames; }

const TetMesh& ScriptedScene::rest_mesh(std::size_t object) const {
    if (object >= meshes_.size())
        throw Error("scene " + spec_.name + " has no object " + std::to_string(object) + " (it has " +
                    std::to_string(meshes_.size()) + ")");
    return meshes_[object];
}

bool ScriptedScene::checks_pair(std::size_t a, std::size_t b) const {
    if (a == b) return false;
    if (!spec_.pairs_given) return true;
    const std::pair<std::size_t, std::size_t> pair(std::min(a, b), std::max(a, b));
    return std::find(spec_.pairs.begin(), spec_.pairs.end(), pair) != spec_.pairs.end();
}

bool ScriptedScene::is_static(std::size_t object) const { return object < spec_.objects.size() && spec_.objects[object].is_static; }

bool ScriptedScene::checks_self(std::size_t object) const {
    return std::find(spec_.self.begin(), spec_.self.end(), object) != spec_.self.end();
}

template <typename Real>
void ScriptedScene::write_positions(std::size_t object, int frame, std::vector<Real>& out) const {
    const TetMesh& mesh = rest_mesh(object);
    if (frame < 0 || frame >= spec_.frames)
        throw Error("scene " + spec_.name + " has no frame " + std::to_string(frame) + " (it has " +
                    std::to_string(spec_.frames) + ")");
    const ObjectSpec& o = spec_.objects[object];
    const RestFrame& rest = rest_[object];
    const double f = frame;

    Pose pose;
    pose.rotation = multiply(rotation(evaluate(o.keys[static_cast<std::size_t>(Channel::turn)], f)), rotation(o.rotate));
    const Vec move = evaluate(o.keys[static_cast<std::size_t>(Channel::move)], f);
    for (int a = 0; a < 3; ++a) pose.translation[a] = o.translate[a] + move[a];
    pose.bend = channel(o, Channel::bend, f);
    pose.twist = channel(o, Channel::twist, f) * kDegree;
    pose.squash = channel(o, Channel::squash, f);
    pose.wobble_phase = o.wobble_period > 0 ? 2 * kPi * f / o.wobble_period : 0.0;
    const double size = 2 * std::max({rest.half[0], rest.half[1], rest.half[2]});
    const double wobble = o.wobble_amplitude * size;
    // Squashing scales one axis and widens the other two so that the volume stays the same.
    const double squash_along = 1.0 - pose.squash, squash_across = 1.0 / std::sqrt(squash_along);

    out.resize(mesh.positions.size());
    const auto num_vertices = static_cast<long long>(mesh.num_vertices());
    bool in_float_range = true;
#pragma omp parallel for schedule(static) reduction(&& : in_float_range)
    for (long long v = 0; v < num_vertices; ++v) {
        Vec q;  // relative to the centre of the rest box
        for (int a = 0; a < 3; ++a) q[a] = mesh.positions[3 * v + a] - rest.centre[a];
        const auto unit = [&](int a) { return rest.half[a] > 0 ? q[a] / rest.half[a] : 0.0; };
        if (o.squash_axis >= 0) {
            const int a = o.squash_axis;
            // Anchored at the low end of the axis: an object squashed against the floor stays on it.
            for (int b = 0; b < 3; ++b)
                q[b] = b == a ? (q[b] + rest.half[b]) * squash_along - rest.half[b] : q[b] * squash_across;
        }
        if (o.bend_along >= 0) q[o.bend_toward] += pose.bend * rest.half[o.bend_along] * unit(o.bend_along) * unit(o.bend_along);
        if (o.twist_axis >= 0) {
            const int a = o.twist_axis, b = (a + 1) % 3, c = (a + 2) % 3;
            const double angle = pose.twist * unit(a), cs = std::cos(angle), sn = std::sin(angle);
            const double qb = q[b], qc = q[c];
            q[b] = cs * qb - sn * qc;
            q[c] = sn * qb + cs * qc;
        }
        if (wobble > 0) {
            // A travelling wave: its phase differs between vertices, so no vertex rests between frames.
            for (int a = 0; a < 3; ++a)
                q[a] += wobble * std::sin(pose.wobble_phase + kPi * unit((a + 1) % 3) + 2.1 * a);
        }
        for (int a = 0; a < 3; ++a) q[a] = o.scale * (q[a] + rest.centre[a]);
        for (int a = 0; a < 3; ++a) {
            const double x = pose.translation[a] + pose.rotation[a][0] * q[0] + pose.rotation[a][1] * q[1] +
                             pose.rotation[a][2] * q[2];
            in_float_range = in_float_range && std::abs(x) <= std::numeric_limits<float>::max();
            out[3 * v + a] = static_cast<Real>(x);
        }
    }
    // The detector works in float: a coordinate beyond its range is this file's mistake, named here
    // rather than as a non-finite vertex of an object index.
    if (!in_float_range)
        throw Error(spec_.source + ":" + std::to_string(o.line) + ": object '" + o.name + "' at frame " +
                    std::to_string(frame) + " has a coordinate beyond float's range (+-3.4e38)");
}

void ScriptedScene::positions(std::size_t object, int frame, std::vector<float>& out) const {
    write_positions(object, frame, out);
}

void ScriptedScene::positions(std::size_t object, int frame, std::vector<double>& out) const {
    write_positions(object, frame, out);
}

} // namespace kdet::scenes
