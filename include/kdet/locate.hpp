#pragma once
/// @file locate.hpp
/// @brief Point location: for each query point, every tet whose closed set holds it, with its
/// barycentric coordinates; optionally the nearest tet within a distance for the points no tet holds.
///
/// Containment is decided exactly for the float32 coordinates of the points and the vertices (exact
/// orientation predicates: a point on a face, edge or vertex shared by several tets gets each of
/// them). Barycentric coordinates, closest points and distances are computed in double
/// (docs/point-location.md gives their error bounds).

#include <kdet/detector.hpp>
#include <kdet/mesh.hpp>
#include <kdet/options.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace kdet {

/// @brief Detector::locate() over every object.
constexpr ObjectId all_objects = 0xffffffffu;

/// @brief How a point location runs.
struct LocateOptions {
    /// A point that no tet holds gets the nearest tet at distance at most `within` (its distance, the
    /// closest point and that point's barycentric coordinates); beyond it, nothing. 0: only the tets
    /// that hold the point. Must be finite and not negative.
    double within = 0.0;
    /// Copy the results to the host (LocateResult); otherwise only Detector::device_locate_results()
    /// holds them (and LocateResult only its counts).
    bool results_to_host = true;
};

/// @brief What a point location found, as compressed rows: the hits of point p are the entries
/// [offsets[p], offsets[p + 1]) of the per-hit arrays, sorted by object and tet.
struct LocateResult {
    std::vector<std::uint64_t> offsets;     ///< [points + 1]
    std::vector<std::uint32_t> objects;     ///< per hit: the object
    std::vector<std::uint32_t> tets;        ///< per hit: the tet's index in its object (the caller's order)
    std::vector<double> barycentrics;       ///< 4 per hit: of the point (or of the closest point) in the tet
    std::vector<double> closest_points;     ///< 3 per hit: the point itself when the tet holds it
    std::vector<double> distances;          ///< per hit: 0 when the tet holds the point
    std::size_t point_count = 0;
    std::size_t hit_count = 0;
};

/// @brief A point location's results where the backend keeps them (GPU memory for Backend::cuda),
/// the same arrays as LocateResult; valid until the next locate() of that detector.
struct DeviceLocateResults {
    const std::uint64_t* offsets = nullptr;
    const std::uint32_t* objects = nullptr;
    const std::uint32_t* tets = nullptr;
    const double* barycentrics = nullptr;
    const double* closest_points = nullptr;
    const double* distances = nullptr;
    std::size_t point_count = 0;
    std::size_t hit_count = 0;
};

/// @brief One-off point location in one mesh: `points` are x y z per point (float or double; any
/// layout through PositionsView), located as float32. Objects are all 0. Throws kdet::Error on a
/// non-finite point, a negative or non-finite `within`, a bad mesh (as Detector::add_object), or
/// `results_to_host = false` (whose device arrays would end with the one-off's detector).
LocateResult locate(const TetMesh& mesh, const PositionsView& points, const LocateOptions& options = {},
                    const DetectorOptions& detector_options = {});
LocateResult locate(const TetMesh& mesh, const std::vector<double>& xyz, const LocateOptions& options = {},
                    const DetectorOptions& detector_options = {});

} // namespace kdet
