#include "pipeline/gather_positions.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/locate.hpp>

#include <string>

namespace kdet {

LocateResult locate(const TetMesh& mesh, const std::vector<double>& xyz, const LocateOptions& options,
                    const DetectorOptions& detector_options) {
    if (xyz.size() % 3 != 0)
        throw Error("locate: " + std::to_string(xyz.size()) + " coordinates are not x y z per point");
    return locate(mesh, xyz_view(xyz.data(), xyz.size() / 3), options, detector_options);
}

} // namespace kdet
