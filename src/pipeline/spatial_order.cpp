#include "pipeline/spatial_order.hpp"

#include "exec/radix_sort.hpp"
#include "pipeline/pipeline_base.hpp"
#include "grid/hash.hpp"

#include <algorithm>
#include <limits>
#include <memory>

namespace kdet {

std::vector<std::uint32_t> spatial_tet_order(const vec3* positions, const std::uint32_t* tets, std::size_t tet_count, int threads) {
    const auto n = static_cast<std::ptrdiff_t>(tet_count);
    // Computed twice rather than stored: a second pass over the caller's tets and their vertices
    // costs less than writing and reading back an array of centroids in fresh memory.
    const auto centroid = [&](std::ptrdiff_t t) {
        const std::uint32_t* v = tets + 4 * t;
        return (positions[v[0]] + positions[v[1]] + positions[v[2]] + positions[v[3]]) * 0.25f;
    };
    const float inf = std::numeric_limits<float>::infinity();
    float lo_x = inf, lo_y = inf, lo_z = inf, hi_x = -inf, hi_y = -inf, hi_z = -inf;
#pragma omp parallel for num_threads(threads) if (n > host_parallel_elements) reduction(min : lo_x, lo_y, lo_z) reduction(max : hi_x, hi_y, hi_z)
    for (std::ptrdiff_t t = 0; t < n; ++t) {
        const vec3 c = centroid(t);
        lo_x = std::min(lo_x, c.x), lo_y = std::min(lo_y, c.y), lo_z = std::min(lo_z, c.z);
        hi_x = std::max(hi_x, c.x), hi_y = std::max(hi_y, c.y), hi_z = std::max(hi_z, c.z);
    }
    // Left uninitialised: each key is written once, and zeroing fresh memory first costs a pass.
    const std::unique_ptr<std::uint64_t[]> keys(new std::uint64_t[tet_count]), scratch(new std::uint64_t[tet_count]);
#pragma omp parallel for num_threads(threads) if (n > host_parallel_elements)
    for (std::ptrdiff_t t = 0; t < n; ++t) {
        const std::uint32_t code = morton_code_in_box(centroid(t), vec3{lo_x, lo_y, lo_z}, vec3{hi_x, hi_y, hi_z});
        keys[static_cast<std::size_t>(t)] = (static_cast<std::uint64_t>(code) << 32) | static_cast<std::uint64_t>(t);
    }
    // By the codes alone: the keys were made in increasing t, and the sort is stable, so tets of equal
    // codes keep their order as the whole key would order them (three passes of 11 bits instead of six).
    radix_sort(keys.get(), tet_count, 62, scratch.get(), threads, 32);
    std::vector<std::uint32_t> order(tet_count);
#pragma omp parallel for num_threads(threads) schedule(static) if (n > host_parallel_elements)
    for (std::ptrdiff_t i = 0; i < n; ++i) order[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(keys[static_cast<std::size_t>(i)] & 0xffffffffu);
    return order;
}

void SceneTopology::add_object(const vec3* positions, std::uint32_t object_vertex_count, const std::uint32_t* object_tets,
                               std::size_t tet_count, int threads) {
    if (object_tet_begin.empty()) object_tet_begin.push_back(0);
    const auto object = static_cast<std::uint32_t>(object_tet_begin.size() - 1);
    const auto first_tet = static_cast<std::uint32_t>(tets.size());
    const std::uint32_t first_vertex = vertex_count;
    constexpr std::uint32_t unnumbered = 0xffffffffu;
    std::vector<std::uint32_t> stored_vertex(object_vertex_count, unnumbered);
    vertex_user_id.resize(first_vertex + std::size_t{object_vertex_count});
    std::uint32_t numbered = 0;
    const auto number = [&](std::uint32_t v) {
        if (stored_vertex[v] == unnumbered) {
            stored_vertex[v] = numbered;
            vertex_user_id[first_vertex + numbered++] = first_vertex + v;
        }
        return first_vertex + stored_vertex[v];
    };
    const std::vector<std::uint32_t> order = spatial_tet_order(positions, object_tets, tet_count, threads);
    tets.reserve(tets.size() + tet_count);
    tet_object.resize(tet_object.size() + tet_count, object);
    tet_user_id.reserve(tet_user_id.size() + tet_count);
    // The caller's tets are read in the stored order, so at random: each tet's row, and then its
    // vertices' entries, are fetched a few tets ahead, so that a mesh listed in no spatial order does
    // not wait on a cache miss at every tet.
    constexpr std::size_t rows_ahead = 16, vertices_ahead = 8;
    for (std::size_t i = 0; i < tet_count; ++i) {
        if (i + rows_ahead < tet_count) __builtin_prefetch(object_tets + 4 * std::size_t{order[i + rows_ahead]});
        if (i + vertices_ahead < tet_count)
            for (int k = 0; k < 4; ++k) __builtin_prefetch(&stored_vertex[object_tets[4 * std::size_t{order[i + vertices_ahead]} + k]]);
        const std::uint32_t t = order[i];
        TetIndices tet;
        for (int k = 0; k < 4; ++k) tet.v[k] = number(object_tets[4 * std::size_t{t} + k]);
        tets.push_back(tet);
        tet_user_id.push_back(first_tet + t);
    }
    for (std::uint32_t v = 0; v < object_vertex_count; ++v) number(v);
    vertex_count = first_vertex + object_vertex_count;
    object_tet_begin.push_back(static_cast<std::uint32_t>(tets.size()));
    object_static.push_back(0);
}

namespace {

template <class Source>
void gather_in_stored_order(const std::vector<std::uint32_t>& vertex_user_id, std::uint32_t first, std::uint32_t count,
                            const Source& source, vec3* stored, int threads) {
    // Read at random where the caller's order is not spatial: fetched a few vertices ahead.
    constexpr std::ptrdiff_t ahead = 16;
    const std::uint32_t* user_id = vertex_user_id.data() + first;
    const auto n = static_cast<std::ptrdiff_t>(count);
#pragma omp parallel for num_threads(threads) schedule(static) if (n > host_parallel_elements)
    for (std::ptrdiff_t v = 0; v < n; ++v) {
        if (v + ahead < n) __builtin_prefetch(source.row(user_id[v + ahead] - first));
        stored[v] = source(user_id[v] - first);
    }
}

} // namespace

void SceneTopology::to_stored_order(std::uint32_t first, const PositionsView& caller, vec3* stored, int threads) const {
    const auto count = static_cast<std::uint32_t>(caller.vertex_count);
    with_positions(caller, [&](const auto& source) {
        gather_in_stored_order(vertex_user_id, first, count, source, stored, threads);
    });
}

} // namespace kdet
