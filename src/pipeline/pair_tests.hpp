#pragma once
/// @file pair_tests.hpp
/// @brief The decisions on a pair of stored tets that the grid's search, the narrow phase and the
/// baselines share: adjacency and boxes, the pre-test, the narrow phase's test. None of them decides
/// the margin: the pairs they find apart go to NearPairsKernel (near_pairs.hpp), which alone holds
/// that decision, so that it is compiled once and not into every test's kernels.

#include "geometry/face_planes.hpp"
#include "geometry/slabs.hpp"
#include "geometry/tet_intersect.hpp"
#include "pipeline/pair_exclusions.hpp"
#include "pipeline/scene_view.hpp"

#include <kdet/options.hpp>

#include <cstdint>

namespace kdet {

/// @brief The narrow-phase test alone on stored tets first < second: the lower stored
/// id goes first, so every method sees the same floating-point computation. `exact_stage` is set when
/// the pair reached the exact stage of NarrowPhase::exact. `after_pretest`: see tets_intersect_as.
template <NarrowPhase Test>
KDET_HD inline bool test_pair(const SceneView& s, std::uint32_t first, std::uint32_t second, bool& exact_stage,
                              bool after_pretest = false) {
    vec3 a[4], b[4];
    load_tet(s, first, a);
    load_tet(s, second, b);
    return tets_intersect_as<Test>(a, b, exact_stage, after_pretest);
}

/// @brief The decision for a grid method's pair (first < second) whose boxes overlap, that is not
/// adjacent and that the slabs did not separate: the face planes' verdict where they are sure (the
/// answer the test gives, see face_planes.hpp), else the test. `planes_separate` is set when the
/// planes proved the pair apart, farther than the scene's margin.
template <NarrowPhase Test>
KDET_HD inline bool planes_or_test_collide(const SceneView& s, std::uint32_t first, std::uint32_t second,
                                           bool& exact_stage, bool& planes_separate) {
    // Both tets' planes and the vertices beside them are this frame's.
    const TetPlanes &pa = s.planes[first], &pb = s.planes[second];
    const PlaneVerdict verdict = face_plane_pretest(pa, pa.vertex, pb, pb.vertex, false, s.margin);
    planes_separate = verdict == PlaneVerdict::separated;
    if (verdict != PlaneVerdict::unsure) return verdict == PlaneVerdict::intersecting;
    return tets_intersect_as<Test>(pa.vertex, pb.vertex, exact_stage, true);
}

/// @brief The decision for a grid method's pair whose boxes overlap and that is not adjacent (first <
/// second): the pre-test where it is sure (the slabs where the scene has them, then the face planes;
/// see slabs.hpp), else the test.
template <NarrowPhase Test>
KDET_HD inline bool candidate_collides(const SceneView& s, std::uint32_t first, std::uint32_t second,
                                       bool& exact_stage) {
    if (s.slabs && slabs_separate(s.slabs[first], s.slabs[second])) return false;
    bool planes_separate = false;
    return planes_or_test_collide<Test>(s, first, second, exact_stage, planes_separate);
}

/// @brief Whether a pair of stored tets first < second needs a decision at all: not adjacent, not
/// excluded (pair_exclusions.hpp), and their boxes overlap.
KDET_HD inline bool may_collide(const SceneView& s, std::uint32_t first, std::uint32_t second) {
    if (s.tet_object[first] == s.tet_object[second] && share_vertex(s.tets[first], s.tets[second])) return false;
    if (excluded_pair(s, first, second)) return false;
    return boxes_overlap(s.info[first].box, s.info[second].box);
}

} // namespace kdet
