#include "scenes/tearing_scene.hpp"

#include <kdet/error.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace kdet::scenes {

namespace {

constexpr double cell = 1.0 / 24.0;
constexpr double cut_x = 1.0;

double centroid(const TetMesh& mesh, std::size_t t, int axis) {
    double sum = 0;
    for (int k = 0; k < 4; ++k) sum += mesh.positions[3 * std::size_t{mesh.tets[4 * t + k]} + axis];
    return sum / 4;
}

} // namespace

TearingScene::TearingScene(int frames) : frames_(frames) {
    if (frames < 1) throw Error("tearing: frames " + std::to_string(frames) + " out of range (at least 1)");
    slab_ = make_box_mesh(48, 24, 3, cell);
    box_ = make_box_mesh(8, 8, 4, cell);
    for (std::uint32_t t = 0; t < slab_.num_tets(); ++t)
        if (std::abs(centroid(slab_, t, 0) - cut_x) < cell) cut_order_.push_back(t);
    std::stable_sort(cut_order_.begin(), cut_order_.end(), [&](std::uint32_t a, std::uint32_t b) {
        return centroid(slab_, a, 1) < centroid(slab_, b, 1);
    });
    const auto tearing_frames = static_cast<std::size_t>(std::max(1, frames * 4 / 5));
    cut_per_frame_ = (cut_order_.size() + tearing_frames - 1) / tearing_frames;
}

const TetMesh& TearingScene::rest_mesh(std::size_t object) const {
    if (object > 1) throw Error("tearing: object " + std::to_string(object) + " out of range (2 objects)");
    return object == 0 ? slab_ : box_;
}

void TearingScene::tets(std::size_t object, int frame, std::vector<std::uint32_t>& out) const {
    const TetMesh& mesh = rest_mesh(object);
    if (object == 1) {
        out = mesh.tets;
        return;
    }
    const std::size_t cut = std::min(cut_order_.size(), static_cast<std::size_t>(std::max(frame, 0)) * cut_per_frame_);
    std::vector<std::uint8_t> gone(mesh.num_tets(), 0);
    for (std::size_t i = 0; i < cut; ++i) gone[cut_order_[i]] = 1;
    out.clear();
    for (std::size_t t = 0; t < mesh.num_tets(); ++t)
        if (!gone[t]) out.insert(out.end(), mesh.tets.begin() + 4 * t, mesh.tets.begin() + 4 * t + 4);
}

template <class Real>
void TearingScene::write_positions(std::size_t object, int frame, std::vector<Real>& out) const {
    const TetMesh& mesh = rest_mesh(object);
    out.assign(mesh.positions.begin(), mesh.positions.end());
    if (object == 0) return;
    // The box comes down beside the cut over the first sixth of the frames, then follows the tear.
    const double progress = frames_ > 1 ? static_cast<double>(frame) / (frames_ - 1) : 0.0;
    const double descent = std::min(1.0, 6.0 * progress);
    const double dx = cut_x + 0.5 * cell, dy = 0.05 + 0.6 * progress;
    const double dz = 3 * cell + 0.1 * (1.0 - descent) - 2 * cell * descent;
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
        out[3 * v] = static_cast<Real>(mesh.positions[3 * v] + dx);
        out[3 * v + 1] = static_cast<Real>(mesh.positions[3 * v + 1] + dy);
        out[3 * v + 2] = static_cast<Real>(mesh.positions[3 * v + 2] + dz);
    }
}

void TearingScene::positions(std::size_t object, int frame, std::vector<float>& out) const {
    write_positions(object, frame, out);
}
void TearingScene::positions(std::size_t object, int frame, std::vector<double>& out) const {
    write_positions(object, frame, out);
}

} // namespace kdet::scenes
