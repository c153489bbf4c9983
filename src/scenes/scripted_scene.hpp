#pragma once
/// @file scripted_scene.hpp
/// @brief Scene files (docs/scenes.md): what a file says, and the scene that plays it. Private to the
/// scenes module and its tests.

#include <kdet/scenes.hpp>

#include <array>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace kdet::scenes {

/// @brief The keyed quantities of an object; each has its own keys.
enum class Channel { move, turn, bend, twist, squash };
constexpr std::size_t kNumChannels = 5;

/// @brief One key of a channel: the frame and the value (x y z for move and turn, else only x).
struct Key {
    double frame = 0.0;
    std::array<double, 3> value{};
    std::size_t line = 0; ///< of the scene file, for messages
};

/// @brief An object of a scene file as written.
struct ObjectSpec {
    std::string name;
    std::size_t line = 0;                  ///< where its `object` statement stands
    std::size_t mesh_line = 0;             ///< where its `mesh` or `file` statement stands
    std::string model;                     ///< a prepared thesis model, or
    std::string file;                      ///< a tet mesh file (relative to the scene file)
    int resolution = 0;                    ///< 0: the one requested
    double scale = 1.0;
    std::array<double, 3> rotate{};        ///< degrees about x, then y, then z
    std::array<double, 3> translate{};
    int bend_along = -1, bend_toward = -1; ///< axes 0-2, -1 when the object does not bend
    int twist_axis = -1;
    int squash_axis = -1;
    double wobble_amplitude = 0.0;         ///< fraction of the largest extent
    double wobble_period = 0.0;            ///< frames
    std::array<std::vector<Key>, kNumChannels> keys;
    bool is_static = false;                ///< `static`: placed once, never moved (no keys or deformations)
};

/// @brief A scene file as written.
struct SceneSpec {
    std::string source;                                      ///< the file (or built-in scene) it was read from
    std::string name;
    int frames = 0;
    std::vector<ObjectSpec> objects;
    bool pairs_given = false;                                ///< false: every pair is checked
    std::vector<std::pair<std::size_t, std::size_t>> pairs;  ///< object indices, a < b
    std::vector<std::size_t> self;                           ///< objects checked against themselves
};

/// @brief Parses scene text; errors are "source:line: what". @p source names it in messages.
SceneSpec parse_scene(const std::string& text, const std::string& source);

/// @brief The value of a channel at @p frame: a C1 cubic through the keys (Catmull-Rom tangents; the
/// first and last key take the slope to their neighbour, so two keys move at constant speed), constant
/// outside the keys, 0 without keys.
std::array<double, 3> evaluate(const std::vector<Key>& keys, double frame);

/// @brief A scene played from a SceneSpec; see docs/scenes.md for the motion.
class ScriptedScene final : public Scene {
public:
    /// @brief Loads the meshes: prepared models at the object's resolution (else @p resolution), files
    /// relative to @p base_dir. Throws kdet::Error when a mesh is missing, prefixed with the file and the
    /// line of the object's mesh statement when @p user_file (a built-in scene's file is not the user's).
    ScriptedScene(SceneSpec spec, int resolution, const std::string& base_dir, bool user_file);

    std::string name() const override;
    std::size_t num_objects() const override;
    int num_frames() const override;
    const TetMesh& rest_mesh(std::size_t object) const override;
    void positions(std::size_t object, int frame, std::vector<float>& out) const override;
    void positions(std::size_t object, int frame, std::vector<double>& out) const override;
    bool checks_pair(std::size_t a, std::size_t b) const override;
    bool checks_self(std::size_t object) const override;
    bool is_static(std::size_t object) const override;
    /// @brief The requested one when a model object follows it, else the first model object's own; 0
    /// without model objects (mesh files only).
    int resolution() const override { return resolution_; }

    const SceneSpec& spec() const { return spec_; }

private:
    template <typename Real>
    void write_positions(std::size_t object, int frame, std::vector<Real>& out) const;

    /// @brief What the motion needs of a rest mesh: its box centre and half extents.
    struct RestFrame {
        std::array<double, 3> centre{}, half{};
    };

    SceneSpec spec_;
    int resolution_ = 0;
    std::vector<TetMesh> meshes_;
    std::vector<RestFrame> rest_;
};

/// @brief The thesis scene files compiled into the library: (name, text) pairs.
const std::vector<std::pair<std::string, std::string>>& builtin_scene_files();

} // namespace kdet::scenes
