#include "arrays.hpp"

#include <kdet/error.hpp>

#include <limits>

namespace kdet::python {

namespace {

/// "float32", "int64", "bool", ...: how NumPy spells a DLPack dtype.
std::string dtype_name(nb::dlpack::dtype dtype) {
    using code = nb::dlpack::dtype_code;
    const char* kind = "unknown";
    switch (static_cast<code>(dtype.code)) {
    case code::Int: kind = "int"; break;
    case code::UInt: kind = "uint"; break;
    case code::Float: kind = "float"; break;
    case code::Bfloat: kind = "bfloat"; break;
    case code::Complex: kind = "complex"; break;
    case code::Bool: return "bool";
    default: break;
    }
    return kind + std::to_string(dtype.bits);
}

std::string shape_text(const std::vector<std::size_t>& shape) {
    std::string out = "(";
    for (std::size_t i = 0; i < shape.size(); ++i) out += (i ? ", " : "") + std::to_string(shape[i]);
    return out + (shape.size() == 1 ? ",)" : ")");
}

/// Throws unless @p shape is (n, columns).
void check_shape(const std::vector<std::size_t>& shape, std::size_t columns, const char* name) {
    if (shape.size() != 2 || shape[1] != columns)
        throw Error(std::string(name) + ": expected an array of shape (n, " + std::to_string(columns) + "), got shape " +
                    shape_text(shape));
}

/// An array export of @p object (DLPack or buffer protocol); a list or tuple goes through numpy.asarray
/// first, so that nested sequences work as they do in NumPy. @p owner keeps a converted array alive.
nb::ndarray<nb::ro> exported_array(nb::handle object, const char* name, nb::object& owner, const char* expected) {
    nb::ndarray<nb::ro> array;
    if (nb::try_cast(object, array, false)) return array;
    // NumPy arrays in a non-native byte order (big-endian VTK data) export neither DLPack nor a buffer;
    // NumPy converts them, and anything else that has __array__.
    const bool sequence = nb::isinstance<nb::list>(object) || nb::isinstance<nb::tuple>(object);
    if (sequence || nb::hasattr(object, "__array__")) {
        const nb::object numpy = nb::module_::import_("numpy");
        try {
            owner = numpy.attr("asarray")(object);
            if (!nb::cast<bool>(owner.attr("dtype").attr("isnative")))
                owner = owner.attr("astype")(owner.attr("dtype").attr("newbyteorder")("="));
        } catch (const nb::python_error& error) {
            throw nb::type_error((std::string(name) + ": cannot read " + (sequence ? "the sequence" : type_label(object)) +
                                  " as an array: " + error.what())
                                     .c_str());
        }
        if (nb::try_cast(owner, array, false)) return array;
    }
    throw nb::type_error((std::string(name) + ": expected " + expected + ", got " + type_label(object)).c_str());
}

/// Reads __cuda_array_interface__ (version 2 or 3): shape, typestr, data, strides in bytes, stream.
Coordinates from_cuda_array_interface(nb::handle object, const char* name);

} // namespace

std::string type_label(nb::handle object) {
    // Python's own types by name, others with their module: np.bool_ reads "numpy.bool", not "bool", and
    // kdet's own as the package exports them.
    const nb::handle type(reinterpret_cast<PyObject*>(Py_TYPE(object.ptr())));
    const std::string name = nb::cast<std::string>(type.attr("__qualname__"));
    const nb::object module_name = nb::getattr(type, "__module__", nb::none());
    if (!nb::isinstance<nb::str>(module_name)) return name;
    const std::string module = nb::cast<std::string>(module_name);
    if (module == "builtins") return name;
    return (module == "kdet._kdet" ? std::string("kdet") : module) + "." + name;
}

Coordinates coordinates(nb::handle object, const char* name) {
    if (nb::hasattr(object, "__cuda_array_interface__")) return from_cuda_array_interface(object, name);
    Coordinates c;
    c.array = exported_array(object, name, c.owner, "an array of shape (n, 3) (NumPy, DLPack or a sequence)");
    std::vector<std::size_t> shape;
    for (std::size_t i = 0; i < c.array.ndim(); ++i) shape.push_back(c.array.shape(i));
    const nb::dlpack::dtype dtype = c.array.dtype();
    if (dtype != nb::dtype<float>() && dtype != nb::dtype<double>()) {
        // A sequence of Python ints is a fine way to write coordinates: read it as float64.
        if (c.owner.is_valid() && (dtype.code == static_cast<std::uint8_t>(nb::dlpack::dtype_code::Int))) {
            c.owner = nb::module_::import_("numpy").attr("asarray")(object, "float64");
            return coordinates(c.owner, name);
        }
        throw nb::type_error(
            (std::string(name) + ": dtype " + dtype_name(dtype) + " is not supported; use float32 or float64").c_str());
    }
    check_shape(shape, 3, name);
    const int device = c.array.device_type();
    if (device == nb::device::cuda::value || device == nb::device::cuda_managed::value) {
        c.on_device = true;
    } else if (device != nb::device::cpu::value && device != nb::device::cuda_host::value) {
        throw nb::type_error((std::string(name) + ": arrays on DLPack device type " + std::to_string(device) +
                              " are not supported (host or CUDA memory only)")
                                 .c_str());
    }
    c.data = c.array.data();
    c.rows = shape[0];
    c.row_stride = c.array.stride(0);
    c.column_stride = c.array.stride(1);
    c.is_double = dtype == nb::dtype<double>();
    return c;
}

namespace {

template <class Scalar>
void copy_rows(const Coordinates& c, double* out) {
    const auto* source = static_cast<const Scalar*>(c.data);
    for (std::size_t v = 0; v < c.rows; ++v)
        for (std::size_t k = 0; k < 3; ++k)
            out[3 * v + k] = source[static_cast<std::int64_t>(v) * c.row_stride + static_cast<std::int64_t>(k) * c.column_stride];
}

} // namespace

void check_reads_cuda_arrays(const Detector& detector, const char* name) {
#ifdef KDET_HAS_CUDA
    if (detector.options().backend != Backend::cuda)
        throw Error(std::string(name) + ": a CUDA array needs a detector with backend='cuda'; this one runs on the " +
                    to_string(detector.options().backend));
#else
    (void)detector;
    throw Error(std::string(name) + ": a CUDA array needs kdet built with its CUDA backend (this build has none)");
#endif
}

void copy_xyz(const Coordinates& c, double* out) {
    if (c.is_double)
        copy_rows<double>(c, out);
    else
        copy_rows<float>(c, out);
}

namespace {

template <class Integer>
void convert_indices(const TetIndices& t, const void* data, std::int64_t row_stride, std::int64_t column_stride,
                     std::vector<std::uint32_t>& out, const char* name) {
    const auto* source = static_cast<const Integer*>(data);
    out.resize(4 * t.rows);
    for (std::size_t r = 0; r < t.rows; ++r)
        for (std::size_t k = 0; k < 4; ++k) {
            const Integer value =
                source[static_cast<std::int64_t>(r) * row_stride + static_cast<std::int64_t>(k) * column_stride];
            if constexpr (std::is_signed_v<Integer>) {
                if (value < 0)
                    throw Error(std::string(name) + ": tet " + std::to_string(r) + " has the negative vertex index " +
                                std::to_string(value));
            }
            if (static_cast<std::uint64_t>(value) > std::numeric_limits<std::uint32_t>::max())
                throw Error(std::string(name) + ": tet " + std::to_string(r) + " has vertex index " +
                            std::to_string(value) + ", beyond 32 bits");
            out[4 * r + k] = static_cast<std::uint32_t>(value);
        }
}

Coordinates from_cuda_array_interface(nb::handle object, const char* name) {
    Coordinates c;
    c.owner = nb::borrow(object);
    const std::string where = std::string(name) + ": __cuda_array_interface__";
    nb::dict interface;
    if (!nb::try_cast(object.attr("__cuda_array_interface__"), interface))
        throw nb::type_error((where + " is not a dict").c_str());
    std::vector<std::size_t> shape;
    std::string typestr;
    nb::tuple data;
    if (!interface.contains("shape") || !interface.contains("typestr") || !interface.contains("data") ||
        !nb::try_cast(interface["shape"], shape) || !nb::try_cast(interface["typestr"], typestr) ||
        !nb::try_cast(interface["data"], data) || data.size() != 2)
        throw nb::type_error((where + " lacks a valid shape, typestr or data entry").c_str());
    if (typestr != "<f4" && typestr != "<f8")
        throw nb::type_error((std::string(name) + ": dtype " + typestr + " is not supported; use float32 or float64").c_str());
    check_shape(shape, 3, name);
    c.is_double = typestr == "<f8";
    const std::int64_t item = c.is_double ? 8 : 4;
    c.rows = shape[0];
    c.data = reinterpret_cast<const void*>(nb::cast<std::uintptr_t>(data[0]));
    if (interface.contains("strides") && !interface["strides"].is_none()) {
        std::vector<std::int64_t> strides;
        if (!nb::try_cast(interface["strides"], strides) || strides.size() != 2 || strides[0] % item || strides[1] % item)
            throw Error(where + ": strides must be two multiples of the item size");
        c.row_stride = strides[0] / item;
        c.column_stride = strides[1] / item;
    }
    if (interface.contains("mask") && !interface["mask"].is_none())
        throw nb::type_error((where + ": masked arrays are not supported").c_str());
    if (interface.contains("stream") && !interface["stream"].is_none()) c.stream = nb::cast<std::uintptr_t>(interface["stream"]);
    c.on_device = true;
    return c;
}

} // namespace

TetIndices tet_indices(nb::handle object, const char* name) {
    TetIndices t;
    t.array = exported_array(object, name, t.owner, "an array of shape (m, 4) of vertex indices (NumPy, DLPack or a sequence)");
    std::vector<std::size_t> shape;
    for (std::size_t i = 0; i < t.array.ndim(); ++i) shape.push_back(t.array.shape(i));
    const nb::dlpack::dtype dtype = t.array.dtype();
    using code = nb::dlpack::dtype_code;
    if (dtype.lanes != 1 || (dtype.code != static_cast<std::uint8_t>(code::Int) &&
                             dtype.code != static_cast<std::uint8_t>(code::UInt)))
        throw nb::type_error((std::string(name) + ": dtype " + dtype_name(dtype) +
                              " is not supported; vertex indices must be integers (uint32 is read without a copy)")
                                 .c_str());
    check_shape(shape, 4, name);
    if (t.array.device_type() != nb::device::cpu::value && t.array.device_type() != nb::device::cuda_host::value)
        throw nb::type_error((std::string(name) + ": vertex indices must be in host memory").c_str());
    t.rows = shape[0];
    const std::int64_t rs = t.array.stride(0), cs = t.array.stride(1);
    if (dtype == nb::dtype<std::uint32_t>() && cs == 1 && (t.rows <= 1 || rs == 4)) {
        t.data = static_cast<const std::uint32_t*>(t.array.data());
        return t;
    }
    const void* data = t.array.data();
    const bool is_signed = dtype.code == static_cast<std::uint8_t>(code::Int);
    switch (dtype.bits) {
    case 8: is_signed ? convert_indices<std::int8_t>(t, data, rs, cs, t.storage, name)
                      : convert_indices<std::uint8_t>(t, data, rs, cs, t.storage, name); break;
    case 16: is_signed ? convert_indices<std::int16_t>(t, data, rs, cs, t.storage, name)
                       : convert_indices<std::uint16_t>(t, data, rs, cs, t.storage, name); break;
    case 32: is_signed ? convert_indices<std::int32_t>(t, data, rs, cs, t.storage, name)
                       : convert_indices<std::uint32_t>(t, data, rs, cs, t.storage, name); break;
    case 64: is_signed ? convert_indices<std::int64_t>(t, data, rs, cs, t.storage, name)
                       : convert_indices<std::uint64_t>(t, data, rs, cs, t.storage, name); break;
    default: throw nb::type_error((std::string(name) + ": dtype " + dtype_name(dtype) + " is not supported").c_str());
    }
    t.data = t.storage.data();
    return t;
}

} // namespace kdet::python
