#include "exact_check.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <array>
#include <iterator>

namespace kdet::cli {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;

std::array<Point, 4> tet_points(const TetMesh& mesh, std::uint32_t tet) {
    std::array<Point, 4> p;
    for (int k = 0; k < 4; ++k) {
        const double* v = &mesh.positions[3 * std::size_t{mesh.tets[4 * std::size_t{tet} + k]}];
        // The detector computes on float32; judge the same coordinates.
        p[k] = Point(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]));
    }
    return p;
}

// Out of line: inlined into surrounding arithmetic, CGAL's rounding-mode switches were seen to be
// undermined by the optimiser (see docs/narrow-phase.md).
[[gnu::noinline]] bool is_flat(const std::array<Point, 4>& p) {
    return CGAL::orientation(p[0], p[1], p[2], p[3]) == CGAL::COPLANAR;
}

[[gnu::noinline]] bool exactly_intersect(const std::array<Point, 4>& a, const std::array<Point, 4>& b) {
    return CGAL::do_intersect(Kernel::Tetrahedron_3(a[0], a[1], a[2], a[3]),
                              Kernel::Tetrahedron_3(b[0], b[1], b[2], b[3]));
}

} // namespace

bool exact_check_available(std::string*) { return true; }

ExactReport check_exact(const TetMesh& a, const TetMesh* b, const std::vector<IndexPair>& reported,
                        const DetectorOptions& options) {
    DetectorOptions superset_options = options;
    superset_options.narrow_phase = NarrowPhase::sat_no_edges;
    superset_options.method = Method::kdet;
    superset_options.contacts = false;
    const std::vector<IndexPair> superset = b ? collide(a, *b, superset_options) : collide_self(a, superset_options);

    std::vector<IndexPair> judged;
    std::set_union(superset.begin(), superset.end(), reported.begin(), reported.end(), std::back_inserter(judged));
    const TetMesh& second = b ? *b : a;
    ExactReport report;
    std::vector<IndexPair> truth, unjudgeable;
    for (const IndexPair& pair : judged) {
        const auto p = tet_points(a, pair.first), q = tet_points(second, pair.second);
        if (is_flat(p) || is_flat(q)) {
            unjudgeable.push_back(pair);
            continue;
        }
        if (exactly_intersect(p, q)) truth.push_back(pair);
    }
    report.skipped_degenerate = unjudgeable.size();
    report.pairs_checked = judged.size() - unjudgeable.size();
    report.true_pairs = truth.size();
    std::vector<IndexPair> reported_judgeable;
    std::set_difference(reported.begin(), reported.end(), unjudgeable.begin(), unjudgeable.end(),
                        std::back_inserter(reported_judgeable));
    std::set_difference(reported_judgeable.begin(), reported_judgeable.end(), truth.begin(), truth.end(),
                        std::back_inserter(report.false_positives));
    std::set_difference(truth.begin(), truth.end(), reported.begin(), reported.end(),
                        std::back_inserter(report.false_negatives));
    return report;
}

} // namespace kdet::cli
