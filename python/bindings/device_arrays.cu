#include "device_arrays.hpp"

#include <kdet/error.hpp>

#include <cuda_runtime.h>

#include <string>

namespace kdet::python {

namespace {

void check(cudaError_t status, const char* what) {
    if (status != cudaSuccess) throw Error(std::string("CUDA error in ") + what + ": " + cudaGetErrorString(status));
}

template <class Scalar>
__global__ void gather_xyz(const Scalar* source, std::size_t rows, std::int64_t row_stride, std::int64_t column_stride,
                           float* out) {
    const std::size_t row = blockIdx.x * static_cast<std::size_t>(blockDim.x) + threadIdx.x;
    if (row >= rows) return;
    const std::int64_t first = static_cast<std::int64_t>(row) * row_stride;
    for (int k = 0; k < 3; ++k) out[3 * row + k] = static_cast<float>(source[first + k * column_stride]);
}

} // namespace

DeviceScratch::~DeviceScratch() {
    if (data_) cudaFree(data_);
}

const float* DeviceScratch::gather(const void* source, bool is_double, std::size_t rows, std::int64_t row_stride,
                                   std::int64_t column_stride, void* stream) {
    if (3 * rows > capacity_) {
        if (data_) check(cudaFree(data_), "cudaFree");
        data_ = nullptr;
        capacity_ = 0;
        check(cudaMalloc(&data_, 3 * rows * sizeof(float)), "cudaMalloc");
        capacity_ = 3 * rows;
    }
    if (rows == 0) return data_;
    const unsigned block = 256;
    const auto blocks = static_cast<unsigned>((rows + block - 1) / block);
    const auto on = static_cast<cudaStream_t>(stream);
    if (is_double)
        gather_xyz<<<blocks, block, 0, on>>>(static_cast<const double*>(source), rows, row_stride, column_stride, data_);
    else
        gather_xyz<<<blocks, block, 0, on>>>(static_cast<const float*>(source), rows, row_stride, column_stride, data_);
    check(cudaGetLastError(), "the gather kernel");
    return data_;
}

int current_cuda_device() {
    int device = 0;
    check(cudaGetDevice(&device), "cudaGetDevice");
    return device;
}

void synchronize_cuda_stream(std::uintptr_t stream) {
    check(cudaStreamSynchronize(reinterpret_cast<cudaStream_t>(stream)), "cudaStreamSynchronize");
}

int cuda_device_of(const void* pointer) {
    cudaPointerAttributes attributes{};
    if (cudaPointerGetAttributes(&attributes, pointer) != cudaSuccess) {
        cudaGetLastError(); // clear the sticky-free error of an unknown pointer
        return -1;
    }
    return attributes.type == cudaMemoryTypeDevice || attributes.type == cudaMemoryTypeManaged ? attributes.device : -1;
}

} // namespace kdet::python
