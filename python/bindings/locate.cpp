// Point location in Python (locate.hpp): the library's LocateResult as NumPy arrays that own copies,
// or as DLPack arrays of the detector's own buffers.
#include "locate.hpp"

#include "arrays.hpp"
#include "scalars.hpp"

#include <kdet/error.hpp>
#include <kdet/locate.hpp>
#include <kdet/mesh.hpp>
#include <kdet/option_table.hpp>

#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>
#ifdef KDET_HAS_CUDA
#include <cuda_runtime.h>
#endif

namespace kdet::python {

namespace {

using namespace nb::literals;

/// What locate() returns: per point the range [offsets[p], offsets[p + 1]) of the per-hit arrays.
struct PyLocateResult {
    nb::object offsets, points, objects, tets, barycentrics, closest_points, distances;
};

/// A NumPy array that owns @p values, shaped (size / columns, columns) or (size,) for one column.
template <class T>
nb::object owned(std::vector<T>&& values, std::size_t columns) {
    auto* held = new std::vector<T>(std::move(values));
    held->reserve(1); // never a null pointer
    nb::capsule owner(held, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
    const std::size_t rows = held->size() / columns;
    if (columns == 1) return nb::cast(nb::ndarray<nb::numpy, T>(held->data(), {rows}, owner));
    return nb::cast(nb::ndarray<nb::numpy, T>(held->data(), {rows, columns}, owner));
}

/// The point of each hit, from the offsets: handy for NumPy indexing.
std::vector<std::uint64_t> hit_points(const std::vector<std::uint64_t>& offsets) {
    std::vector<std::uint64_t> points(offsets.empty() ? 0 : offsets.back());
    for (std::size_t p = 0; p + 1 < offsets.size(); ++p)
        for (std::uint64_t h = offsets[p]; h < offsets[p + 1]; ++h) points[h] = p;
    return points;
}

nb::object host_result(LocateResult&& r) {
    auto out = std::make_unique<PyLocateResult>();
    out->points = owned(hit_points(r.offsets), 1);
    out->offsets = owned(std::move(r.offsets), 1);
    out->objects = owned(std::move(r.objects), 1);
    out->tets = owned(std::move(r.tets), 1);
    out->barycentrics = owned(std::move(r.barycentrics), 4);
    out->closest_points = owned(std::move(r.closest_points), 3);
    out->distances = owned(std::move(r.distances), 1);
    return nb::cast(out.release(), nb::rv_policy::take_ownership);
}

/// A DLPack view of a detector's buffer (valid until its next locate()).
template <class T>
nb::object buffer_view(const T* data, std::size_t rows, std::size_t columns, nb::handle owner, int device_type, int device_id) {
    static T none{};
    T* address = const_cast<T*>(data ? data : &none); // DLPack consumers reject null data
    if (columns == 1)
        return nb::cast(nb::ndarray<nb::array_api, T>(address, {rows}, owner, {}, nb::dtype<T>(), device_type, device_id));
    return nb::cast(nb::ndarray<nb::array_api, T>(address, {rows, columns}, owner, {}, nb::dtype<T>(), device_type, device_id));
}

double within_of(nb::handle within) {
    double distance = 0.0;
    if (within.is_none()) return distance;
    if (!read_real(within, distance)) throw nb::type_error(("within: expected a float or None, got " + type_label(within)).c_str());
    return distance;
}

/// Refuses the keywords of a detection frame (margin, method, ...), which one-off point location
/// would ignore; unknown ones are left to the options' own message.
void refuse_frame_keywords(const nb::kwargs& keywords) {
    for (auto [key, value] : keywords) {
        const std::string name = nb::cast<std::string>(key);
        const OptionInfo* o = find_option(name);
        if (name == "cuda_stream" || (o && name == o->name && !o->shown_on(front_end_locate))) {
            std::string taken;
            for (const OptionInfo& option : option_table())
                if (option.shown_on(front_end_locate) && option.shown_on(front_end_python))
                    taken += std::string(taken.empty() ? "" : ", ") + option.name;
            throw nb::type_error(("locate: keyword '" + name + "' does not apply to point location (it takes " + taken + ")").c_str());
        }
    }
}

} // namespace

nb::object detector_locate(nb::handle owner, Detector& detector, std::mutex& mutex, nb::handle points, nb::handle object,
                           nb::handle within, bool device_results) {
    LocateOptions options;
    options.within = within_of(within);
    options.results_to_host = !device_results;
    ObjectId id = all_objects;
    if (!object.is_none()) {
        long long value = 0;
        bool overflow = false;
        if (!read_integer(object, value, overflow))
            throw nb::type_error(("object: expected an int or None, got " + type_label(object)).c_str());
        if (overflow || value < 0 || static_cast<std::uint64_t>(value) >= detector.object_count())
            throw Error("object id " + nb::cast<std::string>(nb::str(object)) + " out of range (" +
                        std::to_string(detector.object_count()) + " objects)");
        id = static_cast<ObjectId>(value);
    }
    const Coordinates c = coordinates(points, "points");
    if (c.on_device) check_reads_cuda_arrays(detector, "points");
    LocateResult copy;
    DeviceLocateResults buffers;
    {
        nb::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(mutex);
#ifdef KDET_HAS_CUDA
        if (c.on_device && c.stream) {
            const cudaError_t status = cudaStreamSynchronize(reinterpret_cast<cudaStream_t>(c.stream));
            if (status != cudaSuccess) throw Error(std::string("CUDA error in cudaStreamSynchronize: ") + cudaGetErrorString(status));
        }
#endif
        const LocateResult& r = c.on_device ? detector.locate_on_device(c.view(), id, options) : detector.locate(c.view(), id, options);
        if (device_results)
            buffers = detector.device_locate_results();
        else
            copy = r;
    }
    if (!device_results) return host_result(std::move(copy));
    int device_type = nb::device::cpu::value, device_id = 0;
#ifdef KDET_HAS_CUDA
    if (detector.options().backend == Backend::cuda) {
        device_type = nb::device::cuda::value;
        cudaGetDevice(&device_id);
    }
#endif
    auto out = std::make_unique<PyLocateResult>();
    const std::size_t hits = buffers.hit_count;
    out->offsets = buffer_view(buffers.offsets, buffers.point_count + 1, 1, owner, device_type, device_id);
    out->points = nb::none();
    out->objects = buffer_view(buffers.objects, hits, 1, owner, device_type, device_id);
    out->tets = buffer_view(buffers.tets, hits, 1, owner, device_type, device_id);
    out->barycentrics = buffer_view(buffers.barycentrics, hits, 4, owner, device_type, device_id);
    out->closest_points = buffer_view(buffers.closest_points, hits, 3, owner, device_type, device_id);
    out->distances = buffer_view(buffers.distances, hits, 1, owner, device_type, device_id);
    return nb::cast(out.release(), nb::rv_policy::take_ownership);
}

void bind_locate(nb::module_& m, DetectorOptions (*options_from)(const nb::kwargs&)) {
    nb::class_<PyLocateResult>(m, "LocateResult",
                               "Point location's hits: those of point p are rows offsets[p]:offsets[p + 1] of the "
                               "per-hit arrays, sorted by object and tet.")
        .def_ro("offsets", &PyLocateResult::offsets, "uint64 (points + 1,)")
        .def_ro("points", &PyLocateResult::points, "uint64 (k,): the point of each hit (None for device results)")
        .def_ro("objects", &PyLocateResult::objects, "uint32 (k,)")
        .def_ro("tets", &PyLocateResult::tets, "uint32 (k,): the tet's index in its object")
        .def_ro("barycentrics", &PyLocateResult::barycentrics,
                "float64 (k, 4): of the point (or of the tet's closest point) for the tet's vertices")
        .def_ro("closest_points", &PyLocateResult::closest_points, "float64 (k, 3): the point itself where the tet holds it")
        .def_ro("distances", &PyLocateResult::distances, "float64 (k,): 0 where the tet holds the point");
    m.def(
        "locate",
        [options_from](const TetMesh& mesh, nb::handle points, nb::handle within, const nb::kwargs& keywords) {
            refuse_frame_keywords(keywords);
            const DetectorOptions detector_options = options_from(keywords);
            LocateOptions options;
            options.within = within_of(within);
            const Coordinates c = coordinates(points, "points");
            if (c.on_device) throw nb::type_error("points: kdet.locate reads host arrays; use Detector.locate for GPU arrays");
            LocateResult r;
            {
                nb::gil_scoped_release release;
                r = kdet::locate(mesh, c.view(), options, detector_options);
            }
            return host_result(std::move(r));
        },
        "mesh"_a, "points"_a, "within"_a = nb::none(), "options"_a,
        "For each point, every tet of mesh whose closed set holds it (kdet.locate, which reads any mesh, says "
        "more); options are the keywords of Detector that OPTIONS marks 'locate'.");
}

} // namespace kdet::python
