/// @file detector.cpp
/// @brief kdet::mpi::Detector: a thin distributed layer over kdet::Detector (see docs/distributed.md).

#include "agree.hpp"
#include "exchange.hpp"
#include "exchange_kernels.hpp"
#include "exec/cpu_exec.hpp"

#include <kdet/error.hpp>
#include <kdet/mpi.hpp>
#include <kdet/option_table.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <set>
#include <string>
#include <tuple>
#include <utility>

namespace kdet::mpi {

namespace {

/// The local detector's limit on tets, checked on owned tets before they are exchanged.
constexpr std::size_t max_local_tets = (std::size_t{1} << 29) - 1;

using detail::PartSummary;
using detail::TetRecord;

/// A position of a caller's view as the float32 kdet stores (the conversion kdet::Detector makes).
void read_position(const PositionsView& view, std::size_t v, float* out) {
    for (int k = 0; k < 3; ++k) {
        const std::ptrdiff_t at = static_cast<std::ptrdiff_t>(v) * view.row_stride + k * view.column_stride;
        out[k] = view.is_double ? static_cast<float>(static_cast<const double*>(view.data)[at])
                                : static_cast<const float*>(view.data)[at];
    }
}

/// Reads @p view into float32 x y z, or says why not (a wrong count, null data, a non-finite value).
std::string convert_positions(ObjectId object, const PositionsView& view, const std::vector<std::uint32_t>& ids,
                              std::vector<float>& out) {
    const std::size_t expected = ids.size();
    const std::string name = "object " + std::to_string(object) + ": ";
    if (view.vertex_count != expected)
        return name + "got " + std::to_string(view.vertex_count) + " vertices, expected " + std::to_string(expected);
    if (expected > 0 && !view.data) return name + "the positions' data pointer is null";
    out.resize(3 * expected);
    for (std::size_t v = 0; v < expected; ++v) {
        read_position(view, v, &out[3 * v]);
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(out[3 * v + k]))
                return name + "vertex " + std::to_string(ids[v]) +
                       " has a non-finite coordinate (or one beyond float range)";
    }
    return {};
}

/// The errors of a ghost's vertex whose position disagrees with this rank's or with another ghost's.
std::string moved_here(std::size_t object, std::uint32_t vertex, std::uint32_t tet) {
    return "object " + std::to_string(object) + ": vertex " + std::to_string(vertex) +
           " has different positions here and on the rank owning tet " + std::to_string(tet);
}
std::string arrives_twice(std::size_t object, std::uint32_t vertex) {
    return "object " + std::to_string(object) + ": vertex " + std::to_string(vertex) +
           " arrives with two different positions from other ranks";
}

} // namespace

ObjectPart MeshPart::view() const {
    ObjectPart part;
    part.global_vertex_count = global_vertex_count;
    part.global_tet_count = global_tet_count;
    part.vertex_ids = vertex_ids.data();
    part.positions = PositionsView{positions.data(), true, vertex_ids.size(), 3, 1};
    part.tet_ids = tet_ids.data();
    part.tets = tets.data();
    part.tet_count = tet_ids.size();
    return part;
}

struct Detector::Impl {
    /// This rank's part of one object.
    struct Object {
        std::size_t global_vertices = 0, global_tets = 0;
        std::vector<std::uint32_t> vertex_ids;  ///< held vertices, caller's order
        std::vector<float> positions;           ///< x y z per held vertex
        std::vector<std::uint32_t> sorted_ids;  ///< vertex_ids sorted, for lookups
        std::vector<std::uint32_t> sorted_slot; ///< index into vertex_ids of each sorted id
        /// Owned tets' global ids, ascending: the local detector then meets a pair of owned tets in
        /// the single detector's order and computes its contact alike.
        std::vector<std::uint32_t> tet_ids;
        std::vector<std::uint32_t> tets;        ///< 4 indices into vertex_ids per owned tet, tet_ids' order
        std::vector<std::uint32_t> caller_slot; ///< for each owned tet, its index in the caller's part
        bool self = false;

        /// The held index of global vertex @p id, or -1.
        std::ptrdiff_t held(std::uint32_t id) const {
            const auto it = std::lower_bound(sorted_ids.begin(), sorted_ids.end(), id);
            if (it == sorted_ids.end() || *it != id) return -1;
            return sorted_slot[static_cast<std::size_t>(it - sorted_ids.begin())];
        }
    };

    /// One object as the local detector holds it: owned tets first, then the received ones (ghosts)
    /// sorted by global id; local vertices are the held ones, then those only ghosts use, by global id.
    struct LocalObject {
        std::vector<std::uint32_t> ghost_ids;
        std::vector<std::uint32_t> tets;
        std::vector<float> positions;
    };

    explicit Impl(const DetectorOptions& detector_options) : options(detector_options), exec(detector_options) {}

    MPI_Comm comm = MPI_COMM_NULL;
    int rank = 0, size = 1;
    DetectorOptions options;
    CpuExec exec; ///< runs the layer's per-tet functors on the host's threads
    std::vector<std::vector<Aabb>> tet_boxes; ///< [object][owned tet]: this frame's boxes
    std::vector<Object> objects;
    std::set<std::pair<ObjectId, ObjectId>> pairs_off;
    std::string pending_error; ///< from set_positions, reported by the next detect()

    std::vector<LocalObject> local_objects;
    std::unique_ptr<kdet::Detector> local;
    FrameResult result;

    bool checks(ObjectId a, ObjectId b) const {
        if (a == b) return objects[a].self;
        return !pairs_off.count({std::min(a, b), std::max(a, b)});
    }

    /// Every rank must check the same pairs: a hash of the switches is compared each frame.
    std::uint64_t switches_hash() const {
        std::uint64_t h = 1469598103934665603ull;
        const auto mix = [&h](std::uint64_t v) { h = (h ^ v) * 1099511628211ull; };
        mix(objects.size());
        for (const Object& o : objects) mix(o.self);
        for (const auto& p : pairs_off) mix((std::uint64_t{p.first} << 32) | p.second);
        return h;
    }

    void check_object(ObjectId object) const {
        if (object >= objects.size())
            throw Error("object id " + std::to_string(object) + " out of range (" + std::to_string(objects.size()) +
                        " objects)");
    }

    ObjectId add(const ObjectPart& part);
    std::string validate(const ObjectPart& part, Object& out) const;
    std::string check_directory(const Object& object) const;

    const FrameResult& detect();
    std::string summarize(std::vector<unsigned char>& record);
    void exchange(const std::vector<PartSummary>& summaries, std::vector<TetRecord>& received);
    std::string build_local(std::vector<TetRecord>& received, bool& rebuilt);
    std::string renumber(std::size_t o, const TetRecord* ghosts, std::size_t count, LocalObject& lo) const;
    std::string refresh(std::size_t o, const TetRecord* ghosts, std::size_t count);
    void collect_pairs(const kdet::FrameResult& frame);
};

/// Checks a part on this rank alone and fills @p out; returns why it is refused, or "".
std::string Detector::Impl::validate(const ObjectPart& part, Object& out) const {
    const ObjectId id = static_cast<ObjectId>(objects.size());
    const std::string name = "object " + std::to_string(id) + ": ";
    const std::size_t nv = part.positions.vertex_count;
    if (part.global_vertex_count > std::numeric_limits<std::uint32_t>::max() ||
        part.global_tet_count > std::numeric_limits<std::uint32_t>::max())
        return name + "global counts beyond 32-bit ids";
    if ((nv && !part.vertex_ids) || (part.tet_count && (!part.tet_ids || !part.tets)))
        return name + "a null array with a non-zero count";
    if (part.tet_count > max_local_tets)
        return name + std::to_string(part.tet_count) + " tets on one rank, more than a detector holds";
    out.global_vertices = part.global_vertex_count;
    out.global_tets = part.global_tet_count;
    out.vertex_ids.assign(part.vertex_ids, part.vertex_ids + nv);
    for (std::size_t v = 0; v < nv; ++v)
        if (out.vertex_ids[v] >= part.global_vertex_count)
            return name + "vertex id " + std::to_string(out.vertex_ids[v]) + " out of range (" +
                   std::to_string(part.global_vertex_count) + " vertices)";
    std::string bad = convert_positions(id, part.positions, out.vertex_ids, out.positions);
    if (!bad.empty()) return bad;
    std::vector<std::uint32_t> order(nv);
    for (std::size_t v = 0; v < nv; ++v) order[v] = static_cast<std::uint32_t>(v);
    std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return out.vertex_ids[x] < out.vertex_ids[y]; });
    out.sorted_ids.resize(nv);
    out.sorted_slot = order;
    for (std::size_t k = 0; k < nv; ++k) {
        out.sorted_ids[k] = out.vertex_ids[order[k]];
        if (k > 0 && out.sorted_ids[k] == out.sorted_ids[k - 1])
            return name + "vertex id " + std::to_string(out.sorted_ids[k]) + " given twice";
    }
    for (std::size_t t = 0; t < part.tet_count; ++t) {
        if (part.tet_ids[t] >= part.global_tet_count)
            return name + "tet id " + std::to_string(part.tet_ids[t]) + " out of range (" +
                   std::to_string(part.global_tet_count) + " tets)";
        for (int c = 0; c < 4; ++c) {
            const std::uint32_t g = part.tets[4 * t + c];
            if (out.held(g) < 0)
                return name + "tet " + std::to_string(part.tet_ids[t]) + " uses vertex " + std::to_string(g) +
                       (g >= part.global_vertex_count ? ", out of range (" + std::to_string(part.global_vertex_count) + " vertices)"
                                                      : ", which this rank does not hold");
        }
    }
    out.caller_slot.resize(part.tet_count);
    for (std::size_t t = 0; t < part.tet_count; ++t) out.caller_slot[t] = static_cast<std::uint32_t>(t);
    std::sort(out.caller_slot.begin(), out.caller_slot.end(),
              [&](std::uint32_t x, std::uint32_t y) { return part.tet_ids[x] < part.tet_ids[y]; });
    out.tet_ids.resize(part.tet_count);
    out.tets.resize(4 * part.tet_count);
    for (std::size_t k = 0; k < part.tet_count; ++k) {
        const std::size_t t = out.caller_slot[k];
        out.tet_ids[k] = part.tet_ids[t];
        if (k > 0 && out.tet_ids[k] == out.tet_ids[k - 1]) return name + "tet id " + std::to_string(out.tet_ids[k]) + " given twice";
        for (int c = 0; c < 4; ++c) out.tets[4 * k + static_cast<std::size_t>(c)] = static_cast<std::uint32_t>(out.held(part.tets[4 * t + c]));
    }
    return {};
}

/// Collective: each vertex id and tet id goes to a directory rank (blocks of ids), which finds a tet
/// owned by two ranks or by none, or a vertex held with two positions. Returns this rank's finding, or "".
std::string Detector::Impl::check_directory(const Object& object) const {
    struct Entry {
        std::uint32_t id, kind; // kind 0: vertex, 1: tet
        float position[3];
        std::int32_t from;
    };
    const auto home = [&](std::uint64_t id, std::uint64_t count) {
        return static_cast<int>(id * static_cast<std::uint64_t>(size) / std::max<std::uint64_t>(count, 1));
    };
    std::vector<std::vector<Entry>> out(static_cast<std::size_t>(size));
    for (std::size_t v = 0; v < object.vertex_ids.size(); ++v) {
        Entry e{object.vertex_ids[v], 0, {object.positions[3 * v], object.positions[3 * v + 1], object.positions[3 * v + 2]}, rank};
        out[static_cast<std::size_t>(home(e.id, object.global_vertices))].push_back(e);
    }
    for (std::uint32_t t : object.tet_ids)
        out[static_cast<std::size_t>(home(t, object.global_tets))].push_back(Entry{t, 1, {0, 0, 0}, rank});
    std::vector<Entry> got = detail::all_to_all(comm, out);
    std::sort(got.begin(), got.end(), [](const Entry& x, const Entry& y) {
        return std::tie(x.kind, x.id, x.from) < std::tie(y.kind, y.id, y.from);
    });
    const std::string name = "object " + std::to_string(objects.size()) + ": ";
    for (std::size_t k = 1; k < got.size(); ++k) {
        const Entry &a = got[k - 1], &b = got[k];
        if (a.kind != b.kind || a.id != b.id) continue;
        if (a.kind == 1)
            return name + "tet " + std::to_string(a.id) + " is owned by ranks " + std::to_string(a.from) + " and " +
                   std::to_string(b.from);
        if (std::memcmp(a.position, b.position, sizeof a.position) != 0)
            return name + "vertex " + std::to_string(a.id) + " has different positions on ranks " +
                   std::to_string(a.from) + " and " + std::to_string(b.from);
    }
    // This rank's block of tet ids is [first, end): each must have come from some rank.
    const std::uint64_t tets = object.global_tets, ranks = static_cast<std::uint64_t>(size), r = static_cast<std::uint64_t>(rank);
    const std::uint64_t first = (r * tets + ranks - 1) / ranks, end = ((r + 1) * tets + ranks - 1) / ranks;
    std::uint64_t next = first;
    for (const Entry& e : got)
        if (e.kind == 1 && e.id == next) ++next;
    if (next < end)
        return name + "tet " + std::to_string(next) + " is owned by no rank (each of the " + std::to_string(tets) +
               " tets must be owned by one)";
    return {};
}

ObjectId Detector::Impl::add(const ObjectPart& part) {
    detail::agree_on_call(comm, detail::Call::add_object);
    Object object;
    const std::string local_error = validate(part, object);
    // One reduction carries the first bad rank and the spread of the global counts.
    long long mine[5] = {local_error.empty() ? -size : -rank, static_cast<long long>(part.global_vertex_count),
                         -static_cast<long long>(part.global_vertex_count), static_cast<long long>(part.global_tet_count),
                         -static_cast<long long>(part.global_tet_count)};
    long long all[5];
    MPI_Allreduce(mine, all, 5, MPI_LONG_LONG, MPI_MAX, comm);
    if (-all[0] < size) throw Error(detail::agree(comm, local_error, static_cast<int>(-all[0])));
    const std::string name = "object " + std::to_string(objects.size()) + ": ";
    if (all[1] != -all[2])
        throw Error(name + "ranks give different global vertex counts (" + std::to_string(-all[2]) + " and " +
                    std::to_string(all[1]) + ")");
    if (all[3] != -all[4])
        throw Error(name + "ranks give different global tet counts (" + std::to_string(-all[4]) + " and " +
                    std::to_string(all[3]) + ")");
    detail::agree_or_throw(comm, check_directory(object));
    objects.push_back(std::move(object));
    local.reset(); // the local detector's objects no longer match
    return static_cast<ObjectId>(objects.size() - 1);
}

/// This rank's record for the frame's gather: its status, the switches' hash, and per object the
/// box and occupied cells of its part (its tets' boxes kept for exchange()). Returns this rank's
/// pending error, if any.
std::string Detector::Impl::summarize(std::vector<unsigned char>& record) {
    const std::uint32_t status = pending_error.empty() ? 0u : 1u;
    const std::uint64_t hash = switches_hash();
    std::memcpy(record.data(), &status, 4);
    std::memcpy(record.data() + 8, &hash, 8);
    tet_boxes.resize(objects.size());
    for (std::size_t o = 0; o < objects.size(); ++o) {
        const Object& object = objects[o];
        const std::uint64_t n = object.tet_ids.size();
        std::vector<Aabb>& boxes = tet_boxes[o];
        boxes.resize(n);
        exec.for_each(n, detail::OwnedTetBoxes{object.positions.data(), object.tets.data(), options.margin, boxes.data()});
        constexpr std::uint32_t chunk = 4096;
        std::vector<Aabb> chunk_boxes((n + chunk - 1) / chunk);
        exec.for_each(chunk_boxes.size(), detail::ChunkBoxes{boxes.data(), n, chunk, chunk_boxes.data()}, chunk);
        PartSummary s{};
        s.box = detail::empty_box();
        for (const Aabb& box : chunk_boxes) s.box = BoxUnion{}(s.box, box);
        exec.for_each(n, detail::MarkCells{boxes.data(), detail::coarse_grid(s.box), s.cells});
        std::memcpy(record.data() + 16 + o * sizeof(PartSummary), &s, sizeof s);
    }
    return pending_error;
}

/// Sends each owned tet to every other rank holding a part it may touch; fills @p received.
void Detector::Impl::exchange(const std::vector<PartSummary>& summaries, std::vector<TetRecord>& received) {
    const std::size_t n_objects = objects.size();
    const auto summary = [&](int r, std::size_t o) -> const PartSummary& { return summaries[static_cast<std::size_t>(r) * n_objects + o]; };
    // The ranks whose parts overlap this rank's at all: the only ones a tet may go to.
    std::vector<int> near;
    for (int r = 0; r < size; ++r) {
        if (r == rank) continue;
        bool any = false;
        for (std::size_t a = 0; a < n_objects && !any; ++a)
            for (std::size_t b = 0; b < n_objects && !any; ++b)
                any = checks(static_cast<ObjectId>(a), static_cast<ObjectId>(b)) && !detail::box_is_empty(summary(rank, a).box) &&
                      !detail::box_is_empty(summary(r, b).box) && boxes_overlap(summary(rank, a).box, summary(r, b).box);
        if (any) near.push_back(r);
    }
    // The near ranks' summaries and their coarse grids, [j * objects + b].
    std::vector<PartSummary> near_summaries;
    std::vector<detail::CoarseGrid> grids;
    for (int r : near)
        for (std::size_t b = 0; b < n_objects; ++b) {
            near_summaries.push_back(summary(r, b));
            grids.push_back(detail::coarse_grid(summary(r, b).box));
        }
    const auto ranks = static_cast<std::uint32_t>(near.size());
    std::vector<std::vector<TetRecord>> out(static_cast<std::size_t>(size));
    std::vector<std::uint8_t> checked(n_objects);
    std::vector<std::uint32_t> places;
    std::vector<TetRecord*> records(near.size());
    for (std::size_t a = 0; a < n_objects && ranks > 0; ++a) {
        const Object& object = objects[a];
        const std::uint64_t n = object.tet_ids.size();
        for (std::size_t b = 0; b < n_objects; ++b) checked[b] = checks(static_cast<ObjectId>(a), static_cast<ObjectId>(b));
        places.resize(ranks * (n + 1));
        exec.for_each(n, detail::ChooseRanks{tet_boxes[a].data(), n, near_summaries.data(), grids.data(), checked.data(),
                                             static_cast<std::uint32_t>(n_objects), ranks, places.data()},
                      ranks);
        // Each rank's flags become the places of the tets going there.
        for (std::uint32_t j = 0; j < ranks; ++j) {
            std::uint32_t* first = places.data() + j * (n + 1);
            first[n] = 0;
            std::exclusive_scan(first, first + n + 1, first, 0u);
            std::vector<TetRecord>& list = out[static_cast<std::size_t>(near[j])];
            const std::size_t before = list.size();
            list.resize(before + first[n]);
            records[j] = list.data() + before;
        }
        exec.for_each(n, detail::PackRecords{static_cast<std::uint32_t>(a), n, object.tet_ids.data(), object.tets.data(),
                                             object.vertex_ids.data(), object.positions.data(), places.data(), ranks,
                                             records.data()},
                      ranks);
    }
    const std::size_t n = static_cast<std::size_t>(size);
    std::size_t total_send = 0;
    for (const auto& list : out) {
        total_send += list.size();
        result.exchange.ranks_sent_to += list.empty() ? 0u : 1u;
    }
    received = detail::all_to_all(comm, out);
    const std::size_t total_recv = received.size();
    result.exchange.tets_sent = total_send;
    result.exchange.tets_received = total_recv;
    result.exchange.bytes_sent += total_send * sizeof(TetRecord) + (n - 1) * sizeof(int);
    result.exchange.bytes_received += total_recv * sizeof(TetRecord) + (n - 1) * sizeof(int);
}

/// Object @p o's local tets and positions from its owned tets and its ghosts @p ghosts (sorted by
/// global id) into @p lo, the ghosts' vertices renumbered; returns an error found in their positions, or "".
std::string Detector::Impl::renumber(std::size_t o, const TetRecord* ghosts, std::size_t count, LocalObject& lo) const {
    const Object& object = objects[o];
    for (std::size_t k = 0; k < count; ++k) lo.ghost_ids.push_back(ghosts[k].tet);
    // Vertices only ghosts use, by global id; a vertex this rank holds, or that two ghosts share,
    // must arrive with the one position every holder gives it.
    struct Ghost {
        std::uint32_t id;
        const float* position;
    };
    std::vector<Ghost> extra;
    for (std::size_t k = 0; k < count; ++k)
        for (int c = 0; c < 4; ++c) {
            const TetRecord& rec = ghosts[k];
            const std::ptrdiff_t h = object.held(rec.vertex[c]);
            if (h < 0) extra.push_back(Ghost{rec.vertex[c], &rec.position[3 * c]});
            else if (std::memcmp(&object.positions[3 * static_cast<std::size_t>(h)], &rec.position[3 * c], 3 * sizeof(float)) != 0)
                return moved_here(o, rec.vertex[c], rec.tet);
        }
    std::sort(extra.begin(), extra.end(), [](const Ghost& x, const Ghost& y) { return x.id < y.id; });
    std::vector<std::uint32_t> extra_ids;
    const std::size_t held = object.vertex_ids.size();
    lo.positions = object.positions;
    for (std::size_t k = 0; k < extra.size(); ++k) {
        if (k > 0 && extra[k].id == extra[k - 1].id) {
            if (std::memcmp(extra[k].position, extra[k - 1].position, 3 * sizeof(float)) != 0) return arrives_twice(o, extra[k].id);
            continue;
        }
        extra_ids.push_back(extra[k].id);
        lo.positions.insert(lo.positions.end(), extra[k].position, extra[k].position + 3);
    }
    lo.tets = object.tets;
    for (std::size_t k = 0; k < count; ++k)
        for (int c = 0; c < 4; ++c) {
            const std::uint32_t g = ghosts[k].vertex[c];
            const std::ptrdiff_t h = object.held(g);
            lo.tets.push_back(h >= 0 ? static_cast<std::uint32_t>(h)
                                     : static_cast<std::uint32_t>(held + static_cast<std::size_t>(
                                                                             std::lower_bound(extra_ids.begin(), extra_ids.end(), g) -
                                                                             extra_ids.begin())));
        }
    return {};
}

/// Object @p o's ghosts are the previous frame's: its local tets and numbering stay, and only the
/// positions are refreshed in place, with the same checks as renumber(). Returns an error, or "".
std::string Detector::Impl::refresh(std::size_t o, const TetRecord* ghosts, std::size_t count) {
    const Object& object = objects[o];
    LocalObject& lo = local_objects[o];
    const std::size_t held = object.vertex_ids.size(), owned = object.tet_ids.size();
    std::copy(object.positions.begin(), object.positions.end(), lo.positions.begin());
    // First the held vertices are checked and the others written, then those compared with what
    // every other record brings for them.
    for (int pass = 0; pass < 2; ++pass)
        for (std::size_t k = 0; k < count; ++k)
            for (int c = 0; c < 4; ++c) {
                const std::size_t v = lo.tets[4 * (owned + k) + static_cast<std::size_t>(c)];
                float* here = &lo.positions[3 * v];
                const float* brought = &ghosts[k].position[3 * c];
                const bool differs = std::memcmp(here, brought, 3 * sizeof(float)) != 0;
                if (v < held) {
                    if (pass == 0 && differs) return moved_here(o, ghosts[k].vertex[c], ghosts[k].tet);
                } else if (pass == 0) {
                    std::memcpy(here, brought, 3 * sizeof(float));
                } else if (differs) {
                    return arrives_twice(o, ghosts[k].vertex[c]);
                }
            }
    return {};
}

/// Builds the local detector from the owned tets and @p received, or updates it: set_tets() for the
/// objects whose ghosts changed, set_positions() for the others, whose local tets stay as they were.
/// Returns an error found in the received positions, or "" (on an error the caller drops the local
/// detector, so that a half-refreshed object is never used).
std::string Detector::Impl::build_local(std::vector<TetRecord>& received, bool& rebuilt) {
    std::sort(received.begin(), received.end(),
              [](const TetRecord& x, const TetRecord& y) { return std::tie(x.object, x.tet) < std::tie(y.object, y.tet); });
    const bool anew = !local || local_objects.size() != objects.size();
    rebuilt = anew;
    std::vector<std::uint8_t> changed(objects.size(), 0);
    std::vector<LocalObject> next(objects.size());
    std::size_t at = 0;
    for (std::size_t o = 0; o < objects.size(); ++o) {
        const std::size_t begin = at;
        while (at < received.size() && received[at].object == o) ++at;
        const std::vector<std::uint32_t>* before = anew ? nullptr : &local_objects[o].ghost_ids;
        const bool same = before && before->size() == at - begin &&
                          std::equal(before->begin(), before->end(), received.begin() + static_cast<std::ptrdiff_t>(begin),
                                     [](std::uint32_t id, const TetRecord& rec) { return id == rec.tet; });
        const std::string error = same ? refresh(o, received.data() + begin, at - begin)
                                       : renumber(o, received.data() + begin, at - begin, next[o]);
        if (!error.empty()) return error;
        changed[o] = !anew && !same;
        rebuilt = rebuilt || changed[o];
    }
    local_objects.resize(objects.size());
    for (std::size_t o = 0; o < objects.size(); ++o)
        if (anew || changed[o]) local_objects[o] = std::move(next[o]);
    if (anew) {
        local.reset();
        auto fresh = std::make_unique<kdet::Detector>(options);
        for (std::size_t o = 0; o < objects.size(); ++o) {
            const LocalObject& lo = local_objects[o];
            fresh->add_object(lo.positions.data(), lo.positions.size() / 3, lo.tets.data(), lo.tets.size() / 4);
        }
        for (std::size_t a = 0; a < objects.size(); ++a) {
            fresh->set_self_collision(static_cast<ObjectId>(a), objects[a].self);
            for (std::size_t b = a + 1; b < objects.size(); ++b)
                fresh->set_pair_collision(static_cast<ObjectId>(a), static_cast<ObjectId>(b),
                                          checks(static_cast<ObjectId>(a), static_cast<ObjectId>(b)));
        }
        local = std::move(fresh);
    } else {
        // An object whose tets changed is updated in place: its switches stay, the others are untouched.
        for (std::size_t o = 0; o < objects.size(); ++o) {
            const LocalObject& lo = local_objects[o];
            const PositionsView xyz{lo.positions.data(), false, lo.positions.size() / 3, 3, 1};
            if (changed[o])
                local->set_tets(static_cast<ObjectId>(o), lo.tets.data(), lo.tets.size() / 4, xyz);
            else
                local->set_positions(static_cast<ObjectId>(o), xyz);
        }
    }
    return {};
}

/// Keeps the local pairs whose lower tet this rank owns, in global ids and order, and the owned flags.
void Detector::Impl::collect_pairs(const kdet::FrameResult& frame) {
    const auto global = [&](std::uint32_t object, std::uint32_t tet) {
        const Object& o = objects[object];
        return tet < o.tet_ids.size() ? o.tet_ids[tet] : local_objects[object].ghost_ids[tet - o.tet_ids.size()];
    };
    const bool with_contacts = !frame.contacts.empty();
    struct Kept {
        TetPair pair;
        Contact contact;
    };
    std::vector<Kept> kept;
    for (std::size_t k = 0; k < frame.pairs.size(); ++k) {
        const TetPair& p = frame.pairs[k];
        TetPair g{p.object_a, global(p.object_a, p.tet_a), p.object_b, global(p.object_b, p.tet_b)};
        Contact c = with_contacts ? frame.contacts[k] : Contact{};
        bool lower_is_a = true;
        if (g.object_b < g.object_a || (g.object_b == g.object_a && g.tet_b < g.tet_a)) {
            std::swap(g.object_a, g.object_b);
            std::swap(g.tet_a, g.tet_b);
            for (float& d : c.direction) d = -d; // the other tet moves: the opposite direction separates
            lower_is_a = false;
        }
        const std::uint32_t lower_object = lower_is_a ? p.object_a : p.object_b;
        const std::uint32_t lower_local = lower_is_a ? p.tet_a : p.tet_b;
        if (lower_local < objects[lower_object].tet_ids.size()) kept.push_back(Kept{g, c});
    }
    std::sort(kept.begin(), kept.end(), [](const Kept& x, const Kept& y) { return x.pair < y.pair; });
    result.pairs.resize(kept.size());
    result.contacts.resize(with_contacts ? kept.size() : 0);
    for (std::size_t k = 0; k < kept.size(); ++k) {
        result.pairs[k] = kept[k].pair;
        if (with_contacts) result.contacts[k] = kept[k].contact;
    }
    result.colliding.resize(objects.size());
    for (std::size_t o = 0; o < objects.size(); ++o) {
        const Object& object = objects[o];
        result.colliding[o].resize(object.tet_ids.size());
        for (std::size_t k = 0; k < object.tet_ids.size(); ++k) result.colliding[o][object.caller_slot[k]] = frame.colliding[o][k];
    }
    result.counts = frame.counts;
    result.times = frame.times;
    result.memory_bytes = frame.memory_bytes;
}

const FrameResult& Detector::Impl::detect() {
    const double start = MPI_Wtime();
    detail::agree_on_call(comm, detail::Call::detect);
    ExchangeStats stats;
    result.exchange = stats;
    const std::size_t record_bytes = 16 + objects.size() * sizeof(PartSummary);
    std::vector<unsigned char> record(record_bytes), records(record_bytes * static_cast<std::size_t>(size));
    const std::string mine = summarize(record);
    MPI_Allgather(record.data(), static_cast<int>(record_bytes), MPI_BYTE, records.data(), static_cast<int>(record_bytes),
                  MPI_BYTE, comm);
    int first_bad = -1;
    bool switches_differ = false;
    std::vector<PartSummary> summaries(objects.size() * static_cast<std::size_t>(size));
    for (int r = 0; r < size; ++r) {
        const unsigned char* at = records.data() + static_cast<std::size_t>(r) * record_bytes;
        std::uint32_t status;
        std::uint64_t hash;
        std::memcpy(&status, at, 4);
        std::memcpy(&hash, at + 8, 8);
        if (status && first_bad < 0) first_bad = r;
        if (hash != switches_hash()) switches_differ = true;
        if (!objects.empty())
            std::memcpy(&summaries[static_cast<std::size_t>(r) * objects.size()], at + 16, objects.size() * sizeof(PartSummary));
    }
    if (first_bad >= 0) {
        pending_error.clear();
        throw Error(detail::agree(comm, mine, first_bad));
    }
    if (switches_differ)
        throw Error("self-collision or pair switches differ between ranks (set them alike on every rank)");

    std::vector<TetRecord> received;
    exchange(summaries, received);
    result.exchange.bytes_sent += record_bytes * static_cast<std::size_t>(size - 1);
    result.exchange.bytes_received += record_bytes * static_cast<std::size_t>(size - 1);
    const double exchanged = MPI_Wtime();

    std::string error;
    bool rebuilt = false;
    try {
        error = build_local(received, rebuilt);
        if (error.empty()) collect_pairs(local->detect());
    } catch (const Error& e) {
        error = e.what();
    }
    if (!error.empty()) local.reset(); // rebuilt from the held state next frame
    const double detected = MPI_Wtime();
    detail::agree_or_throw(comm, error);

    for (const Object& o : objects) result.exchange.owned_tets += o.tet_ids.size();
    result.exchange.local_tets = result.exchange.owned_tets + result.exchange.tets_received;
    result.exchange.rebuilt = rebuilt;
    result.exchange.exchange_ms = (exchanged - start) * 1e3;
    result.exchange.local_ms = (detected - exchanged) * 1e3;
    result.exchange.total_ms = (MPI_Wtime() - start) * 1e3;
    return result;
}

Detector::Detector(MPI_Comm comm, const DetectorOptions& options) : impl_(std::make_unique<Impl>(options)) {
    MPI_Comm_dup(comm, &impl_->comm);
    MPI_Comm_rank(impl_->comm, &impl_->rank);
    MPI_Comm_size(impl_->comm, &impl_->size);
    // Construction is collective: an option one rank refuses fails on every rank, not in a later call.
    std::string bad;
    if (!options.results_to_host) bad = "kdet::mpi::Detector needs results_to_host: it filters the local pairs on the host";
    else if (options.distances) bad = "kdet::mpi::Detector returns no distances: its FrameResult has pairs, flags and contacts";
    std::string error = detail::agree(impl_->comm, bad);
    // The options that decide the answer must agree (threads, backend and buffer sizes may differ).
    std::uint64_t h = 1469598103934665603ull;
    for (const char* name : {"method", "test", "margin", "contacts"})
        for (const char c : find_option(name)->text(options)) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
    std::uint64_t range[2] = {h, ~h}, agreed[2] = {0, 0};
    MPI_Allreduce(range, agreed, 2, MPI_UINT64_T, MPI_MAX, impl_->comm);
    if (error.empty() && (agreed[0] != h || agreed[1] != ~h))
        error = "the method, test, margin or contacts of kdet::mpi::Detector differ between ranks (give every rank the same)";
    if (!error.empty()) {
        MPI_Comm_free(&impl_->comm); // no destructor runs for a constructor that throws
        throw Error(error);
    }
}

Detector::~Detector() {
    if (impl_ && impl_->comm != MPI_COMM_NULL) {
        int finalized = 0;
        MPI_Finalized(&finalized);
        if (!finalized) MPI_Comm_free(&impl_->comm);
    }
}
Detector::Detector(Detector&&) noexcept = default;
Detector& Detector::operator=(Detector&& other) noexcept {
    if (this != &other) {
        Detector dropped(std::move(*this));
        impl_ = std::move(other.impl_);
    }
    return *this;
}

ObjectId Detector::add_object(const ObjectPart& part) { return impl_->add(part); }

void Detector::set_positions(ObjectId object, const PositionsView& positions) {
    impl_->check_object(object);
    if (!impl_->pending_error.empty()) return; // the first bad call is what detect() reports
    Impl::Object& o = impl_->objects[object];
    std::vector<float> converted;
    const std::string bad = convert_positions(object, positions, o.vertex_ids, converted);
    if (bad.empty()) o.positions = std::move(converted);
    else impl_->pending_error = bad;
}
void Detector::set_positions(ObjectId object, const double* positions, std::size_t vertex_count) {
    set_positions(object, PositionsView{positions, true, vertex_count, 3, 1});
}
void Detector::set_positions(ObjectId object, const float* positions, std::size_t vertex_count) {
    set_positions(object, PositionsView{positions, false, vertex_count, 3, 1});
}

void Detector::set_self_collision(ObjectId object, bool enabled) {
    impl_->check_object(object);
    impl_->objects[object].self = enabled;
    impl_->local.reset();
}
void Detector::set_pair_collision(ObjectId a, ObjectId b, bool enabled) {
    impl_->check_object(a);
    impl_->check_object(b);
    if (a == b) throw Error("set_pair_collision needs two different objects (use set_self_collision)");
    const std::pair<ObjectId, ObjectId> key{std::min(a, b), std::max(a, b)};
    if (enabled) impl_->pairs_off.erase(key);
    else impl_->pairs_off.insert(key);
    impl_->local.reset();
}

const FrameResult& Detector::detect() { return impl_->detect(); }

std::vector<TetPair> Detector::gather_pairs(int root) const {
    const Impl& d = *impl_;
    detail::agree_on_call(d.comm, detail::Call::gather_pairs, root, "root");
    if (root < 0 || root >= d.size)
        throw Error("gather_pairs: root " + std::to_string(root) + " is not a rank of the communicator (0 to " +
                    std::to_string(d.size - 1) + ")");
    const int count = static_cast<int>(d.result.pairs.size());
    std::vector<int> counts(d.rank == root ? static_cast<std::size_t>(d.size) : 0), at(counts.size());
    MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, root, d.comm);
    std::vector<TetPair> all;
    if (d.rank == root) {
        int total = 0;
        for (std::size_t r = 0; r < counts.size(); ++r) {
            at[r] = total;
            total += counts[r];
        }
        all.resize(static_cast<std::size_t>(total));
    }
    MPI_Datatype pair_type;
    MPI_Type_contiguous(sizeof(TetPair), MPI_BYTE, &pair_type);
    MPI_Type_commit(&pair_type);
    MPI_Gatherv(d.result.pairs.data(), count, pair_type, all.data(), counts.data(), at.data(), pair_type, root, d.comm);
    MPI_Type_free(&pair_type);
    std::sort(all.begin(), all.end());
    return all;
}

std::size_t Detector::object_count() const { return impl_->objects.size(); }
MPI_Comm Detector::communicator() const { return impl_->comm; }
int Detector::rank() const { return impl_->rank; }
int Detector::size() const { return impl_->size; }

} // namespace kdet::mpi
