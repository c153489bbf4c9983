/// @file static_order.cpp
/// @brief static_last: the storage order that puts static objects' tets behind the moving ones.

#include "pipeline/pipeline_base.hpp"

namespace kdet {

SceneTopology static_last(const SceneTopology& topology, std::uint32_t& moving_tets) {
    SceneTopology ordered = topology;
    const std::size_t objects = topology.object_tet_begin.empty() ? 0 : topology.object_tet_begin.size() - 1;
    std::size_t next = 0;
    for (int statics = 0; statics < 2; ++statics) {
        if (statics == 1) moving_tets = static_cast<std::uint32_t>(next);
        for (std::size_t o = 0; o < objects; ++o) {
            if ((topology.object_static[o] != 0) != (statics == 1)) continue;
            for (std::uint32_t t = topology.object_tet_begin[o]; t < topology.object_tet_begin[o + 1]; ++t, ++next) {
                ordered.tets[next] = topology.tets[t];
                ordered.tet_object[next] = topology.tet_object[t];
                ordered.tet_user_id[next] = topology.tet_user_id[t];
            }
        }
    }
    if (objects == 0) moving_tets = 0;
    return ordered;
}

} // namespace kdet
