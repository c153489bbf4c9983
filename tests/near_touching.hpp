#pragma once
/// Tet pairs placed around the decision margins of the face-plane pre-test (src/geometry/face_planes.hpp)
/// and of the narrow-phase tests' tolerance, for checking that the pre-test never changes an answer.

#include <kdet/mesh.hpp>
#include <kdet/options.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace kdet::test {

/// @brief Every narrow-phase test the library names, so that a test added later is covered too.
inline std::vector<NarrowPhase> every_narrow_phase_test() {
    std::vector<NarrowPhase> tests;
    for (int v = 0; std::strcmp(to_string(static_cast<NarrowPhase>(v)), "?") != 0; ++v)
        tests.push_back(static_cast<NarrowPhase>(v));
    return tests;
}

/// @brief Tet i of `first` and tet i of `second` form one pair; pairs lie far apart from each other.
struct NearTouchingPairs {
    TetMesh first, second;
};

/// @brief Pairs of a random tet A (shortest edge at least a tenth of its longest) and a tet B with one
/// vertex at the centroid of a face of A moved by a signed depth d along that face's inward normal, its
/// other vertices beyond the face. d < 0 separates the pair by -d along the face normal; d > 0 puts the
/// vertex inside A (by d while d is below its depth under the other faces). A third of the pairs take d
/// within three times the pre-test's separation margin of that face, (2^-15 / s + 2^-16) L^2 / l_f
/// (L: the pair's longest edge; s, l_f: the sine and the shorter of the face's two edges at its largest
/// angle; its inside margin is twice that with l_A L for L^2, l_A A's longest edge, so at most twice
/// that), a third within three times 2^-9 L^2 / l (l: A's shortest edge), the margin of a face at the
/// smallest sine the pre-test allows, and a third within 1e-7 L to
/// 3e-4 L of touching, where the float tests' tolerance lies. `per_size` pairs
/// (rounded up to a cube) for each of four sizes a decade apart, each size on its own lattice at most
/// 60 sizes from the origin, so that the float coordinates keep the depths (relative rounding below 4e-6).
inline NearTouchingPairs near_touching_pairs(std::size_t per_size, unsigned seed) {
    using P = std::array<double, 3>;
    auto sub = [](P a, P b) { return P{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
    auto add = [](P a, P b) { return P{a[0] + b[0], a[1] + b[1], a[2] + b[2]}; };
    auto mul = [](P a, double s) { return P{a[0] * s, a[1] * s, a[2] * s}; };
    auto dot = [](P a, P b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    auto cross = [](P a, P b) { return P{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; };
    auto norm = [&](P a) { return std::sqrt(dot(a, a)); };
    auto edges = [&](const P* v, double& shortest, double& longest) {
        shortest = 1e300;
        longest = 0.0;
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j) {
                shortest = std::min(shortest, norm(sub(v[j], v[i])));
                longest = std::max(longest, norm(sub(v[j], v[i])));
            }
    };
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::size_t side = 1;
    while (side * side * side < per_size) ++side;
    NearTouchingPairs out;
    std::uint32_t pair = 0;
    for (double size : {0.01, 0.1, 1.0, 10.0})
        for (std::size_t cell = 0; cell < side * side * side; ++cell, ++pair) {
            const P corner{30.0 * size + 4.0 * size * static_cast<double>(cell % side),
                           30.0 * size + 4.0 * size * static_cast<double>(cell / side % side),
                           30.0 * size + 4.0 * size * static_cast<double>(cell / side / side)};
            P a[4];
            double shortest = 0.0, longest = 0.0;
            do {
                for (P& v : a) v = add(corner, P{size * unit(rng), size * unit(rng), size * unit(rng)});
                edges(a, shortest, longest);
            } while (shortest < 0.1 * longest);
            const int k = static_cast<int>(rng() % 4); // the face opposite vertex k
            const P f0 = a[(k + 1) % 4], f1 = a[(k + 2) % 4], f2 = a[(k + 3) % 4];
            P n = cross(sub(f1, f0), sub(f2, f0));
            n = mul(n, 1.0 / norm(n));
            if (dot(n, sub(a[k], f0)) > 0.0) n = mul(n, -1.0); // outward
            const P t1 = mul(sub(f1, f0), 1.0 / norm(sub(f1, f0))), t2 = cross(n, t1);
            const P apex_mirror = add(a[k], mul(n, -2.0 * dot(n, sub(a[k], f0))));
            const P centroid = mul(add(add(f0, f1), f2), 1.0 / 3.0);
            P b[4] = {centroid, apex_mirror, add(apex_mirror, mul(t1, 0.5 * longest)),
                      add(apex_mirror, mul(t2, 0.5 * longest))};
            double b_shortest = 0.0, pair_longest = 0.0;
            edges(b, b_shortest, pair_longest);
            pair_longest = std::max(longest, pair_longest);
            // The face's two edges at its largest angle, the one opposite its longest edge.
            P f = sub(f1, f0), g = sub(f2, f0);
            const double l01 = norm(f), l02 = norm(g), l12 = norm(sub(f2, f1));
            if (l01 >= l02 && l01 >= l12) f = sub(f2, f1); // the angle at f2: edges f2-f0 and f2-f1
            else if (l02 >= l12) g = sub(f2, f1);          // the angle at f1: edges f1-f0 and f2-f1
            const double sine = norm(cross(f, g)) / (norm(f) * norm(g));
            const double separation_margin = (std::ldexp(1.0, -15) / sine + std::ldexp(1.0, -16)) * pair_longest *
                                             pair_longest / std::min(norm(f), norm(g));
            const double inside_scale = std::ldexp(1.0, -9) * pair_longest * pair_longest / shortest;
            const double which = unit(rng);
            const double depth = which < 1.0 / 3.0   ? separation_margin * (6.0 * unit(rng) - 3.0)
                                 : which < 2.0 / 3.0 ? inside_scale * (6.0 * unit(rng) - 3.0)
                                                     : (unit(rng) < 0.5 ? -1.0 : 1.0) * pair_longest *
                                                           std::pow(10.0, -7.0 + 3.5 * unit(rng));
            b[0] = sub(centroid, mul(n, depth));
            std::rotate(b, b + rng() % 4, b + 4); // the inner vertex at any index
            for (int v = 0; v < 4; ++v)
                for (int c = 0; c < 3; ++c) {
                    out.first.positions.push_back(a[v][c]);
                    out.second.positions.push_back(b[v][c]);
                }
            for (std::uint32_t v = 0; v < 4; ++v) {
                out.first.tets.push_back(4 * pair + v);
                out.second.tets.push_back(4 * pair + v);
            }
        }
    return out;
}

} // namespace kdet::test
