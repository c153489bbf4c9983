#pragma once
/// @file cuda_exec.cuh
/// @brief The CUDA execution layer: launches the same per-element functors as CpuExec, with CUB for
/// sorting, unique and scans, and CUDA events for stage times. Plain device allocations, kept and grown.

#include <kdet/error.hpp>

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>
#include <cub/device/device_select.cuh>
#include <cuda_runtime.h>

#include <cstdint>
#include <string>

namespace kdet {

inline void cuda_check(cudaError_t status, const char* what) {
    if (status != cudaSuccess) throw Error(std::string("CUDA error in ") + what + ": " + cudaGetErrorString(status));
}

/// @brief Device memory that keeps its allocation between frames; contents are not kept on growth.
template <class T>
class DeviceBuffer {
public:
    DeviceBuffer() = default;
    DeviceBuffer(const DeviceBuffer&) = delete;
    DeviceBuffer& operator=(const DeviceBuffer&) = delete;
    ~DeviceBuffer() { cudaFree(data_); }

    /// @brief Makes room for n elements; discards the old contents when it has to reallocate.
    /// A failed allocation throws and leaves the buffer empty, never a size without memory.
    void resize_discard(std::size_t n) {
        if (n > capacity_) {
            T* old = data_;
            data_ = nullptr;
            size_ = capacity_ = 0;
            cuda_check(cudaFree(old), "cudaFree");
            if (n > static_cast<std::size_t>(-1) / sizeof(T))
                throw Error("cannot allocate " + std::to_string(n) + " elements of device memory: size overflows");
            cuda_check(cudaMalloc(reinterpret_cast<void**>(&data_), n * sizeof(T)), "cudaMalloc");
            capacity_ = n;
        }
        size_ = n;
    }
    T* data() { return data_; }
    const T* data() const { return data_; }
    std::size_t size() const { return size_; }
    std::size_t capacity_bytes() const { return capacity_ * sizeof(T); }

private:
    T* data_ = nullptr;
    std::size_t size_ = 0;
    std::size_t capacity_ = 0;
};

/// @brief Times one stage on the GPU with a pair of events.
class CudaStageTimer {
public:
    CudaStageTimer() {
        cuda_check(cudaEventCreate(&begin_), "cudaEventCreate");
        cuda_check(cudaEventCreate(&end_), "cudaEventCreate");
    }
    ~CudaStageTimer() {
        cudaEventDestroy(begin_);
        cudaEventDestroy(end_);
    }
    CudaStageTimer(const CudaStageTimer&) = delete;
    CudaStageTimer& operator=(const CudaStageTimer&) = delete;
    void start() { cuda_check(cudaEventRecord(begin_), "cudaEventRecord"); }
    double stop_ms() {
        cuda_check(cudaEventRecord(end_), "cudaEventRecord");
        cuda_check(cudaEventSynchronize(end_), "cudaEventSynchronize");
        float ms = 0;
        cuda_check(cudaEventElapsedTime(&ms, begin_, end_), "cudaEventElapsedTime");
        return ms;
    }

private:
    cudaEvent_t begin_{}, end_{};
};

template <class F>
__global__ void for_each_kernel(std::uint64_t n, F f) {
    const std::uint64_t stride = static_cast<std::uint64_t>(gridDim.x) * blockDim.x;
    for (std::uint64_t i = static_cast<std::uint64_t>(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += stride) f(i);
}

class CudaExec {
public:
    template <class T>
    using buffer = DeviceBuffer<T>;
    using stage_timer = CudaStageTimer;

    CudaExec(int /*threads*/, int block_size) : block_size_(block_size) {
        int devices = 0;
        if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0)
            throw Error("backend 'cuda' needs a CUDA device, and none is available");
    }

    template <class F>
    void for_each(std::uint64_t n, const F& f) const {
        if (n == 0) return;
        const int block = launchable_block_size<F>();
        const std::uint64_t wanted = (n + block - 1) / block;
        const auto blocks = static_cast<unsigned>(wanted < (1u << 30) ? wanted : (1u << 30));
        for_each_kernel<<<blocks, block>>>(n, f);
        cuda_check(cudaGetLastError(), "kernel launch");
    }

    /// @brief The requested block size, capped at what the kernel for F can launch with: heavy
    /// kernels need so many registers per thread that 1024 (or 512) threads do not fit a block.
    template <class F>
    int launchable_block_size() const {
        static const int kernel_limit = [] {
            cudaFuncAttributes attributes{};
            cuda_check(cudaFuncGetAttributes(&attributes, for_each_kernel<F>), "cudaFuncGetAttributes");
            return attributes.maxThreadsPerBlock;
        }();
        if (block_size_ <= kernel_limit) return block_size_;
        return kernel_limit >= 32 ? kernel_limit / 32 * 32 : kernel_limit; // whole warps
    }

    void sort(std::uint64_t* keys, std::size_t n) const {
        if (n < 2) return;
        sorted_.resize_discard(n);
        std::size_t bytes = 0;
        cub::DeviceRadixSort::SortKeys(nullptr, bytes, keys, sorted_.data(), n);
        temp_.resize_discard(bytes);
        cuda_check(cub::DeviceRadixSort::SortKeys(temp_.data(), bytes, keys, sorted_.data(), n), "radix sort");
        copy(keys, sorted_.data(), n);
    }

    std::uint64_t exclusive_scan(const std::uint32_t* in, std::uint32_t* out, std::size_t n) const {
        if (n == 0) return 0;
        std::uint32_t last = 0, last_offset = 0;
        download(&last, in + n - 1, 1);
        std::size_t bytes = 0;
        cub::DeviceScan::ExclusiveSum(nullptr, bytes, in, out, n);
        temp_.resize_discard(bytes);
        cuda_check(cub::DeviceScan::ExclusiveSum(temp_.data(), bytes, in, out, n), "exclusive scan");
        download(&last_offset, out + n - 1, 1);
        return std::uint64_t{last_offset} + last;
    }

    template <class T>
    void upload(T* device, const T* host, std::size_t n) const {
        if (n) cuda_check(cudaMemcpy(device, host, n * sizeof(T), cudaMemcpyHostToDevice), "upload");
    }
    template <class T>
    void download(T* host, const T* device, std::size_t n) const {
        if (n) cuda_check(cudaMemcpy(host, device, n * sizeof(T), cudaMemcpyDeviceToHost), "download");
    }
    /// @brief Copies within device memory.
    template <class T>
    void copy(T* destination, const T* source, std::size_t n) const {
        if (n) cuda_check(cudaMemcpy(destination, source, n * sizeof(T), cudaMemcpyDeviceToDevice), "device copy");
    }
    void synchronize() const { cuda_check(cudaDeviceSynchronize(), "synchronize"); }

    std::string device_name() const {
        int device = 0;
        cudaDeviceProp properties{};
        cuda_check(cudaGetDevice(&device), "cudaGetDevice");
        cuda_check(cudaGetDeviceProperties(&properties, device), "cudaGetDeviceProperties");
        return properties.name;
    }

    /// @brief Bytes of the scratch buffers CUB needs, for memory reports.
    std::size_t scratch_bytes() const {
        return temp_.capacity_bytes() + sorted_.capacity_bytes();
    }

private:
    int block_size_;
    mutable DeviceBuffer<unsigned char> temp_;
    mutable DeviceBuffer<std::uint64_t> sorted_;
};

} // namespace kdet
