/// @file fold_bar.cpp
/// @brief fold_bar: a bar wrapped around an axis until its ends pass through each other.

#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <cmath>

namespace kdet {

void fold_bar(const TetMesh& bar, double angle, std::vector<double>& out_positions) {
    if (bar.num_vertices() == 0) throw Error("fold_bar needs a bar with vertices");
    const std::vector<double>& rest = bar.positions;
    double x_min = rest[0], x_max = rest[0], z_min = rest[2], z_max = rest[2];
    for (std::size_t v = 0; v < bar.num_vertices(); ++v) {
        x_min = std::min(x_min, rest[3 * v]);
        x_max = std::max(x_max, rest[3 * v]);
        z_min = std::min(z_min, rest[3 * v + 2]);
        z_max = std::max(z_max, rest[3 * v + 2]);
    }
    const double length = x_max - x_min;
    if (!(length > 0.0)) throw Error("fold_bar needs a bar with a length along x");

    out_positions = rest;
    if (angle == 0.0) return;
    // The centre line (mid height) keeps its length; the axis lies bend_radius above it (below for a
    // negative angle). A layer farther from the axis than the bend radius would turn inside out.
    const double bend_radius = length / angle;
    const double z_centre = 0.5 * (z_min + z_max);
    if (0.5 * (z_max - z_min) >= std::abs(bend_radius))
        throw Error("fold_bar: the bar is too thick to bend by this angle without turning inside out");
    for (std::size_t v = 0; v < bar.num_vertices(); ++v) {
        const double theta = angle * (rest[3 * v] - x_min) / length;
        const double radius = bend_radius - (rest[3 * v + 2] - z_centre);
        out_positions[3 * v] = x_min + radius * std::sin(theta);
        out_positions[3 * v + 2] = z_centre + bend_radius - radius * std::cos(theta);
    }
}

} // namespace kdet
