#pragma once
/// @file arrays.hpp
/// @brief Arrays coming from Python: NumPy and anything with the buffer protocol or __dlpack__ (PyTorch,
/// CuPy, JAX, Warp), objects with __cuda_array_interface__ (Numba, CuPy, Warp), and plain sequences.
/// They are read where they lie, in their own dtype and strides; every wrong type names the argument
/// in a TypeError and every wrong shape or value in a kdet.Error.

#include <kdet/detector.hpp>

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace kdet::python {

namespace nb = nanobind;

/// @brief An (n, 3) array of float32 or float64 coordinates as its owner holds it, host or CUDA memory.
struct Coordinates {
    nb::ndarray<nb::ro> array; ///< keeps a DLPack or buffer-protocol export alive
    nb::object owner;          ///< keeps a __cuda_array_interface__ or converted sequence alive
    const void* data = nullptr;
    std::size_t rows = 0;
    std::int64_t row_stride = 3;    ///< in elements
    std::int64_t column_stride = 1; ///< in elements
    bool is_double = false;
    bool on_device = false; ///< CUDA device (or managed) memory
    /// A CUDA stream that the producer's writes are ordered on (__cuda_array_interface__'s "stream";
    /// 0 when none is given): kdet waits for it before reading.
    std::uintptr_t stream = 0;

    /// @brief The layout as the Detector reads it, where it lies.
    PositionsView view() const { return PositionsView{data, is_double, rows, row_stride, column_stride}; }
};

/// @brief Reads @p object (the argument @p name) as coordinates, without copying.
Coordinates coordinates(nb::handle object, const char* name);

/// @brief Throws unless @p detector can read the CUDA array given as the argument @p name: kdet built
/// with CUDA and the detector on that backend (a CPU detector would read GPU memory as host memory).
void check_reads_cuda_arrays(const Detector& detector, const char* name);

/// @brief Copies host coordinates into x y z per vertex, float64 (a TetMesh's vertices).
void copy_xyz(const Coordinates& c, double* out);

/// @brief (m, 4) vertex indices of any integer dtype, as uint32 (host memory only).
struct TetIndices {
    nb::ndarray<nb::ro> array;
    nb::object owner;
    const std::uint32_t* data = nullptr;
    std::size_t rows = 0;
    std::vector<std::uint32_t> storage; ///< used when the input is not C-contiguous uint32
};

/// @brief Reads @p object (the argument @p name) as tetrahedra; copies only when the dtype is not
/// uint32 or the layout not C-contiguous. Negative or too large indices are a kdet.Error.
TetIndices tet_indices(nb::handle object, const char* name);

/// @brief The Python type name of @p object, for messages.
std::string type_label(nb::handle object);

} // namespace kdet::python
