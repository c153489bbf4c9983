#pragma once
/// Random pairs of tets near each other, for the tests of the pair decisions (the margin's among them).

#include "geometry/vec3.hpp"

#include <random>

namespace kdet::test {

/// @brief Two random tets of about `size` (coordinates within it of their centres), b's centre 1.7 to
/// 2.7 sizes from a's along x: near each other, now and then touching.
inline void random_nearby_tets(std::mt19937& rng, float size, vec3 a[4], vec3 b[4]) {
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    const vec3 offset{(2.2f + 0.5f * unit(rng)) * size, unit(rng) * size, unit(rng) * size};
    for (int k = 0; k < 4; ++k) {
        a[k] = {unit(rng) * size, unit(rng) * size, unit(rng) * size};
        b[k] = {unit(rng) * size + offset.x, unit(rng) * size + offset.y, unit(rng) * size + offset.z};
    }
}

} // namespace kdet::test
