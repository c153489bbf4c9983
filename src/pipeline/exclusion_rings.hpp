#pragma once
/// @file exclusion_rings.hpp
/// @brief The lists of Detector::set_self_exclusion_rings, built on the execution layer (both
/// backends, the same kernels): per tet t, the tets u > t that share no vertex with t but have a vertex
/// within `rings` mesh edges of one of t's (each pair once, under its lower tet: pair_exclusions.hpp).
///
/// Everything is a compressed row array. The vertex graph (each vertex's neighbours and itself) is the
/// vertices' tets expanded by the tets' vertices, each row sorted and made unique. Per vertex, its
/// ball grows from the vertex graph's row by one ring per step through the graph, and the tets at the
/// ball's vertices follow; each such step writes an item once, from the first of the item's own
/// neighbours (in their fixed order) that lies in the row (a binary search in the sorted row), so that
/// rows hold no repeats and are only sorted. A tet's list then merges its four vertices' sorted rows,
/// keeping the later tets that share no vertex with it. The vertices' work is shared by their tets
/// (a tet's list is the union of its vertices' rows); the host only scans the rows' counts between
/// steps.

#include "exec/atomic.hpp"
#include "pipeline/pair_exclusions.hpp"
#include "pipeline/pipeline_base.hpp"
#include "pipeline/scene_view.hpp"

#include <kdet/error.hpp>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace kdet {

namespace exclusion_rings {

struct ZeroKernel {
    std::uint32_t* out;
    KDET_HD void operator()(std::uint64_t i) const { out[i] = 0; }
};

/// Each tet's vertices numbered within the object, as rows of four (row t at 4t).
struct LocalVerticesKernel {
    const TetIndices* tets;
    std::uint32_t first_vertex;
    std::uint32_t* vertices;
    std::uint32_t* begin; ///< [tets + 1]
    KDET_HD void operator()(std::uint64_t t) const {
        for (int k = 0; k < 4; ++k) vertices[4 * t + k] = tets[t].v[k] - first_vertex;
        begin[t + 1] = static_cast<std::uint32_t>(4 * t + 4);
        if (t == 0) begin[0] = 0;
    }
};

struct CountVertexTetsKernel {
    const std::uint32_t* vertices; ///< LocalVerticesKernel's
    std::uint32_t* count;          ///< [vertex_count + 1], zeroed; vertex v counted at v + 1
    KDET_HD void operator()(std::uint64_t i) const { atomic_fetch_add(count + vertices[i] + 1, 1u); }
};

struct FillVertexTetsKernel {
    const std::uint32_t* vertices;
    std::uint32_t* cursor; ///< each vertex's next free place, from its row's start
    std::uint32_t* vertex_tets;
    KDET_HD void operator()(std::uint64_t i) const {
        vertex_tets[atomic_fetch_add(cursor + vertices[i], 1u)] = static_cast<std::uint32_t>(i / 4);
    }
};

/// A compressed row array in the backend's memory: row r's items are items[begin[r], begin[r + 1]).
struct RowsView {
    const std::uint32_t* begin;
    const std::uint32_t* items;
};

/// Per row, the number of items its expansion holds.
struct CountExpansionKernel {
    RowsView rows, adjacency;
    std::uint32_t* count;
    KDET_HD void operator()(std::uint64_t r) const {
        std::uint32_t n = 0;
        for (std::uint32_t i = rows.begin[r]; i < rows.begin[r + 1]; ++i) {
            const std::uint32_t x = rows.items[i];
            n += adjacency.begin[x + 1] - adjacency.begin[x];
        }
        count[r] = n;
    }
};

/// Row r of the expansion, from out_begin[r] on.
struct FillExpansionKernel {
    RowsView rows, adjacency;
    const std::uint32_t* out_begin;
    std::uint32_t* out;
    KDET_HD void operator()(std::uint64_t r) const {
        std::uint32_t o = out_begin[r];
        for (std::uint32_t i = rows.begin[r]; i < rows.begin[r + 1]; ++i) {
            const std::uint32_t x = rows.items[i];
            for (std::uint32_t j = adjacency.begin[x]; j < adjacency.begin[x + 1]; ++j) out[o++] = adjacency.items[j];
        }
    }
};

/// Per sorted row, how many distinct items it holds (Write == false), or those items from out_begin[r]
/// on (Write == true).
template <bool Write>
struct UniqueKernel {
    RowsView sorted;
    const std::uint32_t* out_begin;
    std::uint32_t* out; ///< the items (Write) or the counts
    KDET_HD void operator()(std::uint64_t r) const {
        std::uint32_t n = 0;
        const std::uint32_t first = sorted.begin[r], end = sorted.begin[r + 1];
        for (std::uint32_t i = first; i < end; ++i) {
            const std::uint32_t x = sorted.items[i];
            if (i > first && sorted.items[i - 1] == x) continue;
            if (Write) out[out_begin[r] + n] = x;
            ++n;
        }
        if (!Write) out[r] = n;
    }
};

/// Per row of sorted `rows`, the items y of the adjacency rows of its items x, each once: from the x
/// that comes first in y's own row of `back` (which holds x whenever x's adjacency row holds y).
/// Counts them (Write == false) or writes them from out_begin[r] on, unsorted.
template <bool Write>
struct ExpandOnceKernel {
    RowsView rows, adjacency, back;
    const std::uint32_t* out_begin;
    std::uint32_t* out; ///< the items (Write) or the counts
    KDET_HD void operator()(std::uint64_t r) const {
        const std::uint32_t* const row_first = rows.items + rows.begin[r];
        const std::uint32_t* const row_last = rows.items + rows.begin[r + 1];
        std::uint32_t n = 0;
        for (const std::uint32_t* x = row_first; x != row_last; ++x)
            for (std::uint32_t j = adjacency.begin[*x]; j < adjacency.begin[*x + 1]; ++j) {
                const std::uint32_t y = adjacency.items[j];
                bool first = true;
                for (std::uint32_t k = back.begin[y]; back.items[k] != *x; ++k)
                    if (sorted_holds(row_first, row_last, back.items[k])) {
                        first = false;
                        break;
                    }
                if (!first) continue;
                if (Write) out[out_begin[r] + n] = y;
                ++n;
            }
        if (!Write) out[r] = n;
    }
};

/// A compressed row array in the backend's memory, its row starts also on the host.
template <class Exec>
struct Rows {
    typename Exec::template buffer<std::uint32_t> begin, items;
    std::vector<std::uint32_t> host_begin;
    std::uint32_t rows() const { return static_cast<std::uint32_t>(host_begin.size() - 1); }
    RowsView view() const { return RowsView{begin.data(), items.data()}; }
};

/// Rows starting where `count` (per row, downloaded) says, the total returned; false when it passes
/// `limit` (nothing is allocated then).
template <class Exec>
bool size_rows(const Exec& exec, const typename Exec::template buffer<std::uint32_t>& count, std::uint32_t rows,
               std::uint64_t limit, Rows<Exec>& out) {
    std::vector<std::uint32_t> host(rows);
    exec.download(host.data(), count.data(), rows);
    out.host_begin.assign(std::size_t{rows} + 1, 0);
    std::uint64_t total = 0;
    for (std::uint32_t r = 0; r < rows; ++r) {
        total += host[r];
        if (total > limit) return false;
        out.host_begin[r + 1] = static_cast<std::uint32_t>(total);
    }
    out.begin.resize_discard(std::size_t{rows} + 1);
    exec.upload(out.begin.data(), out.host_begin.data(), std::size_t{rows} + 1);
    out.items.resize_discard(total);
    return true;
}

/// Each row of `rows` replaced by the concatenation of the adjacency rows of its items; false when the
/// result would pass `limit` ids.
template <class Exec>
bool expand(const Exec& exec, RowsView rows, std::uint32_t row_count, RowsView adjacency, std::uint64_t limit,
            typename Exec::template buffer<std::uint32_t>& count, Rows<Exec>& out) {
    count.resize_discard(row_count);
    if (row_count) exec.for_each(row_count, CountExpansionKernel{rows, adjacency, count.data()});
    if (!size_rows(exec, count, row_count, limit, out)) return false;
    if (row_count) exec.for_each(row_count, FillExpansionKernel{rows, adjacency, out.begin.data(), out.items.data()});
    return true;
}

/// Each row of `rows` sorted and without repeats.
template <class Exec>
void sort_unique(const Exec& exec, Rows<Exec>& rows, typename Exec::template buffer<std::uint32_t>& count,
                 typename Exec::template buffer<std::uint32_t>& sorted, Rows<Exec>& out) {
    const std::uint32_t n = rows.rows();
    const std::size_t ids = rows.host_begin.back();
    sorted.resize_discard(ids);
    exec.sort_lists(rows.items.data(), sorted.data(), ids, rows.begin.data(), rows.begin.data() + 1, n);
    const RowsView view{rows.begin.data(), sorted.data()};
    count.resize_discard(n);
    if (n) exec.for_each(n, UniqueKernel<false>{view, nullptr, count.data()});
    size_rows(exec, count, n, 0xffffffffull, out); // at most the ids sorted
    if (n) exec.for_each(n, UniqueKernel<true>{view, out.begin.data(), out.items.data()});
}

/// Per tet t, the tets u > t sharing no vertex with t in the union of its vertices' sorted rows of
/// `vertex_tets`: counted (Write == false) or written from out_begin[t] on, sorted.
template <bool Write>
struct MergeTetsKernel {
    RowsView vertex_tets;
    const TetIndices* tets;
    const std::uint32_t* tet_vertices; ///< LocalVerticesKernel's
    const std::uint32_t* out_begin;
    std::uint32_t* out; ///< the items (Write) or the counts
    KDET_HD void operator()(std::uint64_t i) const {
        const auto t = static_cast<std::uint32_t>(i);
        const std::uint32_t* head[4];
        const std::uint32_t* last[4];
        for (int k = 0; k < 4; ++k) {
            const std::uint32_t v = tet_vertices[4 * i + k];
            head[k] = vertex_tets.items + vertex_tets.begin[v];
            last[k] = vertex_tets.items + vertex_tets.begin[v + 1];
            head[k] = first_not_below(head[k], last[k], t + 1); // only later tets are listed
        }
        std::uint32_t n = 0;
        for (;;) {
            std::uint32_t u = 0xffffffffu;
            for (int k = 0; k < 4; ++k)
                if (head[k] != last[k] && *head[k] < u) u = *head[k];
            if (u == 0xffffffffu) break;
            for (int k = 0; k < 4; ++k)
                if (head[k] != last[k] && *head[k] == u) ++head[k];
            if (share_vertex(tets[t], tets[u])) continue;
            if (Write) out[out_begin[t] + n] = u;
            ++n;
        }
        if (!Write) out[t] = n;
    }
};

/// Rows of ExpandOnceKernel's items, sorted, into `out`; false when they would pass 2^32 - 1 ids.
template <class Exec>
bool expand_once(const Exec& exec, RowsView rows, std::uint32_t row_count, RowsView adjacency, RowsView back,
                 typename Exec::template buffer<std::uint32_t>& count, typename Exec::template buffer<std::uint32_t>& unsorted,
                 Rows<Exec>& out) {
    count.resize_discard(row_count);
    exec.for_each(row_count, ExpandOnceKernel<false>{rows, adjacency, back, nullptr, count.data()});
    if (!size_rows(exec, count, row_count, 0xffffffffull, out)) return false;
    const std::size_t ids = out.host_begin.back();
    unsorted.resize_discard(ids);
    exec.for_each(row_count, ExpandOnceKernel<true>{rows, adjacency, back, out.begin.data(), unsorted.data()});
    exec.sort_lists(unsorted.data(), out.items.data(), ids, out.begin.data(), out.begin.data() + 1, row_count);
    return true;
}

} // namespace exclusion_rings

/// @brief Per tet of one object's `tet_count` tets (local ids; `tets` on the host, their vertices
/// numbered from `first_vertex`, `vertex_count` of them), the sorted local ids u > t of the tets that
/// share no vertex with t but have a vertex within `rings` (>= 1) mesh edges of one of t's vertices.
/// Throws kdet::Error naming `object` when the lists hold more than 2^32 - 1 ids.
template <class Exec>
ExclusionLists build_ring_exclusions(const Exec& exec, const TetIndices* tets, std::uint32_t tet_count,
                                     std::uint32_t first_vertex, std::uint32_t vertex_count, int rings, std::uint32_t object) {
    using namespace exclusion_rings;
    using Buffer = typename Exec::template buffer<std::uint32_t>;
    ExclusionLists lists;
    lists.begin.assign(std::size_t{tet_count} + 1, 0);
    if (tet_count == 0) return lists;
    Buffer count, sorted;
    typename Exec::template buffer<TetIndices> device_tets;
    device_tets.resize_discard(tet_count);
    exec.upload(device_tets.data(), tets, tet_count);
    // Tets' vertices (rows of four), the vertices' tets, and the vertex graph (each vertex's
    // neighbours and itself).
    Rows<Exec> tet_vertices, vertex_tets, vertex_graph, candidates;
    tet_vertices.items.resize_discard(4 * std::size_t{tet_count});
    tet_vertices.begin.resize_discard(std::size_t{tet_count} + 1);
    exec.for_each(tet_count,
                  LocalVerticesKernel{device_tets.data(), first_vertex, tet_vertices.items.data(), tet_vertices.begin.data()});
    count.resize_discard(std::size_t{vertex_count} + 1);
    exec.for_each(std::uint64_t{vertex_count} + 1, ZeroKernel{count.data()});
    exec.for_each(4 * std::uint64_t{tet_count}, CountVertexTetsKernel{tet_vertices.items.data(), count.data()});
    std::vector<std::uint32_t> per_vertex(std::size_t{vertex_count} + 1);
    exec.download(per_vertex.data(), count.data(), per_vertex.size());
    for (std::uint32_t v = 0; v < vertex_count; ++v) per_vertex[v + 1] += per_vertex[v];
    vertex_tets.host_begin = per_vertex;
    vertex_tets.begin.resize_discard(per_vertex.size());
    exec.upload(vertex_tets.begin.data(), per_vertex.data(), per_vertex.size());
    vertex_tets.items.resize_discard(4 * std::size_t{tet_count});
    exec.copy(count.data(), vertex_tets.begin.data(), vertex_count);
    exec.for_each(4 * std::uint64_t{tet_count}, FillVertexTetsKernel{tet_vertices.items.data(), count.data(), vertex_tets.items.data()});
    const auto too_many = [&](const char* what) {
        return Error("object " + std::to_string(object) + ": " + std::to_string(rings) + " exclusion rings: " + what +
                     " would hold more than " + std::to_string(0xffffffffull) + " ids");
    };
    if (!expand(exec, vertex_tets.view(), vertex_count, tet_vertices.view(), 0xffffffffull, count, candidates))
        throw too_many("the vertex graph");
    sort_unique(exec, candidates, count, sorted, vertex_graph);

    // Per vertex: its ball (radius 1 is its row of the vertex graph), then the tets at the ball.
    Rows<Exec> balls[2];
    RowsView ball = vertex_graph.view();
    for (int ring = 1; ring < rings; ++ring) {
        Rows<Exec>& grown = balls[ring % 2];
        if (!expand_once(exec, ball, vertex_count, vertex_graph.view(), vertex_graph.view(), count, sorted, grown))
            throw too_many("the vertices' balls");
        ball = grown.view();
    }
    Rows<Exec>& ball_tets = balls[rings % 2];
    if (!expand_once(exec, ball, vertex_count, vertex_tets.view(), tet_vertices.view(), count, sorted, ball_tets))
        throw too_many("the tets at the vertices' balls");

    // Per tet: the merge of its vertices' rows.
    count.resize_discard(tet_count);
    exec.for_each(tet_count, MergeTetsKernel<false>{ball_tets.view(), device_tets.data(), tet_vertices.items.data(), nullptr,
                                                    count.data()});
    Rows<Exec> merged;
    if (!size_rows(exec, count, tet_count, 0xffffffffull, merged)) throw too_many("the lists");
    exec.for_each(tet_count, MergeTetsKernel<true>{ball_tets.view(), device_tets.data(), tet_vertices.items.data(),
                                                   merged.begin.data(), merged.items.data()});
    lists.begin = merged.host_begin;
    lists.partners.resize(merged.host_begin.back());
    exec.download(lists.partners.data(), merged.items.data(), lists.partners.size());
    return lists;
}

} // namespace kdet
