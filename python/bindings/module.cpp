// The kdet._kdet extension module: the library's API with NumPy arrays in and out. The pure-Python
// part of the package (python/src/kdet/__init__.py) re-exports it, and its collide() and collide_self()
// take meshio meshes and (vertices, tets) pairs as well before calling the library's.
#include "arrays.hpp"
#include "detector.hpp"
#include "fields.hpp"
#include "locate.hpp"
#include "scalars.hpp"
#include "scenes.hpp"
#ifdef KDET_HAS_CUDA
#include <cuda_runtime.h>
#endif

#include <kdet/kdet.hpp>

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <array>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace kdet::python {

namespace {

using namespace nb::literals;

// ---------------------------------------------------------------------------------------------
// Options: every keyword is an entry of the library's option table (kdet/option_table.hpp), which reads
// and checks its value and words the message; a new option appears here without a change to this file.
// What stays here is Python's side: types (TypeError), None for an unset number, and the CUDA stream.

nb::tuple names_of(const char* option) {
    nb::list names;
    for (const std::string& name : find_option(option)->names()) names.append(name);
    return nb::tuple(names);
}

/// "backend, method, ... or cuda_stream": the keywords of Detector().
std::string python_keywords() {
    std::vector<std::string> names;
    for (const OptionInfo& o : option_table())
        if (o.shown_on(front_end_python)) names.emplace_back(o.name);
    names.emplace_back("cuda_stream");
    return join_names(names);
}

/// The table's entry of keyword @p name, or a TypeError as Python words an unknown keyword.
const OptionInfo& keyword_option(const std::string& name) {
    const OptionInfo* o = find_option(name);
    if (!o || name != o->name || !o->shown_on(front_end_python))
        throw nb::type_error(
            ("unexpected keyword argument '" + name + "' (the options are " + python_keywords() + ")").c_str());
    return *o;
}

void set_option(const OptionInfo& o, nb::handle value, DetectorOptions& options) {
    const auto wrong_type = [&](const char* expected) {
        return nb::type_error((std::string(o.name) + ": expected " + expected + ", got " + type_label(value)).c_str());
    };
    switch (o.type) {
    case OptionType::choice:
        if (!nb::isinstance<nb::str>(value)) throw wrong_type("a str");
        return o.parse(nb::cast<std::string>(value), options, o.name);
    case OptionType::boolean: {
        bool flag = false;
        if (!read_bool(value, flag)) throw wrong_type("a bool");
        return o.set_number(options, flag);
    }
    case OptionType::integer: {
        if (value.is_none() && o.unset_by_default()) return o.put(options, o.get(DetectorOptions{}));
        long long number = 0;
        bool overflow = false;
        if (!read_integer(value, number, overflow)) throw wrong_type(o.unset_by_default() ? "an int or None" : "an int");
        if (overflow)
            throw Error(std::string(o.label) + " " + nb::cast<std::string>(nb::str(value)) + " out of range");
        return o.set_number(options, number);
    }
    case OptionType::real: {
        double number = 0.0;
        if (!read_real(value, number)) throw wrong_type("a float");
        return o.set_real(options, number);
    }
    }
}

/// A CUDA stream as the GPU libraries hand it out: None (the default stream), a cudaStream_t as an int, or
/// a stream object with __cuda_stream__ (the CUDA stream protocol), .cuda_stream (PyTorch, Warp) or .ptr
/// (CuPy).
void* cuda_stream_handle(nb::handle stream) {
    if (stream.is_none()) return nullptr;
    nb::object value = nb::borrow(stream);
    if (nb::hasattr(stream, "__cuda_stream__")) {
        value = stream.attr("__cuda_stream__")();
        if (!nb::isinstance<nb::tuple>(value) || nb::len(value) != 2)
            throw nb::type_error("cuda_stream: __cuda_stream__() must return (version, handle)");
        value = value[1];
    } else if (nb::hasattr(stream, "cuda_stream")) {
        value = stream.attr("cuda_stream");
    } else if (nb::hasattr(stream, "ptr")) {
        value = stream.attr("ptr");
    }
    if (!PyLong_Check(value.ptr()))
        throw nb::type_error(("cuda_stream: expected None, a cudaStream_t as an int or a CUDA stream object, got " +
                              type_label(stream)).c_str());
    const unsigned long long handle = PyLong_AsUnsignedLongLong(value.ptr());
    if (PyErr_Occurred()) {
        PyErr_Clear();
        throw Error("cuda_stream: " + nb::cast<std::string>(nb::repr(value)) + " is not a stream handle");
    }
    return reinterpret_cast<void*>(static_cast<std::uintptr_t>(handle));
}

/// DetectorOptions from Detector()'s keywords (those of collide() and collide_self() too).
DetectorOptions options_from_keywords(const nb::kwargs& keywords) {
    DetectorOptions options;
    for (auto [key, value] : keywords) {
        const std::string name = nb::cast<std::string>(key);
        if (name == "cuda_stream")
            options.cuda_stream = cuda_stream_handle(value);
        else
            set_option(keyword_option(name), value, options);
    }
    return options;
}

/// Detector()'s signature for help() and the type stubs: every keyword of the table with its default.
const char* detector_signature() {
    static const std::string signature = [] {
        std::string out = "def __init__(self, *";
        for (const OptionInfo& o : option_table()) {
            if (!o.shown_on(front_end_python)) continue;
            out += std::string(", ") + o.name + ": ";
            if (o.type == OptionType::choice) out += "str = '" + o.default_text() + "'";
            else if (o.type == OptionType::boolean) out += o.get(DetectorOptions{}) ? "bool = True" : "bool = False";
            else if (o.type == OptionType::real) out += "float = " + o.default_text();
            else if (o.unset_by_default()) out += "int | None = None";
            else out += "int = " + o.default_text();
        }
        return out + ", cuda_stream: object = None) -> None";
    }();
    return signature.c_str();
}

// ---------------------------------------------------------------------------------------------
// Meshes

/// A view of @p count rows of @p Columns values owned by the Python object @p owner.
template <class Scalar, std::size_t Columns>
nb::ndarray<nb::numpy, Scalar, nb::shape<-1, static_cast<nb::ssize_t>(Columns)>> rows_view(Scalar* data, std::size_t count,
                                                                                          nb::handle owner) {
    return {data, {count, Columns}, owner};
}

TetMesh mesh_from_arrays(nb::handle vertices, nb::handle tets, bool allow_degenerate, const char* vertices_name,
                         const char* tets_name, const std::string& source) {
    const Coordinates c = coordinates(vertices, vertices_name);
    if (c.on_device) throw nb::type_error((std::string(vertices_name) + ": a mesh's vertices must be in host memory").c_str());
    const TetIndices t = tet_indices(tets, tets_name);
    TetMesh mesh;
    mesh.positions.resize(3 * c.rows);
    copy_xyz(c, mesh.positions.data());
    mesh.tets.assign(t.data, t.data + 4 * t.rows);
    validate_tet_mesh(mesh, source, ReadOptions{allow_degenerate});
    return mesh;
}

nb::object import_meshio(const char* what) {
    try {
        return nb::module_::import_("meshio");
    } catch (const nb::python_error&) {
        PyErr_SetString(PyExc_ImportError, (std::string(what) + " needs meshio: pip install meshio").c_str());
        throw nb::python_error();
    }
}

TetMesh from_meshio(nb::handle mesh, Arg<bool> allow_degenerate_arg) {
    const bool allow_degenerate = read_arg(allow_degenerate_arg, "allow_degenerate");
    if (!nb::hasattr(mesh, "points") || !nb::hasattr(mesh, "cells"))
        throw nb::type_error(("mesh: expected a meshio.Mesh, got " + type_label(mesh)).c_str());
    nb::list tets;
    std::string types;
    const nb::object numpy = nb::module_::import_("numpy");
    for (nb::handle block : mesh.attr("cells")) {
        const std::string type = nb::cast<std::string>(block.attr("type"));
        types += (types.empty() ? "" : ", ") + type;
        // A quadratic tet's first four nodes are its corners.
        if (type == "tetra" || type == "tetra10")
            tets.append(numpy.attr("asarray")(block.attr("data"))[nb::make_tuple(nb::slice(nb::none(), nb::none(), nb::none()), nb::slice(0, 4, 1))]);
    }
    if (tets.size() == 0)
        throw Error("from_meshio: the mesh has no tetra cells (it has: " + (types.empty() ? "no cells" : types) + ")");
    const nb::object all = tets.size() == 1 ? nb::object(tets[0]) : numpy.attr("concatenate")(tets);
    return mesh_from_arrays(mesh.attr("points"), all, allow_degenerate, "mesh.points", "mesh.cells (tetra)", "meshio mesh");
}

nb::object to_meshio(nb::handle self) {
    const nb::object meshio = import_meshio("TetMesh.to_meshio()");
    TetMesh& mesh = nb::cast<TetMesh&>(self);
    // Copies: the meshio mesh must not change when this TetMesh does.
    const nb::object points = nb::cast(rows_view<double, 3>(mesh.positions.data(), mesh.num_vertices(), self)).attr("copy")();
    // int64 cells, as meshio's own readers make them (some of its writers reject unsigned types).
    const nb::object cells =
        nb::cast(rows_view<std::uint32_t, 4>(mesh.tets.data(), mesh.num_tets(), self)).attr("astype")("int64");
    nb::list blocks;
    blocks.append(nb::make_tuple("tetra", cells));
    return meshio.attr("Mesh")(points, blocks);
}

// ---------------------------------------------------------------------------------------------
// Detection results

/// What detect() returns on the host: the library's FrameResult, copied once out of the detector so that
/// it stays valid after the next frame; its arrays are views of this copy.
struct Frame {
    FrameResult result;
    bool contacts_enabled = false;
    bool distances_enabled = false;
};

/// A float32 view of a Frame's per-pair `values` (k rows of `row` floats each), or None when `enabled` is off.
template <class T>
nb::object per_pair_floats(nb::handle frame, bool enabled, std::vector<T>& values, std::initializer_list<std::size_t> row) {
    if (!enabled) return nb::none();
    std::vector<std::size_t> shape{values.size()};
    shape.insert(shape.end(), row);
    return nb::cast(nb::ndarray<nb::numpy, float>(reinterpret_cast<float*>(values.data()), shape.size(), shape.data(), frame));
}

/// What detect(device_results=True) returns: DLPack arrays of the detector's own buffers (valid until the
/// next detect()) and the frame's counts and times.
struct DeviceFrame {
    nb::object pair_keys, colliding, contacts, distances, closest_points;
    FrameCounts counts;
    StageTimes times;
    std::size_t memory_bytes = 0;
};

template <class Scalar>
nb::object device_view(const Scalar* data, std::initializer_list<std::size_t> shape, nb::handle owner, int device_type,
                       int device_id) {
    // A zero-sized export still needs an address: DLPack consumers reject null data pointers.
    static Scalar empty{};
    const Scalar* address = data ? data : &empty;
    // array_api: an object with __dlpack__ and __dlpack_device__ (and the buffer protocol on the host).
    return nb::cast(nb::ndarray<nb::array_api, Scalar>(const_cast<Scalar*>(address), shape, owner, {},
                                                       nb::dtype<Scalar>(), device_type, device_id));
}

// ---------------------------------------------------------------------------------------------
// The detector

ObjectId add_object(PyDetector& self, nb::handle vertices, nb::handle tets) {
    const Coordinates c = coordinates(vertices, "vertices");
    if (c.on_device)
        throw nb::type_error("vertices: add_object reads the rest shape on the host; give set_positions the device array");
    const TetIndices t = tet_indices(tets, "tets");
    nb::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(self.mutex);
    return self.detector.add_object(c.view(), t.data, t.rows);
}

#ifdef KDET_HAS_CUDA
void check_cuda(cudaError_t status, const char* what) {
    if (status != cudaSuccess) throw Error(std::string("CUDA error in ") + what + ": " + cudaGetErrorString(status));
}
#endif

/// GPU positions, read where they lie: the library gathers any layout on the detector's stream and
/// checks the array's device.
void set_device_positions(PyDetector& self, ObjectId id, const Coordinates& c) {
    check_reads_cuda_arrays(self.detector, "positions");
#ifdef KDET_HAS_CUDA
    nb::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(self.mutex);
    // __cuda_array_interface__'s producer stream (1 and 2 are CUDA's legacy and per-thread default
    // streams): its writes must be done before the detector's stream reads the array.
    if (c.stream) check_cuda(cudaStreamSynchronize(reinterpret_cast<cudaStream_t>(c.stream)), "cudaStreamSynchronize");
    self.detector.set_positions_on_device(id, c.view());
#else
    (void)id;
    (void)c;
#endif
}

void set_positions(PyDetector& self, Arg<std::int64_t> object, nb::handle positions) {
    const ObjectId id = object_id(self, object);
    const Coordinates c = coordinates(positions, "positions");
    if (c.on_device) return set_device_positions(self, id, c);
    nb::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(self.mutex);
    self.detector.set_positions(id, c.view());
}

/// What detect() and finish() return: the frame that `complete` (Detector::detect or Detector::finish)
/// completes, on the host or as DLPack arrays of the detector's buffers.
nb::object completed_frame(nb::handle handle, bool device_results, const FrameResult& (Detector::*complete)(),
                           const char* name) {
    PyDetector& self = nb::cast<PyDetector&>(handle);
    const DetectorOptions& options = self.detector.options();
    if (!device_results && !options.results_to_host)
        throw Error(std::string(name) + ": this detector keeps its results on the device (results_to_host=False); "
                    "call " + name + "(device_results=True)");
    std::unique_ptr<Frame> frame;
    auto device_frame = std::make_unique<DeviceFrame>();
    DeviceResults buffers;
    {
        nb::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(self.mutex);
        const FrameResult& result = (self.detector.*complete)();
        if (device_results) {
            buffers = self.detector.device_results();
            device_frame->counts = result.counts;
            device_frame->times = result.times;
            device_frame->memory_bytes = result.memory_bytes;
        } else {
            frame = std::make_unique<Frame>(Frame{result, options.contacts, options.distances});
        }
    }
    if (frame) return nb::cast(frame.release(), nb::rv_policy::take_ownership);

    int device_type = nb::device::cpu::value, device_id = 0;
#ifdef KDET_HAS_CUDA
    if (options.backend == Backend::cuda) {
        device_type = nb::device::cuda::value;
        check_cuda(cudaGetDevice(&device_id), "cudaGetDevice"); // the detector's device
    }
#endif
    device_frame->pair_keys = device_view(buffers.pair_keys, {buffers.pair_count}, handle, device_type, device_id);
    device_frame->colliding = device_view(buffers.colliding, {buffers.tet_count}, handle, device_type, device_id);
    device_frame->contacts = buffers.contacts
                                 ? device_view(reinterpret_cast<const float*>(buffers.contacts), {buffers.pair_count, 4},
                                               handle, device_type, device_id)
                                 : nb::none();
    device_frame->distances =
        buffers.distances ? device_view(buffers.distances, {buffers.pair_count}, handle, device_type, device_id) : nb::none();
    device_frame->closest_points =
        buffers.closest_points ? device_view(reinterpret_cast<const float*>(buffers.closest_points),
                                             {buffers.pair_count, 2, 3}, handle, device_type, device_id)
                               : nb::none();
    return nb::cast(device_frame.release(), nb::rv_policy::take_ownership);
}

nb::object detect(nb::handle handle, Arg<bool> device_results) {
    return completed_frame(handle, read_arg(device_results, "device_results"), &Detector::detect, "detect");
}

nb::object finish(nb::handle handle, Arg<bool> device_results) {
    return completed_frame(handle, read_arg(device_results, "device_results"), &Detector::finish, "finish");
}

nb::dict options_dict(const DetectorOptions& options) {
    nb::dict d;
    for (const OptionInfo& o : option_table()) {
        if (!o.shown_on(front_end_python)) continue;
        const long long value = o.get(options);
        if (o.type == OptionType::choice) d[o.name] = o.text(options);
        else if (o.type == OptionType::boolean) d[o.name] = value != 0;
        else if (o.type == OptionType::real) d[o.name] = o.real(options);
        else if (o.unset_by_default() && value == o.get(DetectorOptions{})) d[o.name] = nb::none();
        else d[o.name] = value;
    }
    d["cuda_stream"] = options.cuda_stream ? nb::cast(reinterpret_cast<std::uintptr_t>(options.cuda_stream)) : nb::none();
    return d;
}

/// "Detector(backend='cpu', method='kdet', ...": the names of the options that are choices.
std::string detector_repr(const Detector& detector) {
    std::string out = "Detector(";
    for (const OptionInfo& o : option_table())
        if (o.type == OptionType::choice && o.shown_on(front_end_python))
            out += std::string(o.name) + "='" + o.text(detector.options()) + "', ";
    return out + std::to_string(detector.object_count()) + " objects)";
}

/// Pairs as a (k, 2) uint32 array that owns a copy of them.
nb::ndarray<nb::numpy, std::uint32_t, nb::shape<-1, 2>> pair_array(const std::vector<IndexPair>& pairs) {
    auto* flat = new std::vector<std::uint32_t>();
    flat->reserve(2 * pairs.size() + 2); // never a null pointer, even without pairs
    for (const IndexPair& p : pairs) flat->insert(flat->end(), {p.first, p.second});
    nb::capsule owner(flat, [](void* held) noexcept { delete static_cast<std::vector<std::uint32_t>*>(held); });
    return {flat->data(), {pairs.size(), 2}, owner};
}

/// kdet.OPTIONS: Detector's keywords as the library's table describes them.
nb::dict options_table() {
    const nb::dict defaults = options_dict(DetectorOptions{});
    nb::dict table;
    for (const OptionInfo& o : option_table()) {
        if (!o.shown_on(front_end_python)) continue;
        nb::dict entry;
        const char* types[] = {"choice", "integer", "boolean", "real"};
        entry["type"] = types[static_cast<int>(o.type)];
        entry["default"] = defaults[o.name];
        if (o.type == OptionType::choice) entry["choices"] = names_of(o.name);
        if (o.type == OptionType::integer) entry["range"] = nb::make_tuple(o.min, o.max);
        entry["help"] = o.help;
        entry["flag"] = o.shown_on(front_end_cli) ? nb::cast(o.flag) : nb::none();
        entry["bench_flag"] = o.shown_on(front_end_bench) ? nb::cast(o.bench_flag) : nb::none();
        entry["locate"] = o.shown_on(front_end_locate);
        table[o.name] = entry;
    }
    return table;
}

void bind_module(nb::module_& m) {
    m.doc() = "kdet's extension module; use the kdet package, which re-exports it.";

    nb::exception<Error> error(m, "Error", PyExc_ValueError);
    error.attr("__doc__") = "Bad input to kdet (a file, an array, an index, a coordinate, an option): the "
                            "library's one-line message. A ValueError.";

    m.attr("BACKENDS") = names_of("backend");
    m.attr("METHODS") = names_of("method");
    m.attr("TESTS") = names_of("test");
    m.attr("HASHES") = names_of("hash");
    m.attr("OPTIONS") = options_table();
    m.attr("__version__") = KDET_VERSION_STRING;
    m.def("version", &kdet::version, "The version, with the git commit the library was built from when known.");
    m.def(
        "cuda_available", [] { return kdet::cuda_available(); },
        "True when the CUDA backend can run here (built with it, and a GPU present).");
    m.def(
        "cuda_unavailable_reason",
        []() -> std::optional<std::string> {
            std::string reason;
            if (kdet::cuda_available(&reason)) return std::nullopt;
            return reason;
        },
        "Why the CUDA backend cannot run here, or None when it can.");
}

/// write_gmsh and write_vtk: a writer whose format has a version, named as the file's header has it (the
/// first of @p versions is the default), and a binary form.
template <class Format>
void bind_versioned_writer(nb::module_& m, const char* name, void (*write)(const TetMesh&, const std::string&, const Format&),
                           const char* format_name, std::array<std::pair<const char*, decltype(Format::version)>, 2> versions,
                           const char* doc) {
    m.def(
        name,
        [write, format_name, versions](const TetMesh& mesh, const std::filesystem::path& path, const std::string& version,
                                       Arg<bool> binary) {
            Format format;
            format.binary = read_arg(binary, "binary");
            const auto known = std::find_if(versions.begin(), versions.end(), [&](const auto& v) { return version == v.first; });
            if (known == versions.end())
                throw Error(std::string("version: ") + format_name + " '" + version + "' is not written (" + versions[1].first +
                            " or " + versions[0].first + ")");
            format.version = known->second;
            nb::gil_scoped_release release;
            write(mesh, path.string(), format);
        },
        "mesh"_a, "path"_a, nb::kw_only(), "version"_a = versions[0].first, "binary"_a = false, doc);
}

void bind_mesh(nb::module_& m) {
    nb::class_<TetMesh>(m, "TetMesh",
                        "A tetrahedral mesh: vertices (n, 3) float64 and tets (m, 4) uint32, 0-based. Both are views "
                        "of the mesh's own memory (no copies).")
        .def(
            "__init__",
            [](TetMesh* self, nb::handle vertices, nb::handle tets, Arg<bool> allow_degenerate) {
                const bool degenerate = read_arg(allow_degenerate, "allow_degenerate");
                new (self) TetMesh(mesh_from_arrays(vertices, tets, degenerate, "vertices", "tets", "TetMesh"));
            },
            "vertices"_a, "tets"_a, nb::kw_only(), "allow_degenerate"_a = false,
            "Copies and checks the arrays as the readers check files (finite coordinates, indices in range, "
            "no zero-volume tets unless allow_degenerate).")
        .def_prop_ro(
            "vertices",
            [](nb::handle self) {
                TetMesh& mesh = nb::cast<TetMesh&>(self);
                return rows_view<double, 3>(mesh.positions.data(), mesh.num_vertices(), self);
            },
            "Vertex coordinates, (n, 3) float64.")
        .def_prop_ro(
            "tets",
            [](nb::handle self) {
                TetMesh& mesh = nb::cast<TetMesh&>(self);
                return rows_view<std::uint32_t, 4>(mesh.tets.data(), mesh.num_tets(), self);
            },
            "Vertex indices of each tetrahedron, (m, 4) uint32.")
        .def_prop_ro("num_vertices", &TetMesh::num_vertices)
        .def_prop_ro("num_tets", &TetMesh::num_tets)
        .def("to_meshio", &to_meshio, "A meshio.Mesh with one 'tetra' cell block (needs meshio).")
        .def("__repr__", [](const TetMesh& mesh) {
            return "TetMesh(" + std::to_string(mesh.num_vertices()) + " vertices, " + std::to_string(mesh.num_tets()) +
                   " tets)";
        });

    m.def(
        "read_tet_mesh",
        [](const std::filesystem::path& path, Arg<bool> allow_degenerate) {
            const ReadOptions options{read_arg(allow_degenerate, "allow_degenerate")};
            nb::gil_scoped_release release;
            return kdet::read_tet_mesh(path.string(), options);
        },
        "path"_a, nb::kw_only(), "allow_degenerate"_a = false,
        "Reads a tet mesh, the format chosen by the extension: .mesh (MEDIT), .msh (Gmsh 2.2/4.1), .vtk (legacy VTK), "
        ".node/.ele or no extension (TetGen). Bad input raises kdet.Error naming the file and line.");
    m.def(
        "write_tet_mesh",
        [](const TetMesh& mesh, const std::filesystem::path& path, Arg<bool> binary) {
            const WriteOptions options{read_arg(binary, "binary")};
            nb::gil_scoped_release release;
            kdet::write_tet_mesh(mesh, path.string(), options);
        },
        "mesh"_a, "path"_a, nb::kw_only(), "binary"_a = false,
        "Writes a tet mesh in the format its extension names (as read_tet_mesh reads it); binary applies to .msh "
        "and .vtk.");
    bind_versioned_writer<GmshFormat>(m, "write_gmsh", &kdet::write_gmsh, "Gmsh MSH", {{{"4.1", GmshVersion::v4_1}, {"2.2", GmshVersion::v2_2}}},
                                      "Writes a Gmsh MSH file, version '4.1' or '2.2', ASCII or binary, whatever the "
                                      "extension of path.");
    bind_versioned_writer<VtkFormat>(m, "write_vtk", &kdet::write_vtk, "legacy VTK", {{{"5.1", VtkVersion::v5_1}, {"4.2", VtkVersion::v4_2}}},
                                     "Writes a legacy VTK UNSTRUCTURED_GRID, version '5.1' (VTK 9's OFFSETS/CONNECTIVITY) "
                                     "or '4.2' (classic CELLS), ASCII or binary, whatever the extension of path.");
    m.def(
        "read_surface",
        [](const std::filesystem::path& path) {
            auto* surface = new TriangleMesh();
            try {
                nb::gil_scoped_release release;
                *surface = kdet::read_surface(path.string());
            } catch (...) {
                delete surface;
                throw;
            }
            nb::capsule owner(surface, [](void* held) noexcept { delete static_cast<TriangleMesh*>(held); });
            return std::make_pair(rows_view<double, 3>(surface->positions.data(), surface->num_vertices(), owner),
                                  rows_view<std::uint32_t, 3>(surface->triangles.data(), surface->num_triangles(), owner));
        },
        "path"_a,
        "Reads a triangle surface (.obj, .off, .stl, .ply): (vertices (n, 3) float64, triangles (m, 3) uint32, "
        "0-based). Bad input raises kdet.Error naming the file and line.");
    m.def(
        "read_points",
        [](const std::filesystem::path& path) {
            auto* xyz = new std::vector<double>();
            try {
                nb::gil_scoped_release release;
                *xyz = kdet::read_points(path.string());
            } catch (...) {
                delete xyz;
                throw;
            }
            nb::capsule owner(xyz, [](void* held) noexcept { delete static_cast<std::vector<double>*>(held); });
            return rows_view<double, 3>(xyz->data(), xyz->size() / 3, owner);
        },
        "path"_a,
        "Reads query points as `kdet locate` does: a text file of `x y z` lines (# starts a comment), or any tet "
        "mesh file, whose vertices are the points. Returns (n, 3) float64; bad input raises kdet.Error naming the "
        "file and line.");
    m.def(
        "validate_tet_mesh",
        [](const TetMesh& mesh, const std::string& source, Arg<bool> allow_degenerate) {
            kdet::validate_tet_mesh(mesh, source, ReadOptions{read_arg(allow_degenerate, "allow_degenerate")});
        },
        "mesh"_a, "source"_a = "TetMesh", nb::kw_only(), "allow_degenerate"_a = false,
        "Checks a mesh as the readers check files (finite coordinates, indices in range, no zero-volume tets "
        "unless allow_degenerate), for one whose arrays were changed in place; raises kdet.Error naming source "
        "and the first bad vertex or tet.");
    m.def("from_meshio", &from_meshio, "mesh"_a, nb::kw_only(), "allow_degenerate"_a = false,
          "A TetMesh from a meshio.Mesh: its points and its 'tetra' (and 'tetra10' corner) cells.");
}

void bind_results(nb::module_& m) {
    bind_fields<FrameCounts>(m, "FrameCounts", "Sizes of one detection.");
    bind_fields<StageTimes>(m, "StageTimes", "Milliseconds spent in each stage of one detection.");

    nb::class_<Frame>(m, "FrameResult", "The result of one detect(), valid for as long as it is kept.")
        .def_prop_ro(
            "pairs",
            [](nb::handle self) {
                FrameResult& r = nb::cast<Frame&>(self).result;
                static_assert(sizeof(TetPair) == 4 * sizeof(std::uint32_t), "TetPair is read as four uint32");
                return rows_view<std::uint32_t, 4>(reinterpret_cast<std::uint32_t*>(r.pairs.data()), r.pairs.size(), self);
            },
            "Colliding pairs, (k, 4) uint32 rows (object_a, tet_a, object_b, tet_b), sorted and unique. Empty for "
            "method 'kdet_no_pairs'.")
        .def_prop_ro(
            "contacts",
            [](nb::handle self) {
                Frame& f = nb::cast<Frame&>(self);
                static_assert(sizeof(Contact) == 4 * sizeof(float), "Contact is read as four float32");
                return per_pair_floats(self, f.contacts_enabled, f.result.contacts, {4});
            },
            "Per pair (depth, nx, ny, nz) float32: moving tet b by depth along n separates the pair. None unless the "
            "detector was made with contacts=True.")
        .def_prop_ro(
            "distances",
            [](nb::handle self) {
                Frame& f = nb::cast<Frame&>(self);
                return per_pair_floats(self, f.distances_enabled, f.result.distances, {});
            },
            "Per pair its distance, float32 (k,): 0 where the tets intersect. None unless the detector was made with "
            "distances=True.")
        .def_prop_ro(
            "closest_points",
            [](nb::handle self) {
                Frame& f = nb::cast<Frame&>(self);
                static_assert(sizeof(ClosestPoints) == 6 * sizeof(float), "ClosestPoints is read as six float32");
                return per_pair_floats(self, f.distances_enabled, f.result.closest_points, {2, 3});
            },
            "Per pair a closest point on tet a, then on tet b, float32 (k, 2, 3); one common point twice where they "
            "intersect. None unless the detector was made with distances=True.")
        .def_prop_ro(
            "colliding",
            [](nb::handle self) {
                FrameResult& r = nb::cast<Frame&>(self).result;
                nb::list flags;
                for (std::vector<std::uint8_t>& object : r.colliding)
                    flags.append(nb::ndarray<nb::numpy, bool, nb::ndim<1>>(reinterpret_cast<bool*>(object.data()),
                                                                          {object.size()}, self));
                return flags;
            },
            "Per object, a bool array with one flag per tet: True when the tet collides.")
        .def_prop_ro(
            "counts", [](const Frame& f) { return f.result.counts; }, "Sizes of this detection (FrameCounts).")
        .def_prop_ro(
            "times", [](const Frame& f) { return f.result.times; }, "Milliseconds per stage (StageTimes).")
        .def_prop_ro(
            "memory_bytes", [](const Frame& f) { return f.result.memory_bytes; }, "Bytes held by the detector's buffers.")
        .def_prop_ro(
            "grid_bytes", [](const Frame& f) { return f.result.grid_bytes; }, "Of which the grid's hash table.")
        .def_prop_ro(
            "candidate_bytes", [](const Frame& f) { return f.result.candidate_bytes; },
            "Of which the candidate pair buffer.")
        .def("__repr__", [](const Frame& f) {
            return "FrameResult(" + std::to_string(f.result.pairs.size()) + " pairs, " +
                   std::to_string(f.result.counts.colliding_tets) + " colliding tets, " +
                   std::to_string(f.result.times.total) + " ms)";
        });

    nb::class_<DeviceFrame>(m, "DeviceFrameResult",
                            "The result of detect(device_results=True): DLPack arrays of the detector's own buffers "
                            "(GPU memory on the CUDA backend), valid until the next detect(). Tets are numbered "
                            "globally: object o's tet i is Detector.first_tet(o) + i.")
        .def_ro("pair_keys", &DeviceFrame::pair_keys,
                "uint64 (k,): (global_a << 32) | global_b per colliding pair, global_a < global_b, sorted.")
        .def_ro("colliding", &DeviceFrame::colliding, "uint32 (tets,): nonzero where the global tet collides.")
        .def_ro("contacts", &DeviceFrame::contacts, "float32 (k, 4) (depth, nx, ny, nz), or None without contacts.")
        .def_ro("distances", &DeviceFrame::distances, "float32 (k,) per pair, or None without distances.")
        .def_ro("closest_points", &DeviceFrame::closest_points,
                "float32 (k, 2, 3) per pair, or None without distances.")
        .def_ro("counts", &DeviceFrame::counts)
        .def_ro("times", &DeviceFrame::times)
        .def_ro("memory_bytes", &DeviceFrame::memory_bytes);
}

void bind_detector(nb::module_& m) {
    nb::class_<PyDetector> detector(m, "Detector",
                           "Finds colliding tets frame after frame, keeping its buffers between frames: add objects, "
                           "then per frame set_positions() for those that moved and detect(). Pairs of different "
                           "objects are checked, self-collision is off, until switched.");
    detector
        .def(
            "__init__",
            [](PyDetector* self, const nb::kwargs& keywords) {
                const DetectorOptions options = options_from_keywords(keywords);
                nb::gil_scoped_release release;
                new (self) PyDetector(options);
            },
            nb::sig(detector_signature()),
            "Names (backend, method, test, hash) are those of kdet.BACKENDS, METHODS, TESTS and HASHES, in any case, "
            "'-' or '_'. threads=None uses all cores. contacts=True adds depth and direction per pair. margin=D reports every "
            "pair at most D apart; distances=True adds each pair's distance and closest points. cuda_stream "
            "(backend='cuda'): the stream all of the detector's GPU work runs on, as an int or a stream object "
            "(PyTorch, CuPy, Warp, __cuda_stream__); None is the default stream. "
            "results_to_host=False keeps results on the device (detect(device_results=True)).")
        .def("add_object",
             [](PyDetector& self, const TetMesh& mesh) {
                 return locked(self, [&] { return self.detector.add_object(mesh); });
             },
             "mesh"_a, "Adds a TetMesh; returns its object id.")
        .def("add_object", &add_object, "vertices"_a, "tets"_a,
             "Adds an object from its rest-shape vertices (n, 3) float32/float64 and tets (m, 4) integers; returns its "
             "object id.")
        .def("set_positions", &set_positions, "object"_a, "positions"_a,
             "Replaces an object's vertex positions: (n, 3) float32/float64, any strides; on the CUDA backend also a GPU "
             "array (__dlpack__ or __cuda_array_interface__), which never passes through the host: it is checked by "
             "the next detect(), which raises kdet.Error on a non-finite value and keeps the previous positions.")
        .def(
            "set_self_collision",
            [](PyDetector& self, Arg<std::int64_t> object, Arg<bool> enabled) {
                const ObjectId id = object_id(self, object);
                const bool on = read_arg(enabled, "enabled");
                locked(self, [&] { self.detector.set_self_collision(id, on); });
            },
            "object"_a, "enabled"_a = true, "Switches self-collision of one object (off by default).")
        .def(
            "set_pair_collision",
            [](PyDetector& self, Arg<std::int64_t> a, Arg<std::int64_t> b, Arg<bool> enabled) {
                const ObjectId ia = object_id(self, a, "a"), ib = object_id(self, b, "b");
                const bool on = read_arg(enabled, "enabled");
                locked(self, [&] { self.detector.set_pair_collision(ia, ib, on); });
            },
            "a"_a, "b"_a, "enabled"_a, "Switches collision between two different objects (on by default).")
        .def(
            "set_static",
            [](PyDetector& self, Arg<std::int64_t> object, Arg<bool> is_static) {
                const ObjectId id = object_id(self, object);
                const bool fixed = read_arg(is_static, "is_static");
                locked(self, [&] { self.detector.set_static(id, fixed); });
            },
            "object"_a, "is_static"_a = true,
            "Marks an object static (placed once, kept across frames; set_positions places it again) or moving. "
            "Pairs of two static objects are never reported.")
        .def(
            "is_static",
            [](PyDetector& self, Arg<std::int64_t> object) {
                const ObjectId id = object_id(self, object);
                return locked(self, [&] { return self.detector.is_static(id); });
            },
            "object"_a, "Whether set_static marked the object static.")
        .def("detect", &detect, "device_results"_a = false,
             nb::sig("def detect(self, device_results: bool = False) -> FrameResult | DeviceFrameResult"),
             "Runs one detection (without the GIL). Returns a FrameResult, or with device_results=True a "
             "DeviceFrameResult of DLPack arrays in the backend's memory.")
        .def(
            "detect_async", [](PyDetector& self) { locked(self, [&] { self.detector.detect_async(); }); },
            "Starts one detection and returns without waiting for the backend (on the CUDA backend everything "
            "is enqueued on the detector's cuda_stream). finish() completes it; results cannot be read before.")
        .def("finish", &finish, "device_results"_a = false,
             nb::sig("def finish(self, device_results: bool = False) -> FrameResult | DeviceFrameResult"),
             "Completes the detection detect_async() started (one wait; a buffer that was too small grows and "
             "the frame runs again) and returns what detect() returns.")
        .def(
            "locate",
            [](nb::handle handle, nb::handle points, nb::handle object, nb::handle within, Arg<bool> device_results) {
                PyDetector& self = nb::cast<PyDetector&>(handle);
                return detector_locate(handle, self.detector, self.mutex, points, object, within,
                                       read_arg(device_results, "device_results"));
            },
            "points"_a, "object"_a = nb::none(), "within"_a = nb::none(), "device_results"_a = false,
            "Point location in one object (or all: None) at the positions as last set: kdet.locate()'s LocateResult, "
            "points (n, 3) host or GPU arrays; device_results=True gives DLPack arrays of the detector's buffers.")
        .def(
            "first_tet",
            [](PyDetector& self, Arg<std::int64_t> object) { return self.detector.first_tet(object_id(self, object)); },
            "object"_a, "Global id of the object's first tet (see DeviceFrameResult).")
        .def(
            "tet_count",
            [](PyDetector& self, Arg<std::int64_t> object) { return self.detector.tet_count(object_id(self, object)); },
            "object"_a)
        .def_prop_ro("object_count", [](PyDetector& self) { return self.detector.object_count(); })
        .def_prop_ro(
            "memory_bytes", [](PyDetector& self) { return locked(self, [&] { return self.detector.memory_bytes(); }); },
            "Bytes held by the detector's buffers (device memory on the CUDA backend).")
        .def_prop_ro(
            "device_name", [](PyDetector& self) { return self.detector.device_name(); },
            "The CPU model or GPU name the detector runs on.")
        .def_prop_ro(
            "options", [](PyDetector& self) { return options_dict(self.detector.options()); },
            "The detector's settings, names as the library spells them.")
        .def("__repr__", [](PyDetector& self) { return detector_repr(self.detector); });
    bind_filters(detector);
}

void bind_collide(nb::module_& m) {
    m.def(
        "collide",
        [](const TetMesh& a, const TetMesh& b, const nb::kwargs& keywords) {
            const DetectorOptions options = options_from_keywords(keywords);
            std::vector<IndexPair> pairs;
            {
                nb::gil_scoped_release release;
                pairs = kdet::collide(a, b, options);
            }
            return pair_array(pairs);
        },
        "a"_a, "b"_a, "options"_a,
        "The library's one-off collide(): the colliding pairs (tet of a, tet of b) as a (k, 2) uint32 array, "
        "sorted. options are Detector's keywords.");
    m.def(
        "collide_self",
        [](const TetMesh& mesh, const nb::kwargs& keywords) {
            const DetectorOptions options = options_from_keywords(keywords);
            std::vector<IndexPair> pairs;
            {
                nb::gil_scoped_release release;
                pairs = kdet::collide_self(mesh, options);
            }
            return pair_array(pairs);
        },
        "mesh"_a, "options"_a,
        "The library's one-off collide_self(): the colliding pairs i < j inside one mesh as a (k, 2) uint32 "
        "array, sorted. options are Detector's keywords.");
}

} // namespace

} // namespace kdet::python

NB_MODULE(_kdet, m) {
    using namespace kdet::python;
    bind_module(m);
    bind_mesh(m);
    bind_results(m);
    bind_detector(m);
    bind_collide(m);
    bind_locate(m, &options_from_keywords);
    bind_scenes(m);
}
