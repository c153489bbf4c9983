#include "grid/bucket_table.hpp"
#include "io/text_reader.hpp"
#include "pipeline/object_filters.hpp"
#include "pipeline/pipeline_base.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/locate.hpp>
#include <kdet/option_table.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

namespace kdet {

/// A refused distance as given: "%g", since std::to_string writes a tiny negative one as -0.000000.
static std::string distance_text(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", value);
    return text;
}

struct Detector::Impl {
    DetectorOptions options;
    std::unique_ptr<PipelineBase> pipeline;
    SceneTopology topology;
    std::vector<std::uint32_t> object_vertex_begin{0};
    PairSwitches pair_enabled;
    bool topology_changed = false;
    std::vector<vec3> positions;            // host copy, float32 and in the order the pipeline stores them
    std::vector<std::uint8_t> positions_dirty; // per object: changed since the last upload
    // Per object: positions were last given on the device, so only the pipeline holds them.
    std::vector<std::uint8_t> positions_on_device;
    // Per object: positions given on the device wait in the pipeline's staging buffer for the next frame.
    std::vector<std::uint8_t> positions_staged;
    FrameResult result;
    LocateResult located;
    bool frame_pending = false; // detect_async() ran, finish() not yet
    ObjectFilters filters;
    std::vector<std::uint8_t> removed; // per object id

    std::size_t objects() const { return object_vertex_begin.size() - 1; }

    /// Gives the pipeline the new topology; positions that only the pipeline holds are fetched first.
    /// Staged positions are checked here, as a frame would: bad ones are dropped, and reported once
    /// the rebuild is done.
    void rebuild_pipeline() {
        const std::string rejected = pull_device_positions();
        pipeline->set_topology(topology);
        pipeline->set_exclusions(filters.exclusions(pipeline->object_first_tets()));
        std::fill(positions_dirty.begin(), positions_dirty.end(), 1); // the pipeline's buffers are new
        topology_changed = false;
        if (!rejected.empty()) throw Error(rejected);
    }

    /// Copies the positions that only the pipeline holds into the host copy; returns the message
    /// naming staged positions that were not finite (dropped: the object keeps its previous ones).
    std::string pull_device_positions() {
        std::string rejected;
        for (std::size_t o = 0; o < objects(); ++o) {
            if (!positions_on_device[o]) continue;
            const std::uint32_t first = object_vertex_begin[o], count = object_vertex_begin[o + 1] - first;
            vec3* held = positions.data() + first;
            if (positions_staged[o]) {
                // Staged in the caller's order; the host copy keeps the pipeline's.
                std::vector<vec3> staged(count);
                pipeline->get_positions(first, staged.data(), count, true);
                const std::uint32_t bad = first_non_finite(xyz_view(staged.data(), count));
                if (bad != no_vertex) {
                    rejected = non_finite_message(o, bad);
                    pipeline->get_positions(first, held, count, false);
                } else {
                    topology.to_stored_order(first, count, staged.data(), held, host_threads());
                }
            } else {
                pipeline->get_positions(first, held, count, false);
            }
            // Staged positions are not in the pipeline's current ones yet: they go with the next frame.
            positions_dirty[o] = positions_staged[o];
            positions_on_device[o] = positions_staged[o] = 0;
        }
        return rejected;
    }

    /// The first i below `count` for which bad(i) holds, or count. Every frame's positions pass here,
    /// so many are scanned on the detector's threads, each to its end: the smallest such i wins.
    template <class Bad>
    std::size_t first_where(std::size_t count, const Bad& bad) const {
        const auto n = static_cast<std::ptrdiff_t>(count);
        std::ptrdiff_t first = n;
#pragma omp parallel for num_threads(host_threads()) schedule(static) if (n > host_parallel_elements) reduction(min : first)
        for (std::ptrdiff_t i = 0; i < n; ++i)
            if (bad(i)) first = std::min(first, i);
        return static_cast<std::size_t>(first);
    }

    /// The first vertex of `xyz` with a coordinate that is not finite as the float32 the pipeline
    /// stores, or no_vertex. Out-of-range doubles become infinite floats, so this also catches values
    /// beyond float range.
    std::uint32_t first_non_finite(const PositionsView& xyz) const {
        const std::size_t count = xyz.vertex_count;
        const std::size_t first = with_positions(xyz, [&](const auto& source) {
            return first_where(count, [&source](std::ptrdiff_t v) {
                const vec3 p = source(static_cast<std::uint64_t>(v));
                return !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z);
            });
        });
        return first < count ? static_cast<std::uint32_t>(first) : no_vertex;
    }

    /// The threads of the host's work on positions: the detector's, as its CPU backend uses.
    int host_threads() const { return kdet::host_threads(options.threads); }

    static std::string non_finite_message(std::size_t object, std::uint32_t vertex) {
        return "object " + std::to_string(object) + ": vertex " + std::to_string(vertex) +
               " of the positions given on the device has a non-finite coordinate; they were not used (the "
               "object keeps its previous positions)";
    }

    void check_object(ObjectId object) const {
        if (object >= objects())
            throw Error("object id " + std::to_string(object) + " out of range (" + std::to_string(objects()) +
                        " objects)");
        if (removed[object]) throw Error("object id " + std::to_string(object) + " was removed");
    }

    /// Rejects coordinates that are not finite as the float32 the pipeline stores.
    void check_finite(std::size_t object, const PositionsView& xyz) const {
        const std::uint32_t bad = first_non_finite(xyz);
        if (bad != no_vertex)
            throw Error("object " + std::to_string(object) + ": vertex " + std::to_string(bad) +
                        " has a non-finite coordinate (or one beyond float range)");
    }

    /// Rejects a view that cannot hold `expected` vertices of `object`: another count, no data, or
    /// strides reaching further than an address can (the reads' offsets would overflow).
    static void check_view(std::size_t object, const PositionsView& xyz, std::size_t expected) {
        const std::string name = "object " + std::to_string(object) + ": ";
        if (xyz.vertex_count != expected)
            throw Error(name + "got " + std::to_string(xyz.vertex_count) + " vertices, expected " + std::to_string(expected));
        check_extent(name + "the positions", xyz);
    }

    /// Rejects a view with no data or strides reaching further than an address can; `what` names it.
    static void check_extent(const std::string& what, const PositionsView& xyz) {
        if (xyz.vertex_count == 0) return;
        if (!xyz.data) throw Error(what + "' data pointer is null");
        const auto magnitude = [](std::ptrdiff_t stride) {
            return stride < 0 ? 0 - static_cast<std::uint64_t>(stride) : static_cast<std::uint64_t>(stride);
        };
        const std::uint64_t item = xyz.is_double ? sizeof(double) : sizeof(float);
        std::uint64_t rows = 0, columns = 0, extent = 0;
        const bool overflows = __builtin_mul_overflow(std::uint64_t{xyz.vertex_count - 1}, magnitude(xyz.row_stride), &rows) ||
                               __builtin_mul_overflow(std::uint64_t{2}, magnitude(xyz.column_stride), &columns) ||
                               __builtin_add_overflow(rows, columns, &extent) || __builtin_mul_overflow(extent, item, &extent) ||
                               extent > static_cast<std::uint64_t>(PTRDIFF_MAX);
        if (overflows)
            throw Error(what + "' strides (" + std::to_string(xyz.row_stride) + ", " +
                        std::to_string(xyz.column_stride) + " elements) reach beyond any address for " +
                        std::to_string(xyz.vertex_count) + " vertices");
    }

    void store_positions(ObjectId object, const PositionsView& xyz) {
        const std::uint32_t first = object_vertex_begin[object];
        check_view(object, xyz, object_vertex_begin[object + 1] - first);
        // Checked first, converted into place second: a simulation sets positions every frame, and a
        // converted copy allocated each time cost a fresh (page-faulted) buffer per frame.
        check_finite(object, xyz);
        topology.to_stored_order(first, xyz, positions.data() + first, host_threads());
        positions_dirty[object] = 1;
        positions_on_device[object] = positions_staged[object] = 0;
    }

    /// Point location over the current positions (locate.hpp) into `out`; `points` on the host
    /// or, with `on_device`, in the backend's memory.
    void locate(const PositionsView& points, bool on_device, ObjectId object, const LocateOptions& how, LocateResult& out) {
        if (!(how.within >= 0.0) || !std::isfinite(how.within))
            throw Error("locate: within must be finite and not negative, got " + distance_text(how.within));
        if (object != all_objects) check_object(object);
        check_extent("locate: the points", points);
        if (objects() == 0) { // no tets, no pipeline geometry: nothing holds any point
            out = LocateResult{};
            out.point_count = points.vertex_count;
            out.offsets.assign(points.vertex_count + 1, 0);
            return;
        }
        if (topology_changed) rebuild_pipeline();
        for (std::size_t o = 0; o < objects(); ++o)
            if (positions_staged[o])
                throw Error("locate: object " + std::to_string(o) +
                            "'s positions given on the device are not checked yet; call detect() first");
        std::vector<PositionUpload> uploads;
        for (std::size_t o = 0; o < objects(); ++o) {
            const std::uint32_t first = object_vertex_begin[o];
            if (positions_dirty[o]) uploads.push_back({first, positions.data() + first, object_vertex_begin[o + 1] - first});
        }
        pipeline->upload_positions(uploads);
        std::fill(positions_dirty.begin(), positions_dirty.end(), 0);

        // The pipeline may store an object's tets elsewhere than the topology (static_last).
        const auto& begin = topology.object_tet_begin;
        LocateRequest request;
        request.points = points;
        request.points_on_device = on_device;
        request.first_tet = object == all_objects ? 0 : pipeline->object_first_tets()[object];
        request.tet_count = object == all_objects ? begin.back() : begin[object + 1] - begin[object];
        request.options = how;
        request.threads = host_threads();
        std::vector<vec3> converted;
        const bool packed_floats = !points.is_double && points.row_stride == 3 && points.column_stride == 1;
        if (!on_device) {
            const std::uint32_t bad = first_non_finite(points);
            if (bad != no_vertex)
                throw Error("locate: point " + std::to_string(bad) + " has a non-finite coordinate (or one beyond float range)");
        }
        if (!on_device && !packed_floats) { // the pipeline reads x y z float32 per point
            converted.resize(points.vertex_count);
            const auto count = static_cast<std::ptrdiff_t>(points.vertex_count);
            with_positions(points, [&](const auto& source) {
#pragma omp parallel for num_threads(host_threads()) schedule(static) if (count > host_parallel_elements)
                for (std::ptrdiff_t v = 0; v < count; ++v) converted[v] = source(static_cast<std::uint64_t>(v));
            });
            request.points = xyz_view(converted.data(), converted.size());
        }
        pipeline->locate(request, out);
    }

    /// Rejects a scene of more tets or vertices than ids can number, were `tets` and `vertices` to
    /// replace `old_tets` and `old_vertices`.
    void check_sizes(std::uint64_t tets, std::uint64_t vertices, std::uint64_t old_tets, std::uint64_t old_vertices) const {
        const std::uint64_t total_tets = topology.tets.size() - old_tets + tets;
        const std::uint64_t total_vertices = std::uint64_t{object_vertex_begin.back()} - old_vertices + vertices;
        if (total_tets > grid_id_mask)
            throw Error("too many tetrahedra: " + std::to_string(total_tets) + " in all, at most " +
                        std::to_string(grid_id_mask));
        if (total_vertices >= 0xffffffffull) throw Error("too many vertices for 32-bit ids");
    }

    void check_indices(ObjectId id, const std::uint32_t* tets, std::size_t tet_count, std::size_t vertex_count) const {
        if (!tets && tet_count > 0)
            throw Error("object " + std::to_string(id) + ": the tets' pointer is null, with " + std::to_string(tet_count) + " tets");
        const std::size_t bad_index = first_where(4 * tet_count, [&](std::ptrdiff_t i) { return tets[i] >= vertex_count; });
        if (bad_index < 4 * tet_count)
            throw Error("object " + std::to_string(id) + ": tet " + std::to_string(bad_index / 4) + " has vertex index " +
                        std::to_string(tets[bad_index]) + " out of range [0, " + std::to_string(vertex_count) + ")");
    }

    /// The positions as the float32 the pipeline stores, checked finite as check_finite checks.
    std::unique_ptr<vec3[]> converted_positions(ObjectId id, const PositionsView& xyz) const {
        // Converted on the detector's threads into memory left uninitialised (each element is written once).
        const std::size_t vertex_count = xyz.vertex_count;
        std::unique_ptr<vec3[]> converted(new vec3[vertex_count]);
        const auto vertices = static_cast<std::ptrdiff_t>(vertex_count);
        with_positions(xyz, [&](const auto& source) {
#pragma omp parallel for num_threads(host_threads()) schedule(static) if (vertices > host_parallel_elements)
            for (std::ptrdiff_t v = 0; v < vertices; ++v) converted[v] = source(static_cast<std::uint64_t>(v));
        });
        check_finite(id, xyz_view(converted.get(), vertex_count));
        return converted;
    }

    /// Adds an object; on a bad index or coordinate it throws and leaves the detector as it was.
    ObjectId add(const PositionsView& xyz, const std::uint32_t* tets, std::size_t tet_count) {
        const std::size_t vertex_count = xyz.vertex_count;
        check_sizes(tet_count, vertex_count, 0, 0);
        const ObjectId id = static_cast<ObjectId>(objects());
        check_view(id, xyz, vertex_count);
        check_indices(id, tets, tet_count, vertex_count);
        const std::unique_ptr<vec3[]> converted = converted_positions(id, xyz);

        // The pipeline stores the tets in spatial order and reports them under the caller's numbering.
        const std::uint32_t base = object_vertex_begin.back();
        const auto count = static_cast<std::uint32_t>(vertex_count);
        topology.add_object(converted.get(), count, tets, tet_count, host_threads());
        object_vertex_begin.push_back(base + count);
        positions.resize(topology.vertex_count);
        topology.to_stored_order(base, count, converted.get(), positions.data() + base, host_threads());
        positions_dirty.push_back(1);
        positions_on_device.push_back(0);
        positions_staged.push_back(0);

        pair_enabled.add_object();
        filters.add_object(pair_enabled);
        removed.push_back(0);
        topology_changed = true;
        return id;
    }

    // Changes of an object's tets (Detector::set_tets, remove_object) and the rest contacts read the
    // current positions of every object and store a new topology: what can fail comes first.

    /// Completes a pending frame and brings positions held by the pipeline alone into the host copy.
    void prepare_edit(Detector& detector) {
        if (frame_pending) detector.finish();
        const std::string rejected = pull_device_positions();
        if (!rejected.empty()) throw Error(rejected);
    }

    /// An object's current positions in the caller's vertex order.
    std::vector<vec3> caller_positions(ObjectId object) const {
        const std::uint32_t first = object_vertex_begin[object], end = object_vertex_begin[object + 1];
        std::vector<vec3> out(end - first);
        for (std::uint32_t v = first; v < end; ++v) out[topology.vertex_user_id[v] - first] = positions[v];
        return out;
    }

    /// The ring lists of `object` in `scene`, its vertices numbered from `first_vertex`.
    ExclusionLists rings_of(const SceneTopology& scene, ObjectId object, std::uint32_t first_vertex,
                            std::uint32_t vertex_count, int rings) const {
        if (rings == 0) return {};
        const std::uint32_t first = scene.object_tet_begin[object];
        return pipeline->ring_exclusions(scene.tets.data() + first, scene.object_tet_begin[object + 1] - first, first_vertex,
                                         vertex_count, rings, object);
    }

    /// Replaces an object's vertices and tets by checked ones (prepare_edit() done).
    void replace(ObjectId object, const vec3* xyz, std::uint32_t vertex_count, const std::uint32_t* tets, std::size_t tet_count) {
        const std::uint32_t first = object_vertex_begin[object], old_count = object_vertex_begin[object + 1] - first;
        SceneTopology next =
            topology.with_object_replaced(object, first, old_count, xyz, vertex_count, tets, tet_count, host_threads());
        ExclusionLists rings = rings_of(next, object, first, vertex_count, filters.rings(object));
        filters.check_room(rings.partners.size(), filters.ring_ids(object));
        std::vector<vec3> next_positions(next.vertex_count);
        std::copy(positions.begin(), positions.begin() + first, next_positions.begin());
        next.to_stored_order(first, vertex_count, xyz, next_positions.data() + first, host_threads());
        std::copy(positions.begin() + first + old_count, positions.end(), next_positions.begin() + first + vertex_count);

        topology = std::move(next);
        positions.swap(next_positions);
        for (std::size_t o = object + 1; o < object_vertex_begin.size(); ++o) object_vertex_begin[o] += vertex_count - old_count;
        positions_dirty[object] = 1;
        filters.forget_tets(object);
        filters.set_rings(object, filters.rings(object), std::move(rings));
        topology_changed = true;
    }

    /// The pairs of stored tets (local ids) colliding now inside object a (a == b) or between a < b,
    /// found by a detector of their own with this one's test.
    std::vector<std::uint64_t> colliding_now(ObjectId a, ObjectId b) const {
        DetectorOptions at_rest;
        at_rest.narrow_phase = options.narrow_phase;
        at_rest.threads = options.threads;
        Detector detector(at_rest);
        const ObjectId both[2] = {a, b};
        for (std::size_t i = 0; i < (a == b ? 1u : 2u); ++i) {
            const ObjectId o = both[i];
            const std::uint32_t first_vertex = object_vertex_begin[o], first = topology.object_tet_begin[o];
            const std::uint32_t count = topology.object_tet_begin[o + 1] - first;
            std::vector<std::uint32_t> tets(4 * std::size_t{count});
            for (std::uint32_t t = 0; t < count; ++t)
                for (int k = 0; k < 4; ++k) tets[4 * std::size_t{t} + k] = topology.tets[first + t].v[k] - first_vertex;
            detector.add_object(xyz_view(positions.data() + first_vertex, object_vertex_begin[o + 1] - first_vertex),
                                tets.data(), count);
        }
        detector.set_self_collision(0, a == b);
        std::vector<std::uint64_t> keys;
        for (const TetPair& p : detector.detect().pairs) keys.push_back(std::uint64_t{p.tet_a} << 32 | p.tet_b);
        return keys;
    }
};

Detector::Detector(const DetectorOptions& options) : impl_(std::make_unique<Impl>()) {
    impl_->options = options;
    check_options(options);
    if (options.cuda_stream && options.backend != Backend::cuda)
        throw Error("option cuda_stream is set, but the backend is '" + std::string(to_string(options.backend)) +
                    "': a CUDA stream needs backend 'cuda'");
    impl_->pipeline = options.backend == Backend::cuda ? make_cuda_pipeline(options) : make_cpu_pipeline(options);
}

Detector::~Detector() = default;
Detector::Detector(Detector&&) noexcept = default;
Detector& Detector::operator=(Detector&&) noexcept = default;

ObjectId Detector::add_object(const float* positions, std::size_t vertex_count, const std::uint32_t* tets,
                              std::size_t tet_count) {
    return impl_->add(xyz_view(positions, vertex_count), tets, tet_count);
}
ObjectId Detector::add_object(const double* positions, std::size_t vertex_count, const std::uint32_t* tets,
                              std::size_t tet_count) {
    return impl_->add(xyz_view(positions, vertex_count), tets, tet_count);
}

ObjectId Detector::add_object(const TetMesh& mesh) {
    io::check_whole_entries(mesh, "add_object");
    return impl_->add(xyz_view(mesh.positions.data(), mesh.num_vertices()), mesh.tets.data(), mesh.num_tets());
}
ObjectId Detector::add_object(const PositionsView& positions, const std::uint32_t* tets, std::size_t tet_count) {
    return impl_->add(positions, tets, tet_count);
}

void Detector::set_positions(ObjectId object, const float* positions, std::size_t vertex_count) {
    set_positions(object, xyz_view(positions, vertex_count));
}
void Detector::set_positions(ObjectId object, const double* positions, std::size_t vertex_count) {
    set_positions(object, xyz_view(positions, vertex_count));
}
void Detector::set_positions(ObjectId object, const PositionsView& positions) {
    impl_->check_object(object);
    impl_->store_positions(object, positions);
}

void Detector::set_positions_on_device(ObjectId object, const float* positions, std::size_t vertex_count) {
    set_positions_on_device(object, xyz_view(positions, vertex_count));
}
void Detector::set_positions_on_device(ObjectId object, const PositionsView& positions) {
    Impl& d = *impl_;
    d.check_object(object);
    const std::uint32_t first = d.object_vertex_begin[object];
    Impl::check_view(object, positions, d.object_vertex_begin[object + 1] - first);
    if (d.topology_changed) d.rebuild_pipeline();
    d.pipeline->stage_positions(first, positions);
    d.positions_dirty[object] = 0;
    d.positions_on_device[object] = d.positions_staged[object] = 1;
}

void Detector::set_self_collision(ObjectId object, bool enabled) {
    impl_->check_object(object);
    impl_->pair_enabled(object, object) = enabled ? 1 : 0;
}

void Detector::set_static(ObjectId object, bool is_static) {
    impl_->check_object(object);
    std::uint8_t& flag = impl_->topology.object_static[object];
    if ((flag != 0) == is_static) return;
    flag = is_static ? 1 : 0;
    impl_->topology_changed = true;
}

bool Detector::is_static(ObjectId object) const {
    impl_->check_object(object);
    return impl_->topology.object_static[object] != 0;
}

void Detector::set_pair_collision(ObjectId a, ObjectId b, bool enabled) {
    impl_->check_object(a);
    impl_->check_object(b);
    if (a == b) throw Error("set_pair_collision needs two different objects; use set_self_collision");
    impl_->pair_enabled(a, b) = impl_->pair_enabled(b, a) = enabled ? 1 : 0;
    impl_->filters.set_explicit(a, b);
}

void Detector::set_collision_filter(ObjectId object, std::uint32_t group, std::uint32_t mask) {
    impl_->check_object(object);
    impl_->filters.set_filter(object, group, mask, impl_->pair_enabled);
}

CollisionFilter Detector::collision_filter(ObjectId object) const {
    impl_->check_object(object);
    return CollisionFilter{impl_->filters.group(object), impl_->filters.mask(object)};
}

void Detector::set_self_exclusion_rings(ObjectId object, int rings) {
    Impl& d = *impl_;
    d.check_object(object);
    if (rings < 0 || rings > max_exclusion_rings)
        throw Error("object " + std::to_string(object) + ": exclusion rings " + std::to_string(rings) + " out of range [0, " +
                    std::to_string(max_exclusion_rings) + "]");
    if (rings == d.filters.rings(object)) return;
    if (d.frame_pending) finish(); // the lists are built on the pipeline's backend, after its frame
    const std::uint32_t first = d.object_vertex_begin[object];
    ExclusionLists lists = d.rings_of(d.topology, object, first, d.object_vertex_begin[object + 1] - first, rings);
    d.filters.check_room(lists.partners.size(), d.filters.ring_ids(object));
    d.filters.set_rings(object, rings, std::move(lists));
}

int Detector::self_exclusion_rings(ObjectId object) const {
    impl_->check_object(object);
    return impl_->filters.rings(object);
}

std::size_t Detector::exclude_rest_contacts(ObjectId object) { return exclude_rest_contacts(object, object); }

std::size_t Detector::exclude_rest_contacts(ObjectId object, ObjectId other) {
    Impl& d = *impl_;
    d.check_object(object);
    d.check_object(other);
    d.prepare_edit(*this);
    const ObjectId a = std::min(object, other), b = std::max(object, other);
    const std::vector<std::uint64_t> keys = d.colliding_now(a, b);
    d.filters.check_room(keys.size());
    d.filters.add_rest_pairs(a, b, keys);
    return keys.size();
}

void Detector::remove_object(ObjectId object) {
    Impl& d = *impl_;
    d.check_object(object);
    d.prepare_edit(*this);
    d.replace(object, nullptr, 0, nullptr, 0);
    d.filters.set_rings(object, 0, ExclusionLists{});
    d.pair_enabled(object, object) = 0;
    d.removed[object] = 1;
}

void Detector::set_tets(ObjectId object, const std::uint32_t* tets, std::size_t tet_count) {
    Impl& d = *impl_;
    d.check_object(object);
    const std::uint32_t vertices = d.object_vertex_begin[object + 1] - d.object_vertex_begin[object];
    d.check_sizes(tet_count, 0, d.topology.object_tet_begin[object + 1] - d.topology.object_tet_begin[object], 0);
    d.check_indices(object, tets, tet_count, vertices);
    d.prepare_edit(*this);
    const std::vector<vec3> xyz = d.caller_positions(object);
    d.replace(object, xyz.data(), vertices, tets, tet_count);
}

void Detector::set_tets(ObjectId object, const std::uint32_t* tets, std::size_t tet_count, const PositionsView& positions) {
    Impl& d = *impl_;
    d.check_object(object);
    const std::uint32_t old_vertices = d.object_vertex_begin[object + 1] - d.object_vertex_begin[object];
    d.check_sizes(tet_count, positions.vertex_count, d.topology.object_tet_begin[object + 1] - d.topology.object_tet_begin[object], old_vertices);
    Impl::check_view(object, positions, positions.vertex_count);
    d.check_indices(object, tets, tet_count, positions.vertex_count);
    const std::unique_ptr<vec3[]> xyz = d.converted_positions(object, positions);
    d.prepare_edit(*this);
    d.replace(object, xyz.get(), static_cast<std::uint32_t>(positions.vertex_count), tets, tet_count);
}

void Detector::set_tets(ObjectId object, const TetMesh& mesh) {
    io::check_whole_entries(mesh, "object " + std::to_string(object) + ": set_tets");
    set_tets(object, mesh.tets.data(), mesh.num_tets(), xyz_view(mesh.positions.data(), mesh.num_vertices()));
}

bool Detector::contains(ObjectId object) const { return object < impl_->objects() && !impl_->removed[object]; }

const FrameResult& Detector::detect() {
    detect_async();
    return finish();
}

void Detector::detect_async() {
    Impl& d = *impl_;
    if (d.frame_pending) finish(); // its counters are checked before the next frame overwrites them
    if (d.topology_changed) d.rebuild_pipeline();
    if (d.filters.exclusions_changed()) d.pipeline->set_exclusions(d.filters.exclusions(d.pipeline->object_first_tets()));
    if (d.objects() == 0) {
        d.result = FrameResult{};
        return;
    }
    std::vector<PositionUpload> uploads;
    std::vector<VertexRange> staged;
    for (std::size_t o = 0; o < d.objects(); ++o) {
        const std::uint32_t first = d.object_vertex_begin[o], count = d.object_vertex_begin[o + 1] - first;
        if (d.positions_dirty[o]) uploads.push_back({first, d.positions.data() + first, count});
        if (d.positions_staged[o]) staged.push_back({first, count});
        if (d.topology.object_static[o] && (d.positions_dirty[o] || d.positions_staged[o])) d.pipeline->static_moved();
    }
    d.pipeline->start(uploads, staged, d.pair_enabled.table());
    std::fill(d.positions_dirty.begin(), d.positions_dirty.end(), 0);
    std::fill(d.positions_staged.begin(), d.positions_staged.end(), 0);
    d.frame_pending = true;
}

const FrameResult& Detector::finish() {
    Impl& d = *impl_;
    if (!d.frame_pending) return d.result;
    d.frame_pending = false;
    const std::uint32_t bad = d.pipeline->finish(d.result);
    if (bad != no_vertex) {
        const auto& begin = d.object_vertex_begin;
        const auto object = static_cast<std::size_t>(std::upper_bound(begin.begin(), begin.end(), bad) - begin.begin() - 1);
        throw Error(Impl::non_finite_message(object, bad - begin[object]) + "; this frame's results were discarded");
    }
    return d.result;
}

DeviceResults Detector::device_results() const {
    if (impl_->frame_pending)
        throw Error("device_results: the frame started by detect_async() is not finished; call finish() first");
    return impl_->pipeline->device_results();
}

const LocateResult& Detector::locate(const PositionsView& points, ObjectId object, const LocateOptions& options) {
    if (impl_->frame_pending) finish();
    impl_->locate(points, false, object, options, impl_->located);
    return impl_->located;
}

const LocateResult& Detector::locate(const PositionsView& points, ObjectId object) {
    return locate(points, object, LocateOptions{});
}
const LocateResult& Detector::locate_on_device(const PositionsView& points, ObjectId object, const LocateOptions& options) {
    if (impl_->frame_pending) finish();
    impl_->locate(points, true, object, options, impl_->located);
    return impl_->located;
}
DeviceLocateResults Detector::device_locate_results() const { return impl_->pipeline->device_locate_results(); }

LocateResult locate(const TetMesh& mesh, const PositionsView& points, const LocateOptions& options,
                    const DetectorOptions& detector_options) {
    if (!options.results_to_host)
        throw Error("locate: results_to_host=false would leave a one-off point location only its counts (its device arrays "
                    "end with its detector); a Detector's locate() keeps device results");
    Detector detector(detector_options);
    const ObjectId object = detector.add_object(mesh);
    detector.locate(points, object, options);
    return std::move(detector.impl_->located);
}

std::uint32_t Detector::first_tet(ObjectId object) const {
    impl_->check_object(object);
    return impl_->topology.object_tet_begin[object];
}

std::size_t Detector::object_count() const { return impl_->objects(); }
std::size_t Detector::tet_count(ObjectId object) const {
    impl_->check_object(object);
    return impl_->topology.object_tet_begin[object + 1] - impl_->topology.object_tet_begin[object];
}
std::size_t Detector::memory_bytes() const { return impl_->pipeline->memory_bytes(); }
std::string Detector::device_name() const { return impl_->pipeline->device_name(); }
const DetectorOptions& Detector::options() const { return impl_->options; }

namespace {

/// @brief Throws when `options` ask for what a one-off query, which returns host pairs alone, cannot give.
void check_one_off_options(const char* function, const DetectorOptions& options) {
    const std::string name(function);
    if (options.method == Method::kdet_no_pairs)
        throw Error(name + ": method 'kdet_no_pairs' only flags colliding tets and builds no pairs; a Detector's detect() gives the flags");
    if (!options.results_to_host)
        throw Error(name + ": results_to_host=false keeps the pairs on the device, and " + name +
                    " returns them on the host; a Detector gives device results");
    if (options.contacts || options.distances)
        throw Error(name + ": " + (options.contacts ? "contacts" : "distances") + " would be computed and dropped, as " +
                    name + " returns the pairs alone; a Detector's detect() results hold them");
}

std::vector<IndexPair> to_index_pairs(const FrameResult& result) {
    std::vector<IndexPair> pairs;
    pairs.reserve(result.pairs.size());
    for (const TetPair& p : result.pairs) pairs.emplace_back(p.tet_a, p.tet_b);
    return pairs;
}

} // namespace

std::vector<IndexPair> collide(const TetMesh& a, const TetMesh& b, const DetectorOptions& options) {
    check_one_off_options("collide", options);
    Detector detector(options);
    detector.add_object(a);
    detector.add_object(b);
    return to_index_pairs(detector.detect());
}

std::vector<IndexPair> collide_self(const TetMesh& mesh, const DetectorOptions& options) {
    check_one_off_options("collide_self", options);
    Detector detector(options);
    const ObjectId id = detector.add_object(mesh);
    detector.set_self_collision(id, true);
    return to_index_pairs(detector.detect());
}

const char* git_commit(); // generated at build time by cmake/write_commit.cmake

std::string version() {
    const std::string commit = git_commit();
    if (!commit.empty()) return std::string(KDET_VERSION_STRING) + " (" + commit + ")";
    return KDET_VERSION_STRING;
}

} // namespace kdet
