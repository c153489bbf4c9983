#include "pipeline/pair_keys.hpp"
#include "pipeline/pipeline_base.hpp"

#include <algorithm>

#include <omp.h>

namespace kdet {

namespace {

/// The object of global tet `global` and its index there. With few objects a count of the objects
/// starting at or before it, without a branch: the objects of a pair's second tets alternate at
/// random, and a binary search would mispredict at every level.
struct TetLocator {
    const std::vector<std::uint32_t>& begin; ///< [objects + 1]
    static constexpr std::size_t few_objects = 16;

    void operator()(std::uint32_t global, std::uint32_t& object, std::uint32_t& tet) const {
        const std::size_t objects = begin.size() - 1;
        std::uint32_t o = 0;
        if (objects <= few_objects) {
            for (std::size_t k = 1; k < objects; ++k) o += global >= begin[k] ? 1u : 0u;
        } else {
            o = static_cast<std::uint32_t>(std::upper_bound(begin.begin(), begin.end(), global) - begin.begin() - 1);
        }
        object = o;
        tet = global - begin[o];
    }
};

} // namespace

int host_threads(int requested) { return requested > 0 ? requested : omp_get_max_threads(); }

void pairs_from_keys(const std::vector<std::uint32_t>& object_tet_begin, const std::uint64_t* keys, std::size_t count,
                     TetPair* pairs, int threads) {
    const TetLocator locate{object_tet_begin};
    const auto n = static_cast<std::ptrdiff_t>(count);
#pragma omp parallel for num_threads(host_threads(threads)) schedule(static) if (n > host_parallel_elements)
    for (std::ptrdiff_t k = 0; k < n; ++k) {
        TetPair& p = pairs[k];
        locate(key_first(keys[k]), p.object_a, p.tet_a);
        locate(key_second(keys[k]), p.object_b, p.tet_b);
    }
}

void flags_by_object(const std::vector<std::uint32_t>& object_tet_begin, const std::uint32_t* flags,
                     std::vector<std::vector<std::uint8_t>>& colliding, int threads) {
    const std::size_t objects = object_tet_begin.empty() ? 0 : object_tet_begin.size() - 1;
    colliding.resize(objects);
    if (objects == 0) return;
    for (std::size_t o = 0; o < objects; ++o) colliding[o].resize(object_tet_begin[o + 1] - object_tet_begin[o]);
    const auto n = static_cast<std::ptrdiff_t>(object_tet_begin.back());
    const TetLocator locate{object_tet_begin};
#pragma omp parallel num_threads(host_threads(threads)) if (n > host_parallel_elements)
    {
        // Each thread a contiguous range of global tets, walked object by object.
        const std::ptrdiff_t parts = omp_get_num_threads(), part = omp_get_thread_num();
        const auto first = static_cast<std::uint32_t>(n * part / parts), end = static_cast<std::uint32_t>(n * (part + 1) / parts);
        if (first < end) {
            std::uint32_t object = 0, tet = 0;
            locate(first, object, tet);
            for (std::uint32_t t = first; t < end; ++object) {
                const std::uint32_t object_end = std::min(end, object_tet_begin[object + 1]);
                std::uint8_t* out = colliding[object].data();
                for (; t < object_end; ++t) out[t - object_tet_begin[object]] = flags[t] ? 1 : 0;
            }
        }
    }
}

} // namespace kdet
