/// @file drape.cpp
/// @brief The `drape` scene: a sheet three tets thick falls onto a static ball, wraps over it and folds
/// where it hangs.

#include "scenes/generated_scene.hpp"

#include <kdet/scenes.hpp>

#include <algorithm>
#include <cmath>

namespace kdet {
namespace {

constexpr int kFrames = 120;
constexpr double kPi = 3.141592653589793;
constexpr double kRadius = 1.0;       // the ball's
constexpr double kHalfSheet = 1.7;    // half the sheet's side
constexpr int kFallEnd = 30;          // the sheet lies flat on the ball's top
constexpr int kWrapEnd = 80;          // and has wrapped over it down to the equator
constexpr double kPleats = 8.0;       // folds around the hanging part
constexpr double kFoldStrength = 6.0; // above 1 / (hanging length), the hanging part folds over itself

/// @brief A ball: a box mesh whose points are pushed out from the cube onto the sphere of the same
/// largest-axis norm (conforming, and valid at this resolution), centred on the origin.
TetMesh make_ball(int cells) {
    TetMesh ball = make_box_mesh(cells, cells, cells, 2.0 * kRadius / cells);
    for (std::size_t v = 0; v < ball.num_vertices(); ++v) {
        double* p = &ball.positions[3 * v];
        for (int a = 0; a < 3; ++a) p[a] -= kRadius;
        const double cube = std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])});
        const double round = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        if (round > 0)
            for (int a = 0; a < 3; ++a) p[a] *= cube / round;
    }
    return ball;
}

} // namespace

std::unique_ptr<Scene> make_drape_scene(int resolution) {
    if (resolution < 1 || resolution > 4) throw Error("drape: resolution " + std::to_string(resolution) + " out of range [1, 4]");
    // Sheets of 1 cube's thickness (three tets across it), 40 to 160 cubes a side; a ball of about as
    // many tets.
    const int cells = 40 * resolution;
    const double thickness = 2.0 * kHalfSheet / cells;
    TetMesh sheet = make_box_mesh(cells, cells, 1, thickness);
    for (std::size_t v = 0; v < sheet.num_vertices(); ++v) {
        sheet.positions[3 * v] -= kHalfSheet;
        sheet.positions[3 * v + 1] -= kHalfSheet;
    }
    TetMesh ball = make_ball(static_cast<int>(std::lround(std::cbrt(cells * cells * 6.0 / 6.0))));
    auto motion = [ball_positions = ball.positions, rest = sheet.positions, thickness](std::size_t o, int frame,
                                                                                       std::vector<double>& out) {
        if (o == 0) {
            out = ball_positions;
            return;
        }
        // The sheet's lower face sinks a third of its thickness into the ball: a large contact area.
        const double lie = kRadius - thickness / 3.0;
        const double drop = frame < kFallEnd ? 0.6 * kRadius * (1.0 - static_cast<double>(frame) / kFallEnd) : 0.0;
        const double wrap = std::clamp(static_cast<double>(frame - kFallEnd) / (kWrapEnd - kFallEnd), 0.0, 1.0);
        const double fold = std::clamp(static_cast<double>(frame - kWrapEnd) / (kFrames - 1 - kWrapEnd), 0.0, 1.0);
        const double top = 0.5 * kPi * wrap; // the polar angle down to which the sheet lies on the ball
        out.resize(rest.size());
        for (std::size_t v = 0; v < rest.size() / 3; ++v) {
            const double u = rest[3 * v], w = rest[3 * v + 1], h = rest[3 * v + 2];
            const double rho = std::sqrt(u * u + w * w);
            double phi = std::atan2(w, u);
            const double r = lie + h;
            // Arc length is kept on the ball; past `top` the sheet goes on along the tangent there, and
            // its hanging part pleats around the ball, folding over itself as the pleats deepen.
            const double theta = std::min(rho / lie, top);
            const double hanging = std::max(0.0, rho - top * lie);
            phi += fold * kFoldStrength * hanging / kRadius * std::sin(kPleats * phi) / kPleats;
            const double st = std::sin(theta), ct = std::cos(theta), cp = std::cos(phi), sp = std::sin(phi);
            out[3 * v] = r * st * cp + hanging * ct * cp;
            out[3 * v + 1] = r * st * sp + hanging * ct * sp;
            out[3 * v + 2] = r * ct - hanging * st + drop;
        }
    };
    return std::make_unique<scenes::GeneratedScene>("drape", resolution, kFrames, std::vector<TetMesh>{std::move(ball), std::move(sheet)},
                                                    std::vector<std::size_t>{0, 1}, std::vector<bool>{true, false},
                                                    std::vector<bool>{false, true}, std::move(motion));
}

} // namespace kdet
