// Replacing one object's tets and vertices in the concatenated topology (Detector::set_tets,
// Detector::remove_object): the object is stored afresh, the others only shift their ids.

#include "pipeline/pipeline_base.hpp"

#include <cstdint>
#include <vector>

namespace kdet {

namespace {

/// source[0, begin), then the piece, then source[end, ...), the last two renumbered by
/// shift(element, in_piece): the piece takes the object's place, and what follows it moves.
template <class T, class Shift>
std::vector<T> spliced(const std::vector<T>& source, std::size_t begin, std::size_t end, const std::vector<T>& piece,
                       const Shift& shift) {
    std::vector<T> out;
    out.reserve(source.size() - (end - begin) + piece.size());
    out.insert(out.end(), source.begin(), source.begin() + static_cast<std::ptrdiff_t>(begin));
    for (const T& x : piece) out.push_back(shift(x, true));
    for (std::size_t i = end; i < source.size(); ++i) out.push_back(shift(source[i], false));
    return out;
}

} // namespace

SceneTopology SceneTopology::with_object_replaced(std::uint32_t object, std::uint32_t first_vertex,
                                                 std::uint32_t old_vertex_count, const vec3* positions,
                                                 std::uint32_t new_vertex_count, const std::uint32_t* object_tets,
                                                 std::size_t tet_count, int threads) const {
    // The object stored alone, numbered from zero, as add_object() would store it.
    SceneTopology piece;
    piece.add_object(positions, new_vertex_count, object_tets, tet_count, threads);

    const std::uint32_t first_tet = object_tet_begin[object], end_tet = object_tet_begin[object + 1];
    const std::uint32_t end_vertex = first_vertex + old_vertex_count;
    // Ids past the object move by the difference of its counts (modulo 2^32, which the sums undo).
    const std::uint32_t tet_shift = static_cast<std::uint32_t>(tet_count) - (end_tet - first_tet);
    const std::uint32_t vertex_shift = new_vertex_count - old_vertex_count;

    SceneTopology next;
    next.tets = spliced(tets, first_tet, end_tet, piece.tets, [&](TetIndices t, bool in_piece) {
        for (std::uint32_t& v : t.v) v += in_piece ? first_vertex : vertex_shift;
        return t;
    });
    next.tet_object = spliced(tet_object, first_tet, end_tet, piece.tet_object,
                              [&](std::uint32_t o, bool in_piece) { return in_piece ? object : o; });
    next.tet_user_id = spliced(tet_user_id, first_tet, end_tet, piece.tet_user_id,
                               [&](std::uint32_t id, bool in_piece) { return id + (in_piece ? first_tet : tet_shift); });
    next.vertex_user_id = spliced(vertex_user_id, first_vertex, end_vertex, piece.vertex_user_id,
                                  [&](std::uint32_t id, bool in_piece) { return id + (in_piece ? first_vertex : vertex_shift); });
    next.object_tet_begin = object_tet_begin;
    next.object_static = object_static;
    for (std::size_t o = object + 1; o < next.object_tet_begin.size(); ++o) next.object_tet_begin[o] += tet_shift;
    next.vertex_count = vertex_count + vertex_shift;
    return next;
}

} // namespace kdet
