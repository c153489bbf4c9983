#pragma once
/// @file tet_intersect.hpp
/// @brief The tetrahedron-tetrahedron tests of the narrow phase, callable from host and device code.
///
/// Common contract of every test:
/// - closed sets: tets that only touch (a shared vertex, edge or face, a vertex on a face) intersect;
/// - a pure, deterministic function of the 8 float points (the pipeline passes the lower id first);
/// - all tolerances are relative to the longest edge of the pair, never absolute: each test moves the
///   pair to a frame with origin at a[0] and longest edge 1;
/// - a separation is reported only when proven by a gap above 32 float epsilons (relative), so an
///   intersecting pair is never missed; pairs closer than that count as intersecting. The `exact` test
///   has no tolerance: it answers exactly for the float points it is given;
/// - no exceptions, no allocation, no static state.

#include <kdet/options.hpp>

#include "geometry/exact_test.hpp"
#include "geometry/gjk.hpp"
#include "geometry/gpr.hpp"
#include "geometry/sat.hpp"

#include <type_traits>

namespace kdet {

/// @brief Separating axis test over the 44 axes (4 + 4 face normals, 36 edge cross products).
/// Edge pairs within sqrt(eps) of parallel are skipped (they add no usable axis).
/// `edges_first`: see narrow::sat_separates (the same answer, sooner after the face-plane pre-test).
KDET_HD inline bool tets_intersect_sat(const vec3 a[4], const vec3 b[4], bool edges_first = false) {
    return narrow::sat_intersect(a, b, true, edges_first);
}

/// @brief Face normals only (8 axes). Conservative: never misses an intersecting pair, but may report
/// pairs that only an edge-edge axis separates.
KDET_HD inline bool tets_intersect_sat_no_edges(const vec3 a[4], const vec3 b[4]) {
    return narrow::sat_intersect(a, b, false);
}

/// @brief 44-axis SAT that also returns the minimum translation vector (MTV).
///
/// Convention: translating the SECOND tet b by depth * direction separates the pair (up to touching).
/// direction is a unit vector along the axis of least overlap, oriented from the projections (b moves
/// the shorter way out), never from centroids; depth >= 0 is that overlap in input units, 0 for
/// touching pairs. Face axes win near-ties (within the tolerance) over edge axes, so the direction
/// is stable under small motions. depth and direction are written only when the function returns
/// true; for degenerate pairs with no usable axis (parallel segments, points) they are 0 and (0,0,0).
KDET_HD inline bool tets_intersect_sat_mtv(const vec3 a[4], const vec3 b[4], float& depth, vec3& direction) {
    return narrow::sat_mtv_intersect(a, b, depth, direction);
}

/// @brief GJK on the Minkowski difference with the signed-volumes distance sub-algorithm (Montanari
/// et al. 2017), in the unit-size frame, with capped iterations; a separation is certified by the
/// projection gap along GJK's direction, and the rare pair whose direction cannot certify the
/// distance GJK found (rounding on pairs much closer than their size) is decided by the SAT axes.
KDET_HD inline bool tets_intersect_gjk(const vec3 a[4], const vec3 b[4]) { return narrow::gjk_intersect(a, b); }

/// @brief Face-plane test in the style of Ganovelli, Ponchio and Rocchini (2002): the 16 + 16
/// vertex-to-face-plane distances decide the face axes, and the edge axes are decided from the same
/// distances, two faces at a time. Each face normal is oriented against the opposite vertex, so the
/// vertex order does not matter. An edge it cannot decide within the tolerance (sharp edges amplify
/// rounding) is decided by that edge's 6 SAT axes; a tet too flat to orient sends the pair to the SAT.
KDET_HD inline bool tets_intersect_fast(const vec3 a[4], const vec3 b[4]) { return narrow::gpr_intersect(a, b); }

/// @brief Exact: true iff the closed tets share a point, for the float coordinates given (CGAL's
/// do_intersect with exact predicates gives the same answer), zero-volume tets included. A float
/// separating-axis test with proven error bounds decides almost every pair; the rest go to an exact
/// stage (exact_test.hpp), and then `exact_stage` is set to true (it is never cleared). The default test.
/// `edges_first`: see narrow::exact_intersect (the same answer, sooner after the face-plane pre-test).
KDET_HD inline bool tets_intersect_exact(const vec3 a[4], const vec3 b[4], bool& exact_stage, bool edges_first = false) {
    return narrow::exact_intersect(a, b, exact_stage, edges_first);
}
KDET_HD inline bool tets_intersect_exact(const vec3 a[4], const vec3 b[4]) {
    bool exact_stage = false;
    return narrow::exact_intersect(a, b, exact_stage);
}

/// @brief The test `Test`, chosen at compile time, so that a kernel instantiated for one test holds
/// only that test's code (registers and stack are those of the test in use); `exact_stage` as for
/// tets_intersect_exact (only that test has an exact stage). `after_pretest`: the pair is one the
/// face-plane pre-test left undecided, so the tests that can take it run their edge axes first.
template <NarrowPhase Test>
KDET_HD inline bool tets_intersect_as(const vec3 a[4], const vec3 b[4], bool& exact_stage, bool after_pretest = false) {
    if constexpr (Test == NarrowPhase::exact) {
        return tets_intersect_exact(a, b, exact_stage, after_pretest);
    } else if constexpr (Test == NarrowPhase::sat_no_edges) {
        return tets_intersect_sat_no_edges(a, b);
    } else if constexpr (Test == NarrowPhase::sat_mtv) {
        // Only the verdict counts here; the contact stage computes depth and direction when
        // DetectorOptions::contacts is on, for every test alike.
        float depth;
        vec3 direction;
        return tets_intersect_sat_mtv(a, b, depth, direction);
    } else if constexpr (Test == NarrowPhase::gjk) {
        return tets_intersect_gjk(a, b);
    } else if constexpr (Test == NarrowPhase::fast) {
        return tets_intersect_fast(a, b);
    } else {
        static_assert(Test == NarrowPhase::sat, "every NarrowPhase has its test");
        return tets_intersect_sat(a, b, after_pretest);
    }
}

/// @brief Calls `f` with std::integral_constant<NarrowPhase, test>: turns a test chosen at run time
/// into one chosen at compile time, once per launch instead of once per pair.
template <class F>
KDET_HD inline decltype(auto) with_narrow_phase(NarrowPhase test, F&& f) {
    switch (test) {
    case NarrowPhase::exact:
        return f(std::integral_constant<NarrowPhase, NarrowPhase::exact>{});
    case NarrowPhase::sat_no_edges:
        return f(std::integral_constant<NarrowPhase, NarrowPhase::sat_no_edges>{});
    case NarrowPhase::sat_mtv:
        return f(std::integral_constant<NarrowPhase, NarrowPhase::sat_mtv>{});
    case NarrowPhase::gjk:
        return f(std::integral_constant<NarrowPhase, NarrowPhase::gjk>{});
    case NarrowPhase::fast:
        return f(std::integral_constant<NarrowPhase, NarrowPhase::fast>{});
    case NarrowPhase::sat:
        break;
    }
    return f(std::integral_constant<NarrowPhase, NarrowPhase::sat>{});
}

/// @brief Runs the test selected by `test` (for code that tests a few pairs; kernels take the test
/// as a template argument); `exact_stage` as for tets_intersect_exact.
KDET_HD inline bool tets_intersect(NarrowPhase test, const vec3 a[4], const vec3 b[4], bool& exact_stage) {
    return with_narrow_phase(test, [&](auto chosen) { return tets_intersect_as<decltype(chosen)::value>(a, b, exact_stage); });
}
KDET_HD inline bool tets_intersect(NarrowPhase test, const vec3 a[4], const vec3 b[4]) {
    bool exact_stage = false;
    return tets_intersect(test, a, b, exact_stage);
}

} // namespace kdet
