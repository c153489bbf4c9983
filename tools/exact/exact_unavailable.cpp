#include "exact_check.hpp"

#include <kdet/error.hpp>

namespace kdet::cli {

bool exact_check_available(std::string* reason) {
    if (reason) *reason = "kdet was built without CGAL (install libcgal-dev and reconfigure)";
    return false;
}

ExactReport check_exact(const TetMesh&, const TetMesh*, const std::vector<IndexPair>&, const DetectorOptions&) {
    std::string reason;
    exact_check_available(&reason);
    throw Error("--check-exact is not available: " + reason);
}

} // namespace kdet::cli
