#pragma once
/// @file exact_check.hpp
/// @brief `kdet collide --check-exact`: how right the chosen narrow-phase test is on the user's own
/// meshes, against CGAL's exact predicates. CGAL stays out of the kdet library: only this tool part uses it.

#include <kdet/detector.hpp>
#include <kdet/mesh.hpp>

#include <string>
#include <vector>

namespace kdet::cli {

/// @brief The chosen test's pairs compared with the exact answer.
struct ExactReport {
    std::size_t pairs_checked = 0;  ///< pairs judged exactly
    std::size_t true_pairs = 0;     ///< pairs that really intersect (closed sets)
    std::size_t skipped_degenerate = 0; ///< pairs with a zero-volume tet, which CGAL cannot judge
    std::vector<IndexPair> false_positives; ///< reported, but separated
    std::vector<IndexPair> false_negatives; ///< intersecting, but not reported
};

/// @brief True when the tool was built with CGAL; otherwise `reason` says so.
bool exact_check_available(std::string* reason);

/// @brief Judges `reported` (pairs of a and b, or inside a when b is null) exactly. The exact answer
/// is computed on the pairs that `sat_no_edges` reports (a superset of the true pairs: its zero
/// false negatives against CGAL are asserted in the tests) together with the reported pairs, on the
/// float coordinates the detector sees.
ExactReport check_exact(const TetMesh& a, const TetMesh* b, const std::vector<IndexPair>& reported,
                        const DetectorOptions& options);

} // namespace kdet::cli
