#pragma once
/// @file prepare_pipeline.hpp
/// @brief From a triangle surface to a tet mesh of a requested size: alpha wrapping (CGAL), then
/// TetGen -pq; and the cache of the thesis models built that way.

#include <kdet/mesh.hpp>
#include <kdet/prepare.hpp>

#include <cstddef>
#include <ostream>
#include <string>

namespace kdet::prepare {

/// @brief How close the searches get: they stop once within `aim` of the target and fail beyond
/// `tolerance` (both relative).
struct SearchLimits {
    double aim = 0.03;
    double tolerance = 0.10;
    int max_wraps = 12;
};

/// @brief A tet mesh of about a requested size and how it was found.
struct SizedMesh {
    TetMesh mesh;
    double alpha = 0.0;  ///< alpha of the wrap that made it, relative to the surface's box diagonal
    int wraps = 0;       ///< wrap + TetGen runs the search took
};

/// @brief Closes @p surface by alpha wrapping and tetrahedralizes it with TetGen -pq, searching
/// alpha until the tet count is within `limits.aim` of @p target_tets (or the closest one found
/// within `limits.tolerance`). @p work_dir holds TetGen's files while it runs. The offset of the wrap
/// is alpha / 30. Deterministic. Throws kdet::Error when TetGen is missing or fails, or when no
/// alpha tried lands within the tolerance; @p log (may be null) gets one line per try.
SizedMesh tetrahedralize(const TriangleMesh& surface, std::size_t target_tets, const std::string& work_dir,
                         const SearchLimits& limits = {}, std::ostream* log = nullptr);

/// @brief The TetGen program on PATH; throws kdet::Error naming the Debian package when there is none.
std::string find_tetgen();

/// @brief Moves @p surface so its bounding box is centred at the origin and scales it so the box's
/// largest extent is 1: the size the scene files are written for.
void normalize(TriangleMesh& surface);

/// @brief What prepare_model did.
struct Prepared {
    PreparedRecord record;
    bool built = false;  ///< false: it was already in the cache
    int wraps = 0;
};

/// @brief Makes sure the cache holds @p model at @p resolution for its current source surface and
/// tools, building it (normalize, then tetrahedralize to Table 5.2's count) unless it is there and
/// @p force is false.
Prepared prepare_model(const ModelInfo& model, int resolution, bool force, std::ostream* log = nullptr);

} // namespace kdet::prepare
