#pragma once
/// @file tearing_scene.hpp
/// @brief The "tearing" benchmark scene: topology that changes every frame.

#include <kdet/scenes.hpp>

#include <cstdint>
#include <vector>

namespace kdet::scenes {

/// @brief A slab (48 x 24 x 3 cubes of side 1/24, six tets each) torn along the line x = 1: the tets
/// whose centroids lie within one cube of it are removed a few per frame, in order of y, so that the
/// cut runs across the slab in the first 80 % of the frames. A box (8 x 8 x 4 cubes) descends onto the
/// slab beside the cut and presses two cubes deep into it while it follows the tear along y.
/// Object 0 is the slab (its vertices stand still, its tets change), object 1 the box.
class TearingScene final : public Scene {
public:
    /// @brief Throws kdet::Error for frames < 1.
    explicit TearingScene(int frames);
    std::string name() const override { return "tearing"; }
    std::size_t num_objects() const override { return 2; }
    int num_frames() const override { return frames_; }
    /// @brief The whole slab and the box; the slab loses tets from frame 1 on (tets()).
    const TetMesh& rest_mesh(std::size_t object) const override;
    void positions(std::size_t object, int frame, std::vector<float>& out) const override;
    void positions(std::size_t object, int frame, std::vector<double>& out) const override;
    bool changes_tets() const override { return true; }
    void tets(std::size_t object, int frame, std::vector<std::uint32_t>& out) const override;

private:
    template <class Real>
    void write_positions(std::size_t object, int frame, std::vector<Real>& out) const;

    int frames_;
    TetMesh slab_, box_;
    std::vector<std::uint32_t> cut_order_; ///< the slab's tets along the cut, in the order they go
    std::size_t cut_per_frame_ = 0;
};

} // namespace kdet::scenes
