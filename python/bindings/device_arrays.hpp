#pragma once
/// @file device_arrays.hpp
/// @brief The CUDA side of the Python package (built only with the CUDA backend): positions that a GPU
/// array holds in float64 or with strides are gathered into float32 x y z on the device, so that they
/// never pass through the host.

#include <cstddef>
#include <cstdint>

namespace kdet::python {

/// @brief Device memory for gathered positions, grown as needed and kept between frames.
class DeviceScratch {
public:
    DeviceScratch() = default;
    ~DeviceScratch();
    DeviceScratch(const DeviceScratch&) = delete;
    DeviceScratch& operator=(const DeviceScratch&) = delete;

    /// @brief Copies rows x 3 float32 or float64 values (strides in elements) into float32 x y z per row,
    /// on @p stream (the detector's, DetectorOptions::cuda_stream), so that the detector reads them after
    /// the copy. Throws kdet::Error on a CUDA error.
    const float* gather(const void* source, bool is_double, std::size_t rows, std::int64_t row_stride,
                        std::int64_t column_stride, void* stream);

private:
    float* data_ = nullptr;
    std::size_t capacity_ = 0; // floats
};

/// @brief The current CUDA device, which the detector runs on.
int current_cuda_device();

/// @brief Waits for the work queued on @p stream (a cudaStream_t as an integer; 1 and 2 are CUDA's legacy
/// and per-thread default streams).
void synchronize_cuda_stream(std::uintptr_t stream);

/// @brief The CUDA device that @p pointer lives on, or -1 when it is not device or managed memory.
int cuda_device_of(const void* pointer);

} // namespace kdet::python
