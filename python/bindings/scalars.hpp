#pragma once
/// @file scalars.hpp
/// @brief Scalars coming from Python: Python's own bool, int and float, and NumPy scalars of the same
/// kind (np.bool_, np.int64, np.float32, ...), which indexing and reducing NumPy arrays give. A bool is
/// never read as a number, nor a number as a bool.

#include <nanobind/nanobind.h>

namespace kdet::python {

namespace nb = nanobind;

/// @brief Reads a bool or np.bool_ into @p out; false (and @p out untouched) for any other type.
bool read_bool(nb::handle value, bool& out);

/// @brief Reads an int or NumPy integer into @p out; false for any other type. @p overflow is set
/// when the value does not fit a long long.
bool read_integer(nb::handle value, long long& out, bool& overflow);

/// @brief Reads a float, an int or a NumPy floating or integer scalar into @p out (an int too large for a
/// double reads as an infinity of its sign); false for any other type.
bool read_real(nb::handle value, double& out);

/// @brief A bool argument of a binding that also takes np.bool_ (nanobind's bool takes True and False
/// alone); stubs and help() show it as bool.
struct Flag {
    bool value = false;
    operator bool() const { return value; }
};

} // namespace kdet::python

namespace nanobind::detail {

template <>
struct type_caster<kdet::python::Flag> {
    NB_TYPE_CASTER(kdet::python::Flag, const_name("bool"))

    bool from_python(handle src, uint8_t, cleanup_list*) noexcept {
        // read_bool may import NumPy, which can raise; a failed read is a plain mismatch here.
        try {
            return kdet::python::read_bool(src, value.value);
        } catch (...) {
            PyErr_Clear();
            return false;
        }
    }
    static handle from_cpp(kdet::python::Flag flag, rv_policy, cleanup_list*) noexcept {
        return handle(flag.value ? Py_True : Py_False).inc_ref();
    }
};

} // namespace nanobind::detail
