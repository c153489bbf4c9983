#include "scalars.hpp"

#include "arrays.hpp"

#include <kdet/error.hpp>

#include <nanobind/stl/string.h>

#include <limits>
#include <string>

namespace kdet::python {
namespace {

/// The dtype kind ('b', 'i', 'u', 'f', ...) of a NumPy scalar, 0 for anything else. NumPy is imported
/// only when the type is not one of Python's own.
char numpy_kind(nb::handle value) {
    const nb::object numpy = nb::module_::import_("numpy");
    if (PyObject_IsInstance(value.ptr(), numpy.attr("generic").ptr()) != 1) return 0;
    return nb::cast<std::string>(value.attr("dtype").attr("kind"))[0];
}

/// The int @p value holds, or a TypeError naming @p name; @p overflow is set beyond a long long.
long long integer_arg(nb::handle value, const char* name, bool& overflow) {
    long long out = 0;
    if (!read_integer(value, out, overflow))
        throw nb::type_error((std::string(name) + ": expected an int, got " + type_label(value)).c_str());
    return out;
}

[[noreturn]] void beyond(nb::handle value, const char* name, const char* bits) {
    throw Error(std::string(name) + ": " + nb::cast<std::string>(nb::str(value)) + " is beyond a " + bits + " integer");
}

} // namespace

bool read_bool(nb::handle value, bool& out) {
    if (PyBool_Check(value.ptr())) {
        out = value.ptr() == Py_True;
        return true;
    }
    if (PyLong_Check(value.ptr()) || PyFloat_Check(value.ptr()) || numpy_kind(value) != 'b') return false;
    out = PyObject_IsTrue(value.ptr()) == 1;
    return true;
}

bool read_integer(nb::handle value, long long& out, bool& overflow) {
    if (PyBool_Check(value.ptr()) || PyFloat_Check(value.ptr())) return false;
    if (!PyLong_Check(value.ptr())) {
        const char kind = numpy_kind(value);
        if (kind != 'i' && kind != 'u') return false;
    }
    const nb::object index = nb::steal(PyNumber_Index(value.ptr()));
    if (!index.is_valid()) throw nb::python_error();
    int too_large = 0;
    out = PyLong_AsLongLongAndOverflow(index.ptr(), &too_large);
    overflow = too_large != 0;
    return true;
}

bool read_real(nb::handle value, double& out) {
    if (PyBool_Check(value.ptr())) return false;
    if (!PyFloat_Check(value.ptr()) && !PyLong_Check(value.ptr())) {
        const char kind = numpy_kind(value);
        if (kind != 'f' && kind != 'i' && kind != 'u') return false;
    }
    out = PyFloat_AsDouble(value.ptr());
    if (out == -1.0 && PyErr_Occurred()) {
        if (!PyErr_ExceptionMatches(PyExc_OverflowError)) throw nb::python_error();
        PyErr_Clear(); // an int beyond a double's range
        const bool negative = PyObject_RichCompareBool(value.ptr(), nb::int_(0).ptr(), Py_LT) == 1;
        out = negative ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
    }
    return true;
}

bool read_arg(Arg<bool> arg, const char* name) {
    bool out = false;
    if (!read_bool(arg.value, out))
        throw nb::type_error((std::string(name) + ": expected a bool, got " + type_label(arg.value)).c_str());
    return out;
}

std::int64_t read_arg(Arg<std::int64_t> arg, const char* name) {
    bool overflow = false;
    const long long out = integer_arg(arg.value, name, overflow);
    if (overflow) beyond(arg.value, name, "64-bit");
    return out;
}

int read_arg(Arg<int> arg, const char* name) {
    bool overflow = false;
    const long long out = integer_arg(arg.value, name, overflow);
    if (overflow || out < std::numeric_limits<int>::min() || out > std::numeric_limits<int>::max())
        beyond(arg.value, name, "32-bit");
    return static_cast<int>(out);
}

} // namespace kdet::python
