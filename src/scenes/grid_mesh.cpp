/// @file grid_mesh.cpp
/// @brief Tet meshes of solids sampled on a regular grid of cubes: make_box_mesh and make_torus_mesh.

#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace kdet {
namespace {

/// @brief Regular grid of cubes; cube (i, j, k) spans origin + [i, i+1] x [j, j+1] x [k, k+1] times cell_size.
struct CubeGrid {
    std::size_t nx, ny, nz;
    double cell_size;
    double origin[3];

    std::size_t num_cubes() const { return nx * ny * nz; }
    std::size_t num_points() const { return (nx + 1) * (ny + 1) * (nz + 1); }
    std::size_t cube_index(std::size_t i, std::size_t j, std::size_t k) const { return (k * ny + j) * nx + i; }
    std::size_t point_index(std::size_t i, std::size_t j, std::size_t k) const {
        return (k * (ny + 1) + j) * (nx + 1) + i;
    }
    double coordinate(int axis, double steps) const { return origin[axis] + steps * cell_size; }
};

/// Throws unless every grid point can get a 32-bit vertex index.
void check_grid_size(const CubeGrid& grid) {
    if (grid.num_points() >= std::numeric_limits<std::uint32_t>::max())
        throw Error("grid of " + std::to_string(grid.num_cubes()) + " cubes has too many vertices for 32-bit indices");
}

// Cube corners are numbered by bits: bit 0 is +x, bit 1 is +y, bit 2 is +z. Each tet walks from corner 0
// to corner 7 along one permutation of the axes, so all cubes share the same diagonal direction and
// neighbouring cubes split their common face the same way. Odd permutations list their last two corners
// swapped so that every tet is positively oriented.
constexpr int kKuhnTets[6][4] = {{0, 1, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7},
                                 {0, 1, 7, 5}, {0, 2, 7, 3}, {0, 4, 7, 6}};

/// @brief 1 for each cube (in cube_index order) whose centre satisfies `inside(x, y, z)`, else 0.
template <typename Inside>
std::vector<std::uint8_t> mark_cubes(const CubeGrid& grid, Inside inside) {
    std::vector<std::uint8_t> kept(grid.num_cubes());
    const auto layers = static_cast<long long>(grid.nz);
#pragma omp parallel for schedule(static)
    for (long long layer = 0; layer < layers; ++layer) {
        const auto k = static_cast<std::size_t>(layer);
        const double z = grid.coordinate(2, static_cast<double>(k) + 0.5);
        for (std::size_t j = 0; j < grid.ny; ++j) {
            const double y = grid.coordinate(1, static_cast<double>(j) + 0.5);
            for (std::size_t i = 0; i < grid.nx; ++i) {
                const double x = grid.coordinate(0, static_cast<double>(i) + 0.5);
                kept[grid.cube_index(i, j, k)] = inside(x, y, z) ? 1 : 0;
            }
        }
    }
    return kept;
}

/// @brief Grid point of corner `corner` (numbered as in kKuhnTets) of cube (i, j, k).
std::size_t corner_point(const CubeGrid& grid, std::size_t i, std::size_t j, std::size_t k, int corner) {
    const auto step = [corner](int axis) { return static_cast<std::size_t>((corner >> axis) & 1); };
    return grid.point_index(i + step(0), j + step(1), k + step(2));
}

/// @brief Calls visit(i, j, k) for every kept cube, in cube_index order.
template <typename Visit>
void for_each_kept_cube(const CubeGrid& grid, const std::vector<std::uint8_t>& kept, Visit visit) {
    for (std::size_t k = 0; k < grid.nz; ++k)
        for (std::size_t j = 0; j < grid.ny; ++j)
            for (std::size_t i = 0; i < grid.nx; ++i)
                if (kept[grid.cube_index(i, j, k)]) visit(i, j, k);
}

/// @brief The kept cubes, 6 tets each; only the grid points they use become vertices, in grid order.
TetMesh mesh_kept_cubes(const CubeGrid& grid, const std::vector<std::uint8_t>& kept) {
    constexpr std::uint32_t unused = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> vertex_of_point(grid.num_points(), unused);
    std::size_t num_kept = 0;
    for_each_kept_cube(grid, kept, [&](std::size_t i, std::size_t j, std::size_t k) {
        ++num_kept;
        for (int corner = 0; corner < 8; ++corner) vertex_of_point[corner_point(grid, i, j, k, corner)] = 0;
    });

    TetMesh mesh;
    std::uint32_t next_vertex = 0;
    for (std::size_t k = 0; k <= grid.nz; ++k)
        for (std::size_t j = 0; j <= grid.ny; ++j)
            for (std::size_t i = 0; i <= grid.nx; ++i) {
                std::uint32_t& vertex = vertex_of_point[grid.point_index(i, j, k)];
                if (vertex == unused) continue;
                vertex = next_vertex++;
                mesh.positions.insert(mesh.positions.end(), {grid.coordinate(0, static_cast<double>(i)),
                                                             grid.coordinate(1, static_cast<double>(j)),
                                                             grid.coordinate(2, static_cast<double>(k))});
            }

    mesh.tets.reserve(num_kept * 24);
    for_each_kept_cube(grid, kept, [&](std::size_t i, std::size_t j, std::size_t k) {
        for (const auto& tet : kKuhnTets)
            for (int corner : tet) mesh.tets.push_back(vertex_of_point[corner_point(grid, i, j, k, corner)]);
    });
    return mesh;
}

/// @brief Grid of cubes of edge `cell_size` covering the torus's bounding box.
///
/// The grid is shifted off the torus's symmetry planes by a fraction of a cell per axis, so that the
/// kept cubes do not come in groups of 8 mirror images and the count can be tuned in steps of one cube.
CubeGrid torus_grid(double major_radius, double minor_radius, double cell_size) {
    const double ring_extent = 2.0 * (major_radius + minor_radius);
    const double axis_extent = 2.0 * minor_radius;
    const auto cubes_across = [cell_size](double extent) {
        return static_cast<std::size_t>(std::ceil(extent / cell_size)) + 1;
    };
    const std::size_t n_ring = cubes_across(ring_extent);
    const std::size_t n_axis = cubes_across(axis_extent);
    CubeGrid grid{n_ring, n_ring, n_axis, cell_size,
                  {-0.5 * ring_extent - 0.31 * cell_size, -0.5 * ring_extent - 0.17 * cell_size,
                   -0.5 * axis_extent - 0.43 * cell_size}};
    check_grid_size(grid);
    return grid;
}

} // namespace

TetMesh make_box_mesh(int nx, int ny, int nz, double cell_size) {
    if (nx < 1 || ny < 1 || nz < 1 || !(cell_size > 0.0))
        throw Error("box mesh needs at least one cube along each axis and a positive cell size");
    const CubeGrid grid{static_cast<std::size_t>(nx), static_cast<std::size_t>(ny), static_cast<std::size_t>(nz),
                        cell_size, {0.0, 0.0, 0.0}};
    check_grid_size(grid);
    return mesh_kept_cubes(grid, std::vector<std::uint8_t>(grid.num_cubes(), 1));
}

TetMesh make_torus_mesh(double major_radius, double minor_radius, std::size_t target_tets) {
    if (!(minor_radius > 0.0) || !(major_radius > minor_radius))
        throw Error("torus needs 0 < minor radius < major radius");
    if (target_tets == 0) throw Error("torus needs a positive tet count");

    const auto inside = [major_radius, minor_radius](double x, double y, double z) {
        const double from_ring = std::hypot(x, y) - major_radius;
        return from_ring * from_ring + z * z < minor_radius * minor_radius;
    };
    // The count falls (almost monotonically) in steps as the cell grows: bracket the target between a
    // fine and a coarse cell size around the volume estimate, then bisect, keeping the closest count.
    const double target = static_cast<double>(target_tets);
    double best_cell_size = 0.0;
    double best_error = std::numeric_limits<double>::infinity();
    const auto tets_for = [&](double cell_size) {
        const std::vector<std::uint8_t> kept = mark_cubes(torus_grid(major_radius, minor_radius, cell_size), inside);
        const auto tets = static_cast<double>(6 * std::count(kept.begin(), kept.end(), std::uint8_t{1}));
        const double error = std::abs(tets - target) / target;
        if (error < best_error) {
            best_error = error;
            best_cell_size = cell_size;
        }
        return tets;
    };
    const double pi = std::acos(-1.0);
    const double torus_volume = 2.0 * pi * pi * major_radius * minor_radius * minor_radius;
    double fine = std::cbrt(6.0 * torus_volume / target);
    double coarse = fine;
    while (tets_for(fine) < target) fine *= 0.8;
    while (tets_for(coarse) >= target) coarse *= 1.25;
    for (int step = 0; step < 40 && best_error > 0.01; ++step) {
        const double middle = 0.5 * (fine + coarse);
        (tets_for(middle) >= target ? fine : coarse) = middle;
    }

    const CubeGrid grid = torus_grid(major_radius, minor_radius, best_cell_size);
    return mesh_kept_cubes(grid, mark_cubes(grid, inside));
}

} // namespace kdet
