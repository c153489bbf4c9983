#pragma once
/// @file peer_cases.hpp
/// @brief The cases on which kdet is compared with the CGAL-based peer (cpu_vs_cgal.cpp): the models
/// against a moved copy, the models folded onto themselves, random soups and the procedural scene,
/// each as a few frames of the same objects.

#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/mesh.hpp>
#include <kdet/prepare.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <regex>
#include <string>
#include <vector>

namespace kdet::bench {

struct PeerCase {
    std::string name;
    bool self = false;                        ///< one object with self-collision, else two objects
    std::vector<std::vector<TetMesh>> frames; ///< [frame][object]; the tets are the same in every frame

    std::size_t tet_count() const {
        std::size_t n = 0;
        for (const TetMesh& m : frames[0]) n += m.num_tets();
        return n;
    }
};

/// Frames of every case (frame by frame cycles through them).
constexpr int peer_frames = 4;

struct Box3 {
    double lo[3] = {1e300, 1e300, 1e300};
    double hi[3] = {-1e300, -1e300, -1e300};
    double centre(int a) const { return 0.5 * (lo[a] + hi[a]); }
    double extent(int a) const { return hi[a] - lo[a]; }
};

inline Box3 box_of(const TetMesh& mesh) {
    Box3 b;
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v)
        for (int a = 0; a < 3; ++a) {
            b.lo[a] = std::min(b.lo[a], mesh.positions[3 * v + a]);
            b.hi[a] = std::max(b.hi[a], mesh.positions[3 * v + a]);
        }
    return b;
}

/// A copy turned by `angle` about the z axis through the box centre and shifted along x by `shift`
/// times the largest extent: it overlaps the original in most of its volume.
inline TetMesh moved_copy(const TetMesh& mesh, double angle, double shift) {
    const Box3 b = box_of(mesh);
    const double size = std::max({b.extent(0), b.extent(1), b.extent(2)});
    TetMesh out = mesh;
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
        const double x = mesh.positions[3 * v] - b.centre(0), y = mesh.positions[3 * v + 1] - b.centre(1);
        out.positions[3 * v] = b.centre(0) + std::cos(angle) * x - std::sin(angle) * y + shift * size;
        out.positions[3 * v + 1] = b.centre(1) + std::sin(angle) * x + std::cos(angle) * y;
    }
    return out;
}

/// Folds a mesh onto itself: the part beyond the plane x = (box centre) turns by `angle` about the
/// axis parallel to y through the box centre, so it sweeps into the part before the plane. The turn
/// grows smoothly across a band of a tenth of the length beyond the plane, so the tets there bend
/// instead of tearing.
inline TetMesh folded(const TetMesh& mesh, double angle) {
    const Box3 b = box_of(mesh);
    const double x0 = b.centre(0), z0 = b.centre(2), band = 0.1 * b.extent(0);
    TetMesh out = mesh;
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
        const double x = mesh.positions[3 * v] - x0, z = mesh.positions[3 * v + 2] - z0;
        if (x <= 0.0) continue;
        const double s = std::min(1.0, x / band);
        const double turn = angle * s * s * (3.0 - 2.0 * s);
        out.positions[3 * v] = x0 + std::cos(turn) * x - std::sin(turn) * z;
        out.positions[3 * v + 2] = z0 + std::sin(turn) * x + std::cos(turn) * z;
    }
    return out;
}

/// `count` random tets (four random corners each in a cube of their size) whose sizes are spread
/// evenly over three decades, [0.001, 1], in a cube sized for about 300 tets per unit volume, so
/// that the number of box-overlapping pairs per tet does not depend on the count. `jitter` shifts
/// every tet by a small random offset (one per frame).
inline TetMesh random_soup(std::size_t count, unsigned seed, double jitter) {
    const double extent = std::cbrt(static_cast<double>(count) / 300.0);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    TetMesh mesh;
    mesh.positions.reserve(12 * count);
    mesh.tets.reserve(4 * count);
    for (std::size_t t = 0; t < count; ++t) {
        const double size = std::pow(10.0, -3.0 * unit(rng));
        double centre[3];
        for (double& c : centre) c = extent * unit(rng);
        for (int k = 0; k < 4; ++k)
            for (double c : centre) mesh.positions.push_back(c + size * (unit(rng) - 0.5));
        for (std::uint32_t k = 0; k < 4; ++k) mesh.tets.push_back(static_cast<std::uint32_t>(4 * t) + k);
    }
    std::mt19937 move(seed + 7919u);
    std::uniform_real_distribution<double> offset(-jitter, jitter);
    for (std::size_t t = 0; t < count; ++t) {
        const double d[3] = {offset(move), offset(move), offset(move)};
        for (std::size_t k = 12 * t; k < 12 * t + 12; ++k) mesh.positions[k] += d[k % 3];
    }
    return mesh;
}

inline PeerCase model_case(const std::string& file, bool fold) {
    const TetMesh mesh = read_tet_mesh(data_path(file));
    PeerCase c{file.substr(0, file.find('.')) + (fold ? " folded" : " vs moved copy"), fold, {}};
    for (int f = 0; f < peer_frames; ++f)
        c.frames.push_back(fold ? std::vector<TetMesh>{folded(mesh, 2.4 + 0.03 * f)}
                                : std::vector<TetMesh>{mesh, moved_copy(mesh, 0.3, 0.1 + 0.01 * f)});
    return c;
}

inline PeerCase soup_case(std::size_t count) {
    PeerCase c{"soup " + std::to_string(count / 1000) + "k", false, {}};
    for (int f = 0; f < peer_frames; ++f)
        c.frames.push_back({random_soup(count / 2, 11, 0.01 * f), random_soup(count - count / 2, 12, 0.01 * f)});
    return c;
}

inline PeerCase procedural_case(std::size_t count) {
    ProceduralSceneOptions options;
    options.total_tets = count;
    const ProceduralScene scene(options);
    PeerCase c{"procedural " + std::to_string(count / 1000) + "k", false, {}};
    for (int f = 0; f < peer_frames; ++f) {
        std::vector<TetMesh> objects(scene.num_objects());
        for (std::size_t o = 0; o < objects.size(); ++o) {
            objects[o].tets = scene.rest_mesh(o).tets;
            scene.positions(o, scene.num_frames() / 2 - peer_frames / 2 + f, objects[o].positions);
        }
        c.frames.push_back(objects);
    }
    return c;
}

/// A case's name and how to build it, so that only the cases asked for are built.
struct PeerCaseMaker {
    std::string name;
    bool small; ///< part of the quick set
    std::function<PeerCase()> make;
};

/// Every case, small ones first within each kind.
inline std::vector<PeerCaseMaker> peer_case_makers() {
    std::vector<PeerCaseMaker> makers;
    for (const char* model : {"bunny.mesh", "hand.mesh", "octopus-low.mesh"}) {
        const std::string file = model, stem = file.substr(0, file.find('.'));
        const bool small = stem == "octopus-low";
        makers.push_back({stem + " vs moved copy", small, [file] { return model_case(file, false); }});
        makers.push_back({stem + " folded", small, [file] { return model_case(file, true); }});
    }
    for (std::size_t count : {1000u, 10000u, 100000u, 1000000u})
        makers.push_back({"soup " + std::to_string(count / 1000) + "k", count <= 10000, [count] { return soup_case(count); }});
    for (std::size_t count : {10000u, 100000u, 1000000u})
        makers.push_back({"procedural " + std::to_string(count / 1000) + "k", count <= 10000,
                          [count] { return procedural_case(count); }});
    return makers;
}

/// The cases whose names match `only` (all of them, or only the small ones when `quick`).
inline std::vector<PeerCase> peer_cases(bool quick, const std::regex& only) {
    std::vector<PeerCase> cases;
    for (const PeerCaseMaker& maker : peer_case_makers())
        if ((!quick || maker.small) && std::regex_search(maker.name, only)) cases.push_back(maker.make());
    return cases;
}

} // namespace kdet::bench
