#pragma once
/// @file view_test_support.hpp
/// @brief What the viewer's tests share: a scratch folder and small scenes.

#include "session.hpp"

#include "test_support.hpp"

#include <kdet/io.hpp>
#include <kdet/scenes.hpp>

#include <unistd.h>

#include <filesystem>
#include <random>
#include <string>

namespace kdet::view::test {

/// @brief A fresh folder @p name for this test process.
inline std::filesystem::path temp_dir(const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / ("kdet_view_test_" + std::to_string(getpid())) / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

/// @brief The procedural scene with @p tets tets and @p frames frames.
inline ViewSource procedural(std::size_t tets, int frames) {
    ViewSource source;
    source.request.procedural = ProceduralSceneOptions{tets, frames};
    return source;
}

/// @brief Two mesh files: the small octopus model and a copy of it moved into it.
inline ViewSource octopus_pair() {
    kdet::test::use_default_data_dir();
    const std::string octopus = data_path("octopus-low.mesh");
    const TetMesh mesh = read_tet_mesh(octopus);
    const auto dir = temp_dir("octopus");
    write_tetgen(kdet::test::moved(mesh, 0.3, 0.15 * kdet::test::extent_of(mesh), 0.0, 0.0), (dir / "moved").string());
    ViewSource source;
    source.meshes = {octopus, (dir / "moved").string()};
    return source;
}

/// @brief Two mesh files: an 8x8x8 box of unit cubes and a 2x2x2 box wholly inside it, so that
/// every colliding tet lies inside the big box.
inline ViewSource nested_boxes() {
    const auto dir = temp_dir("nested");
    TetMesh small = make_box_mesh(2, 2, 2, 1.0);
    for (double& x : small.positions) x += 3.37;
    write_tetgen(make_box_mesh(8, 8, 8, 1.0), (dir / "big").string());
    write_tetgen(small, (dir / "small").string());
    ViewSource source;
    source.meshes = {(dir / "big").string(), (dir / "small").string()};
    return source;
}

/// @brief A 4x4x4 box of unit cubes as a mesh file, and points in and around it: its vertices (each
/// held by several tets) and random points in the box grown by one unit on every side.
struct BoxAndPoints {
    TetMesh box;
    ViewSource source;
    std::vector<double> points;
};

inline BoxAndPoints box_and_points() {
    BoxAndPoints b{make_box_mesh(4, 4, 4, 1.0), {}, {}};
    const auto dir = temp_dir("points");
    write_tetgen(b.box, (dir / "box").string());
    b.source.meshes = {(dir / "box").string()};
    b.points = b.box.positions;
    std::mt19937 random(7);
    std::uniform_real_distribution<double> coordinate(-1.0, 5.0);
    for (int i = 0; i < 1500; ++i) b.points.push_back(coordinate(random));
    return b;
}

} // namespace kdet::view::test
