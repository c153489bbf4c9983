#pragma once
/// @file scalars.hpp
/// @brief Scalars coming from Python: Python's own bool, int and float, and NumPy scalars of the same
/// kind (np.bool_, np.int64, np.float32, ...), which indexing and reducing NumPy arrays give. A bool is
/// never read as a number, nor a number as a bool.

#include <nanobind/nanobind.h>

#include <cstdint>

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

/// @brief A bool or int argument that a binding reads itself with read_arg(): nanobind passes any value
/// through, so that one of the wrong type gets a one-line TypeError naming the argument ("enabled:
/// expected a bool, got int") rather than nanobind's list of every signature. A bool takes np.bool_,
/// an int NumPy integers; stubs and help() show the type as @p T's.
template <class T>
struct Arg {
    nb::handle value;
};

/// @brief The bool @p arg holds, or a TypeError naming @p name.
bool read_arg(Arg<bool> arg, const char* name);

/// @brief The int @p arg holds, or a TypeError naming @p name (a kdet.Error for one beyond 64 bits).
std::int64_t read_arg(Arg<std::int64_t> arg, const char* name);

/// @brief As the 64-bit read, with a kdet.Error naming @p name for a value beyond an int's range.
int read_arg(Arg<int> arg, const char* name);

} // namespace kdet::python

namespace nanobind::detail {

template <class T>
struct type_caster<kdet::python::Arg<T>> {
    NB_TYPE_CASTER(kdet::python::Arg<T>, make_caster<T>::Name)

    bool from_python(handle src, uint8_t, cleanup_list*) noexcept {
        value.value = src;
        return true;
    }
};

} // namespace nanobind::detail
