/// @file test_narrow_phase.cpp
/// @brief Obvious cases for every tetrahedron-tetrahedron test, at unit and tiny scales; the `exact`
/// test's arithmetic, its exact contacts at every float scale, and the pipeline's count of pairs
/// that reached its exact stage. The comparison against CGAL lives in tests/cgal.

#include <gtest/gtest.h>

#include <kdet/detector.hpp>

#include <cfloat>
#include <cmath>
#include <vector>

#include "geometry/tet_intersect.hpp"
#include "test_support.hpp"

namespace {

using kdet::Detector;
using kdet::DetectorOptions;
using kdet::FrameResult;
using kdet::Method;
using kdet::NarrowPhase;
using kdet::TetMesh;
using kdet::vec3;

constexpr NarrowPhase k_all_tests[] = {NarrowPhase::sat, NarrowPhase::sat_no_edges, NarrowPhase::sat_mtv,
                                       NarrowPhase::gjk, NarrowPhase::fast, NarrowPhase::exact};

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

// ---- The exact test ------------------------------------------------------------------------------------

/// Sign of det(p1 - p0, q1 - q0, r1 - r0) in long double for small integer inputs (exact there).
int reference_sign(vec3 p0, vec3 p1, vec3 q0, vec3 q1, vec3 r0, vec3 r1) {
    const long double p[3] = {p1.x - p0.x, p1.y - p0.y, p1.z - p0.z}, q[3] = {q1.x - q0.x, q1.y - q0.y, q1.z - q0.z},
                      r[3] = {r1.x - r0.x, r1.y - r0.y, r1.z - r0.z};
    const long double det = p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) +
                            p[2] * (q[0] * r[1] - q[1] * r[0]);
    return det > 0 ? 1 : (det < 0 ? -1 : 0);
}

TEST(ExactSum, SignsOfDeterminantsOfDifferences) {
    using kdet::exact::sign_det3_exact;
    using kdet::exact::sign_det2_exact;
    const vec3 o{0, 0, 0}, x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
    EXPECT_EQ(sign_det3_exact(o, x, o, y, o, z), 1);
    EXPECT_EQ(sign_det3_exact(o, y, o, x, o, z), -1);
    EXPECT_EQ(sign_det3_exact(o, x, o, x, o, z), 0);
    EXPECT_EQ(sign_det2_exact(o, x, o, y, 0, 1), 1);
    EXPECT_EQ(sign_det2_exact(o, x, o, y, 1, 0), -1);
    EXPECT_EQ(sign_det2_exact(o, x, x, o, 0, 1), 0);
    // Small integers: every determinant is exact in long double, so the signs must agree.
    std::uint32_t state = 12345;
    const auto next = [&] {
        state = state * 1664525u + 1013904223u;
        return static_cast<float>(static_cast<int>(state >> 27) - 16);
    };
    for (int n = 0; n < 20000; ++n) {
        vec3 v[6];
        for (vec3& p : v) p = vec3{next(), next(), next()};
        if (n % 3 == 0) v[5] = v[4] + (v[1] - v[0]) + (v[3] - v[2]); // r a sum of p and q: exactly 0
        EXPECT_EQ(sign_det3_exact(v[0], v[1], v[2], v[3], v[4], v[5]), reference_sign(v[0], v[1], v[2], v[3], v[4], v[5]));
    }
}

TEST(ExactSum, ExtremeFloats) {
    using kdet::exact::sign_det3_exact;
    const float big = FLT_MAX, tiny = 0x1p-149f, small = FLT_MIN;
    const vec3 o{0, 0, 0};
    // Rows whose differences overflow float (2 FLT_MAX), the smallest products, both at once.
    EXPECT_EQ(sign_det3_exact(vec3{-big, 0, 0}, vec3{big, 0, 0}, o, vec3{0, big, 0}, o, vec3{0, 0, -big}), -1);
    EXPECT_EQ(sign_det3_exact(o, vec3{tiny, 0, 0}, o, vec3{0, tiny, 0}, o, vec3{0, 0, tiny}), 1);
    EXPECT_EQ(sign_det3_exact(o, vec3{big, tiny, 0}, o, vec3{0, small, 0}, o, vec3{0, 0, tiny}), 1);
    // (1 - 2^-149) * 1 - 1 * 1: the difference 1 - 2^-149 has no double, the sign comes from its last bit.
    EXPECT_EQ(sign_det3_exact(vec3{tiny, 0, 0}, vec3{1, 1, 0}, o, vec3{1, 1, 0}, o, vec3{0, 0, 1}), -1);
    // big^3 - big^3 +- tiny^3: the tiny product decides, 1170 binary orders of magnitude below.
    for (int last : {-1, 0, 1}) {
        kdet::exact::ExactSum sum;
        sum.add_product(big, big, big, false);
        if (last != 0) sum.add_product(tiny, tiny, tiny, last < 0);
        sum.add_product(-big, big, big, false);
        EXPECT_EQ(sum.sign(), last);
    }
}

/// Tets touching exactly (a vertex inside a face, crossing edges, faces in one plane) at every power
/// of two that floats hold, translated by multiples of the size; then moved out of contact and into
/// overlap by 2^-20 of the size. The answers are known without an oracle: exact contact is touching.
TEST(ExactTest, ExactContactsAtEveryScale) {
    // Unit configurations, coordinates multiples of 1/4; the first tet is the corner tet, whose slanted
    // face lies in x + y + z = 1, and x + y = 1 is a plane through its edge (1,0,0)-(0,1,0).
    struct Contact {
        const char* name;
        vec3 b[4];
    };
    const Contact contacts[] = {
        {"vertex on face", {{0.25f, 0.25f, 0.5f}, {1.25f, 0.75f, 0.75f}, {0.5f, 1.25f, 0.75f}, {0.75f, 0.5f, 1.5f}}},
        {"edge on edge", {{0.5f, 0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}, {1.5f, 1.0f, 0.25f}, {1.0f, 1.5f, -0.25f}}},
        {"face on face", {{0.5f, 0.25f, 0.25f}, {0.25f, 0.5f, 0.25f}, {0.25f, 0.25f, 0.5f}, {1.0f, 1.0f, 1.0f}}},
    };
    const vec3 corner[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    int checked = 0;
    for (int exponent = -140; exponent <= 120; ++exponent) {
        const float s = std::ldexp(1.0f, exponent);
        for (const vec3 offset : {vec3{0, 0, 0}, vec3{3, -5, 7}})
            for (const Contact& c : contacts)
                for (int move = -1; move <= 1; ++move) {
                    // Moving along +x leaves the contact plane on the far side of the first tet.
                    const float step = static_cast<float>(move) * std::max(std::ldexp(s, -20), 0x1p-149f);
                    vec3 a[4], b[4];
                    for (int i = 0; i < 4; ++i) {
                        a[i] = (corner[i] + offset) * s;
                        b[i] = (c.b[i] + offset) * s + vec3{step, 0, 0};
                    }
                    const bool expected = move <= 0;
                    bool stage = false;
                    EXPECT_EQ(kdet::tets_intersect_exact(a, b, stage), expected) << c.name << " 2^" << exponent << " move " << move;
                    EXPECT_EQ(kdet::tets_intersect_exact(b, a, stage), expected) << c.name << " 2^" << exponent << " move " << move;
                    if (move == 0) {
                        EXPECT_TRUE(stage) << "a touching pair needs the exact stage";
                    }
                    ++checked;
                }
    }
    EXPECT_EQ(checked, 261 * 2 * 3 * 3);
}

TEST(ExactTest, ClearPairsStayInTheFloatFilter) {
    const Tet a = corner_tet(1.0f, vec3{0, 0, 0});
    const Tet b{{vec3{0.2f, 0.2f, 0.2f}, vec3{0.9f, 0.3f, 0.1f}, vec3{0.1f, 0.8f, 0.3f}, vec3{0.3f, 0.2f, 0.9f}}};
    bool stage = false;
    EXPECT_TRUE(kdet::tets_intersect_exact(a.v, b.v, stage));
    EXPECT_FALSE(kdet::tets_intersect_exact(a.v, transformed(b, 1.0f, vec3{0.6f, 0.1f, 0.0f}).v, stage));
    EXPECT_FALSE(stage);
    EXPECT_TRUE(kdet::tets_intersect_exact(a.v, corner_tet(1.0f, vec3{1, 0, 0}).v, stage)); // shared vertex
    EXPECT_TRUE(stage);
}

/// Flat tets in the plane z = 0 touching at a point of an edge, the first tet's first vertex (the exact
/// test's origin) about 2^-45 from the origin, with bits down to 2^-60: differences to it need more
/// bits than a double holds, and round differently in each binade, so the plane test's double bound is
/// what keeps touching from reading as apart. Moved by one unit across the edge, the pair separates or
/// overlaps.
TEST(ExactTest, CoplanarContactsAgainstATinyOrigin) {
    std::uint32_t state = 2024;
    const auto integer = [&](int lo, int hi) {
        state = state * 1664525u + 1013904223u;
        return lo + static_cast<int>((state >> 8) % static_cast<std::uint32_t>(hi - lo + 1));
    };
    const auto at = [](long long x, long long y, int exponent) {
        return vec3{std::ldexp(static_cast<float>(x), exponent), std::ldexp(static_cast<float>(y), exponent), 0.0f};
    };
    int checked = 0;
    while (checked < 3000) {
        // Edge p q of the first tet, its origin side; the second tet on the other side, touching at m.
        const long long px = 2 * integer(-1000, 1000), py = 2 * integer(-1000, 1000);
        const long long qx = 2 * integer(-1000, 1000), qy = 2 * integer(-1000, 1000);
        const long long nx = qy - py, ny = px - qx; // normal of the edge
        const long long origin_side = -(nx * px + ny * py); // n . (0 - p)
        if (origin_side == 0) continue;
        const long long sign = origin_side > 0 ? -1 : 1; // toward the far side
        const long long mx = (px + qx) / 2, my = (py + qy) / 2;
        long long w[2][2];
        for (auto& v : w)
            do {
                v[0] = integer(-1000, 1000);
                v[1] = integer(-1000, 1000);
            } while (sign * (nx * v[0] + ny * v[1]) <= 0);
        if (w[0][0] * w[1][1] - w[0][1] * w[1][0] == 0) continue;
        const long long step_x = std::llabs(nx) >= std::llabs(ny) ? sign * (nx > 0 ? 1 : -1) : 0;
        const long long step_y = step_x == 0 ? sign * (ny > 0 ? 1 : -1) : 0;
        for (int move = -1; move <= 1; ++move) {
            const vec3 a[4] = {at(integer(-32768, 32768), integer(-32768, 32768), -60), at(px, py, -10), at(qx, qy, -10),
                               at(px, py, -10)};
            vec3 b[4] = {at(mx, my, -10), at(mx + w[0][0], my + w[0][1], -10), at(mx + w[1][0], my + w[1][1], -10),
                         at(mx, my, -10)};
            for (vec3& v : b) v = v + at(move * step_x, move * step_y, -10);
            const bool expected = move <= 0;
            EXPECT_EQ(kdet::tets_intersect_exact(a, b), expected) << checked << " move " << move;
            EXPECT_EQ(kdet::tets_intersect_exact(b, a), expected) << checked << " move " << move;
        }
        ++checked;
    }
}

/// Zero-volume tets, with answers known by construction.
TEST(ExactTest, DegenerateTets) {
    const auto tet = [](vec3 p, vec3 q, vec3 r, vec3 t) { return Tet{{p, q, r, t}}; };
    const vec3 o{0, 0, 0};
    // Two triangles in the plane z = 0 side by side: touching along the hypotenuse, apart, overlapping.
    const Tet left = tet(o, vec3{1, 0, 0}, vec3{0, 1, 0}, vec3{0.25f, 0.25f, 0});
    for (const float gap : {0.0f, 0x1p-23f, -0x1p-23f}) {
        const Tet right = tet(vec3{1 + gap, 0, 0}, vec3{gap, 1, 0}, vec3{1 + gap, 1, 0}, vec3{1 + gap, 1, 0});
        EXPECT_EQ(kdet::tets_intersect_exact(left.v, right.v), gap <= 0) << gap;
        EXPECT_EQ(kdet::tets_intersect_exact(right.v, left.v), gap <= 0) << gap;
    }
    // The same triangle in the parallel plane z = 2^-30: apart.
    const Tet lifted = tet(vec3{0, 0, 0x1p-30f}, vec3{1, 0, 0x1p-30f}, vec3{0, 1, 0x1p-30f}, vec3{0, 1, 0x1p-30f});
    EXPECT_FALSE(kdet::tets_intersect_exact(left.v, lifted.v));
    // Collinear segments on the x axis: end to end, overlapping, apart; and parallel lines.
    const Tet segment = tet(o, vec3{1, 0, 0}, vec3{0.5f, 0, 0}, o);
    EXPECT_TRUE(kdet::tets_intersect_exact(segment.v, tet(vec3{1, 0, 0}, vec3{2, 0, 0}, vec3{2, 0, 0}, vec3{1, 0, 0}).v));
    EXPECT_TRUE(kdet::tets_intersect_exact(segment.v, tet(vec3{0.75f, 0, 0}, vec3{3, 0, 0}, vec3{3, 0, 0}, vec3{3, 0, 0}).v));
    EXPECT_FALSE(kdet::tets_intersect_exact(segment.v, tet(vec3{1.0f + 0x1p-23f, 0, 0}, vec3{3, 0, 0}, vec3{3, 0, 0}, vec3{3, 0, 0}).v));
    EXPECT_FALSE(kdet::tets_intersect_exact(segment.v, tet(vec3{0, 0x1p-40f, 0}, vec3{1, 0x1p-40f, 0}, vec3{1, 0x1p-40f, 0}, vec3{1, 0x1p-40f, 0}).v));
    // A segment crossing a triangle's edge in its plane, and one just missing its vertex.
    EXPECT_TRUE(kdet::tets_intersect_exact(left.v, tet(vec3{0.5f, -1, 0}, vec3{0.5f, 1, 0}, vec3{0.5f, 1, 0}, vec3{0.5f, 1, 0}).v));
    EXPECT_FALSE(kdet::tets_intersect_exact(left.v, tet(vec3{1.0f + 0x1p-23f, -1, 0}, vec3{1.0f + 0x1p-23f, 1, 0}, vec3{1.0f + 0x1p-23f, 1, 0}, vec3{1.0f + 0x1p-23f, 1, 0}).v));
    // Points: on an edge, at a vertex, just outside, and two points.
    const auto point = [&](vec3 p) { return tet(p, p, p, p); };
    const Tet solid = corner_tet(1.0f, o);
    EXPECT_TRUE(kdet::tets_intersect_exact(solid.v, point(vec3{0.5f, 0.5f, 0}).v));
    EXPECT_TRUE(kdet::tets_intersect_exact(point(vec3{0, 0, 1}).v, solid.v));
    EXPECT_FALSE(kdet::tets_intersect_exact(solid.v, point(vec3{0.5f, 0.5f + 0x1p-24f, 0}).v));
    EXPECT_TRUE(kdet::tets_intersect_exact(point(vec3{1, 2, 3}).v, point(vec3{1, 2, 3}).v));
    EXPECT_FALSE(kdet::tets_intersect_exact(point(vec3{1, 2, 3}).v, point(vec3{1, 2, 3.0000005f}).v));
}

/// The pipeline counts the pairs that reached the exact stage: the same count for every method that
/// runs the test once per candidate, none for the other tests. A mesh against an identical copy has
/// touching pairs everywhere (each tet's copy and its neighbours' copies).
TEST(ExactTest, PipelineCountsPairsThatReachedTheExactStage) {
    const TetMesh mesh = kdet::test::random_soup(400, 2.0, 1.0, 7);
    const auto count = [&](Method method, NarrowPhase test) {
        DetectorOptions options;
        options.method = method;
        options.narrow_phase = test;
        Detector detector(options);
        detector.add_object(mesh);
        detector.add_object(mesh);
        const FrameResult& r = detector.detect();
        return r.counts.exact_stage_pairs;
    };
    const std::uint64_t kdet_count = count(Method::kdet, NarrowPhase::exact);
    EXPECT_GE(kdet_count, mesh.num_tets());
    EXPECT_EQ(count(Method::brute_force_loop, NarrowPhase::exact), kdet_count);
    EXPECT_EQ(count(Method::brute_force_pairs, NarrowPhase::exact), kdet_count);
    EXPECT_GT(count(Method::kdet_no_pairs, NarrowPhase::exact), 0u);
    EXPECT_EQ(count(Method::kdet, NarrowPhase::sat), 0u);
}

/// Zero-volume tets (which only ReadOptions::allow_degenerate lets in from files) go through the whole
/// pipeline and are decided exactly: a flat tet touched at one interior point by a solid tet, and a
/// collinear tet touched at one point, collide; the same solid tets moved 2^-20 away do not, although
/// that gap is below the float tests' tolerance (sat still reports them).
TEST(ExactTest, PipelineDecidesZeroVolumeTetsExactly) {
    const auto one_tet = [](std::vector<double> xyz) {
        TetMesh mesh;
        mesh.positions = std::move(xyz);
        mesh.tets = {0, 1, 2, 3};
        return mesh;
    };
    const auto moved = [](TetMesh mesh, int axis, double by) {
        for (std::size_t v = 0; v < mesh.num_vertices(); ++v) mesh.positions[3 * v + axis] += by;
        return mesh;
    };
    const auto pairs = [](const TetMesh& a, const TetMesh& b, NarrowPhase test) {
        DetectorOptions options;
        options.narrow_phase = test;
        return kdet::collide(a, b, options).size();
    };
    const double gap = std::ldexp(1.0, -20);
    // In the plane x + y + z = 1, and a tet on its side of the plane with one vertex in the flat tet.
    const TetMesh flat = one_tet({1, 0, 0, 0, 1, 0, 0, 0, 1, 0.25, 0.25, 0.5});
    const TetMesh on_flat = one_tet({0.5, 0.25, 0.25, 1.5, 0.25, 0.25, 0.5, 1.25, 0.25, 0.5, 0.25, 1.25});
    const TetMesh line = one_tet({0, 0, 0, 1, 1, 1, 0.5, 0.5, 0.5, 0.25, 0.25, 0.25});
    const TetMesh on_line = one_tet({0.75, 0.75, 0.75, 1.75, 0.75, 0.75, 0.75, 1.75, 0.75, 0.75, 0.75, -0.25});
    EXPECT_EQ(pairs(flat, on_flat, NarrowPhase::exact), 1u);
    EXPECT_EQ(pairs(flat, moved(on_flat, 0, gap), NarrowPhase::exact), 0u);
    EXPECT_EQ(pairs(flat, moved(on_flat, 0, gap), NarrowPhase::sat), 1u);
    EXPECT_EQ(pairs(line, on_line, NarrowPhase::exact), 1u);
    EXPECT_EQ(pairs(line, moved(on_line, 0, gap), NarrowPhase::exact), 0u);
    EXPECT_EQ(pairs(line, moved(on_line, 0, gap), NarrowPhase::sat), 1u);
    EXPECT_EQ(pairs(flat, line, NarrowPhase::exact), 1u); // the line crosses the plane at (1, 1, 1) / 3
}

} // namespace
