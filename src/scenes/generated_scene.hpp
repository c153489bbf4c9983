#pragma once
/// @file generated_scene.hpp
/// @brief A scene whose meshes are built in code and whose motion is a function of the frame: what the
/// scenes of heap.cpp and drape.cpp share. Private to the scenes module.

#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace kdet::scenes {

/// @brief Objects with rest meshes (one mesh shared by the objects that are alike), a motion that gives
/// each object's positions at a frame, which objects are static and self-collide, and their collision
/// filters (none unless set_filters() gives them).
class GeneratedScene final : public Scene {
public:
    /// @brief Writes object `o`'s vertex positions at `frame` as x y z doubles into `out` (resized).
    using Motion = std::function<void(std::size_t o, int frame, std::vector<double>& out)>;

    /// @brief Object o's rest mesh is meshes[mesh_of[o]].
    GeneratedScene(std::string name, int resolution, int frames, std::vector<TetMesh> meshes, std::vector<std::size_t> mesh_of,
                   std::vector<bool> is_static, std::vector<bool> self, Motion motion)
        : name_(std::move(name)), resolution_(resolution), frames_(frames), meshes_(std::move(meshes)),
          mesh_of_(std::move(mesh_of)), static_(std::move(is_static)), self_(std::move(self)), motion_(std::move(motion)) {}

    std::string name() const override { return name_; }
    std::size_t num_objects() const override { return mesh_of_.size(); }
    int num_frames() const override { return frames_; }
    const TetMesh& rest_mesh(std::size_t object) const override {
        check(object, 0);
        return meshes_[mesh_of_[object]];
    }
    /// @brief The motion is written with z up; the scene turns it to y up, as the thesis scenes stand.
    void positions(std::size_t object, int frame, std::vector<double>& out) const override {
        check(object, frame);
        motion_(object, frame, out);
        for (std::size_t v = 0; v + 2 < out.size(); v += 3) {
            const double y = out[v + 1];
            out[v + 1] = out[v + 2];
            out[v + 2] = -y;
        }
    }
    void positions(std::size_t object, int frame, std::vector<float>& out) const override {
        std::vector<double> exact;
        positions(object, frame, exact);
        out.assign(exact.begin(), exact.end());
    }
    /// @brief Object o's collision filter becomes filters[o].
    void set_filters(std::vector<CollisionFilter> filters) { filters_ = std::move(filters); }
    CollisionFilter collision_filter(std::size_t object) const override {
        return object < filters_.size() ? filters_[object] : CollisionFilter{};
    }
    bool checks_self(std::size_t object) const override { return object < self_.size() && self_[object]; }
    bool is_static(std::size_t object) const override { return object < static_.size() && static_[object]; }
    int resolution() const override { return resolution_; }

private:
    void check(std::size_t object, int frame) const {
        if (object >= mesh_of_.size())
            throw Error("scene " + name_ + " has no object " + std::to_string(object) + " (it has " +
                        std::to_string(mesh_of_.size()) + ")");
        if (frame < 0 || frame >= frames_)
            throw Error("scene " + name_ + " has no frame " + std::to_string(frame) + " (it has " + std::to_string(frames_) + ")");
    }

    std::string name_;
    int resolution_;
    int frames_;
    std::vector<TetMesh> meshes_;
    std::vector<std::size_t> mesh_of_;
    std::vector<bool> static_, self_;
    std::vector<CollisionFilter> filters_;
    Motion motion_;
};

} // namespace kdet::scenes
