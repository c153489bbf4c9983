#pragma once
/// @file spatial_order.hpp
/// @brief The order in which the pipeline stores an object's tets: close in space, close in memory.
///
/// Meshes often list their tets in no spatial order (TetGen's output puts consecutive tets far apart
/// in the model). The grid stages gather the data of a tet's neighbours, so storing neighbours next
/// to each other turns most of those gathers into cache hits. The order is computed once, when the
/// object is added; a deforming mesh keeps its neighbours, so the order stays good. The vertices
/// follow the tets (SceneTopology::add_object).

#include "geometry/vec3.hpp"

#include <cstdint>
#include <vector>

namespace kdet {

/// @brief Tet indices sorted by the Morton code of the tet's centroid within the box of all centroids
/// (10 bits per axis), ties by index. A permutation of 0 .. tet_count-1, the same on any number of
/// `threads` (a one-off query on a large mesh computes it on the detector's threads).
std::vector<std::uint32_t> spatial_tet_order(const vec3* positions, const std::uint32_t* tets, std::size_t tet_count,
                                             int threads = 1);

} // namespace kdet
