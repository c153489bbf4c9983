/// @file test_narrow_phase.cpp
/// @brief Obvious cases for every tetrahedron-tetrahedron test, at unit and tiny scales.
/// The exact comparison against CGAL lives in tests/cgal.

#include <gtest/gtest.h>

#include <cmath>

#include "geometry/tet_intersect.hpp"

namespace {

using kdet::NarrowPhase;
using kdet::vec3;

constexpr NarrowPhase k_all_tests[] = {NarrowPhase::sat, NarrowPhase::sat_no_edges, NarrowPhase::sat_mtv,
                                       NarrowPhase::gjk, NarrowPhase::fast};

/// A tet given as a unit corner tet, scaled and then moved.
struct Tet {
    vec3 v[4];
};

Tet corner_tet(float scale, vec3 offset) {
    return Tet{{offset, offset + vec3{scale, 0, 0}, offset + vec3{0, scale, 0}, offset + vec3{0, 0, scale}}};
}

Tet transformed(const Tet& t, float scale, vec3 offset) {
    Tet r;
    for (int i = 0; i < 4; ++i) r.v[i] = t.v[i] * scale + offset;
    return r;
}

/// Every test, in both argument orders, must give `expected`.
void expect_all(const Tet& a, const Tet& b, bool expected, const char* what) {
    for (NarrowPhase test : k_all_tests) {
        EXPECT_EQ(kdet::tets_intersect(test, a.v, b.v), expected) << what << " test=" << kdet::to_string(test);
        EXPECT_EQ(kdet::tets_intersect(test, b.v, a.v), expected)
            << what << " (swapped) test=" << kdet::to_string(test);
    }
}

class NarrowPhaseScale : public ::testing::TestWithParam<float> {};

TEST_P(NarrowPhaseScale, ObviousCases) {
    const float s = GetParam();
    const vec3 o{0.25f * s, -0.5f * s, 0.75f * s};
    const Tet a = corner_tet(s, o);
    expect_all(a, a, true, "identical");
    expect_all(a, corner_tet(s, o + vec3{3 * s, 0, 0}), false, "far apart along x");
    expect_all(a, corner_tet(s, o + vec3{2 * s, 2 * s, 2 * s}), false, "far apart diagonally");
    // Shares only vertex 1 of a: touching counts as intersecting.
    expect_all(a, corner_tet(s, o + vec3{s, 0, 0}), true, "shared vertex");
    // Shares the face x = 0 region only at the plane: b is the mirror image of a.
    const Tet mirror{{o, o + vec3{-s, 0, 0}, o + vec3{0, s, 0}, o + vec3{0, 0, s}}};
    expect_all(a, mirror, true, "shared face (mirror)");
    // A small tet strictly inside a.
    expect_all(a, transformed(corner_tet(1.0f, vec3{0, 0, 0}), 0.2f * s, o + vec3{0.1f * s, 0.1f * s, 0.1f * s}),
               true, "nested");
    // Overlapping but not nested.
    expect_all(a, corner_tet(s, o + vec3{0.3f * s, 0.3f * s, 0.1f * s}), true, "overlapping");
    // Mirror image pushed away by 1% of the size: separated by the face plane x = 0.
    const Tet pushed{{o + vec3{-0.01f * s, 0, 0}, o + vec3{-1.01f * s, 0, 0}, o + vec3{-0.01f * s, s, 0},
                      o + vec3{-0.01f * s, 0, s}}};
    expect_all(a, pushed, false, "face gap 1%");
}

INSTANTIATE_TEST_SUITE_P(Scales, NarrowPhaseScale, ::testing::Values(1.0f, 1e-3f, 1e-6f, 1e3f));

/// Two tets whose only separating axes are edge-edge cross products: the face-only test reports them,
/// the others do not.
TEST(NarrowPhase, EdgeEdgeSeparation) {
    // a: edge along x at z = 0, body below; b: edge along y at z = gap, body above.
    for (float s : {1.0f, 1e-6f}) {
        const float g = 0.01f * s;
        const Tet a{{vec3{-s, 0, 0}, vec3{s, 0, 0}, vec3{0, s, -s}, vec3{0, -s, -s}}};
        const Tet b{{vec3{0, -s, g}, vec3{0, s, g}, vec3{s, 0, g + s}, vec3{-s, 0, g + s}}};
        for (NarrowPhase test : k_all_tests) {
            const bool expected = test == NarrowPhase::sat_no_edges;
            EXPECT_EQ(kdet::tets_intersect(test, a.v, b.v), expected) << kdet::to_string(test) << " s=" << s;
            EXPECT_EQ(kdet::tets_intersect(test, b.v, a.v), expected) << kdet::to_string(test) << " s=" << s;
        }
        // Touching edge on edge.
        const Tet touching{{vec3{0, -s, 0}, vec3{0, s, 0}, vec3{s, 0, s}, vec3{-s, 0, s}}};
        expect_all(a, touching, true, "edge on edge");
    }
}

TEST(NarrowPhase, MtvOfOverlappingCopies) {
    const float r = 1.0f / std::sqrt(3.0f);
    for (float s : {1.0f, 1e-6f}) {
        const Tet a = corner_tet(s, vec3{0, 0, 0});
        // b's corner lies 0.1 s (along x + y + z) inside a's slanted face: the least overlap is
        // 0.1 s / sqrt(3) along the face normal (1, 1, 1) / sqrt(3).
        const Tet b = corner_tet(s, vec3{0.8f * s, 0.05f * s, 0.05f * s});
        float depth = -1.0f;
        vec3 direction{0, 0, 0};
        ASSERT_TRUE(kdet::tets_intersect_sat_mtv(a.v, b.v, depth, direction));
        EXPECT_NEAR(depth, 0.1f * r * s, 1e-5f * s);
        EXPECT_NEAR(direction.x, r, 1e-5f);
        EXPECT_NEAR(direction.y, r, 1e-5f);
        EXPECT_NEAR(direction.z, r, 1e-5f);
        // Swapped: b is now the fixed one, so a moves the other way.
        ASSERT_TRUE(kdet::tets_intersect_sat_mtv(b.v, a.v, depth, direction));
        EXPECT_NEAR(depth, 0.1f * r * s, 1e-5f * s);
        EXPECT_NEAR(direction.x, -r, 1e-5f);
    }
}

TEST(NarrowPhase, MtvNotWrittenWhenSeparated) {
    const Tet a = corner_tet(1.0f, vec3{0, 0, 0});
    const Tet b = corner_tet(1.0f, vec3{5, 0, 0});
    float depth = 42.0f;
    vec3 direction{7, 7, 7};
    EXPECT_FALSE(kdet::tets_intersect_sat_mtv(a.v, b.v, depth, direction));
    EXPECT_EQ(depth, 42.0f);
    EXPECT_EQ(direction.x, 7.0f);
}

TEST(NarrowPhase, MtvOfTouchingPairIsZero) {
    const Tet a = corner_tet(1.0f, vec3{0, 0, 0});
    const Tet b = corner_tet(1.0f, vec3{1, 0, 0});
    float depth = -1.0f;
    vec3 direction{0, 0, 0};
    ASSERT_TRUE(kdet::tets_intersect_sat_mtv(a.v, b.v, depth, direction));
    EXPECT_LE(depth, 1e-6f);
    EXPECT_GE(depth, 0.0f);
}

/// Orientation of the vertices must not matter (the face test flips normals against the opposite vertex).
TEST(NarrowPhase, VertexOrderDoesNotMatter) {
    const Tet a = corner_tet(1.0f, vec3{0, 0, 0});
    const Tet near_gap = corner_tet(1.0f, vec3{0.4f, 0.4f, 0.4f});   // x+y+z >= 1.2 for b: separated
    const Tet overlap = corner_tet(1.0f, vec3{0.2f, 0.2f, 0.2f});    // b's corner inside a
    const int orders[4][4] = {{0, 1, 2, 3}, {1, 0, 2, 3}, {3, 2, 0, 1}, {2, 3, 1, 0}};
    for (const auto& order : orders) {
        Tet pa, pg, po;
        for (int i = 0; i < 4; ++i) {
            pa.v[i] = a.v[order[i]];
            pg.v[i] = near_gap.v[order[i]];
            po.v[i] = overlap.v[order[i]];
        }
        expect_all(pa, pg, false, "permuted, separated");
        expect_all(pa, po, true, "permuted, overlapping");
    }
}

TEST(NarrowPhase, DegenerateInputs) {
    const vec3 p{1, 2, 3};
    const Tet point{{p, p, p, p}};
    const Tet other{{p + vec3{1, 0, 0}, p + vec3{1, 0, 0}, p + vec3{1, 0, 0}, p + vec3{1, 0, 0}}};
    expect_all(point, point, true, "same point");
    expect_all(point, other, false, "two points");
    // A flat tet (a triangle) lying on a face of a corner tet.
    const Tet a = corner_tet(1.0f, vec3{0, 0, 0});
    const Tet flat{{vec3{0.1f, 0.1f, 0}, vec3{0.5f, 0.1f, 0}, vec3{0.1f, 0.5f, 0}, vec3{0.2f, 0.2f, 0}}};
    for (NarrowPhase test : k_all_tests) EXPECT_TRUE(kdet::tets_intersect(test, a.v, flat.v)) << kdet::to_string(test);
}

} // namespace
