#pragma once
/// @file cuda_exec.cuh
/// @brief The CUDA execution layer: launches the same per-element functors as CpuExec, with CUB for
/// sorting, unique and scans, and CUDA events for stage times. Plain device allocations, kept and grown.
/// Every launch, copy and CUB call goes to the stream of DetectorOptions::cuda_stream (the default
/// stream when none is given), so a frame runs in order after the caller's own work on that stream.

#include "exec/radix_sort.hpp"
#include "exec/tuning.hpp"

#include <kdet/error.hpp>
#include <kdet/options.hpp>

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_reduce.cuh>
#include <cub/device/device_scan.cuh>
#include <cub/device/device_select.cuh>
#include <cuda_runtime.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

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
        if (!try_resize_discard(n))
            throw Error("cannot allocate " + std::to_string(n) + " elements of " + std::to_string(sizeof(T)) +
                        " bytes of device memory: the device has not that much free");
    }
    /// @brief resize_discard that returns false instead of throwing when the device has not the memory
    /// (the buffer is then empty), so that the caller can ask for less.
    bool try_resize_discard(std::size_t n) {
        if (n > capacity_) {
            T* old = data_;
            data_ = nullptr;
            size_ = capacity_ = 0;
            cuda_check(cudaFree(old), "cudaFree");
            if (n > static_cast<std::size_t>(-1) / sizeof(T)) return false;
            const cudaError_t status = cudaMalloc(reinterpret_cast<void**>(&data_), n * sizeof(T));
            if (status == cudaErrorMemoryAllocation) {
                data_ = nullptr;
                (void)cudaGetLastError(); // so that the next launch's check does not report it
                return false;
            }
            cuda_check(status, "cudaMalloc");
            capacity_ = n;
        }
        size_ = n;
        return true;
    }
    /// @brief Exchanges the memory of two buffers (growing one while keeping its contents).
    void swap(DeviceBuffer& other) noexcept {
        std::swap(data_, other.data_);
        std::swap(size_, other.size_);
        std::swap(capacity_, other.capacity_);
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

/// @brief Page-locked host memory, kept and grown: copies from the device land here without the
/// driver's extra staging copy, and a buffer that has grown allocates nothing in later frames.
class PinnedBuffer {
public:
    PinnedBuffer() = default;
    PinnedBuffer(const PinnedBuffer&) = delete;
    PinnedBuffer& operator=(const PinnedBuffer&) = delete;
    ~PinnedBuffer() { cudaFreeHost(data_); }

    /// @brief At least `bytes` of pinned memory; the old contents are not kept.
    unsigned char* reserve(std::size_t bytes) {
        if (bytes > capacity_) {
            unsigned char* old = data_;
            data_ = nullptr;
            capacity_ = 0;
            cuda_check(cudaFreeHost(old), "cudaFreeHost");
            cuda_check(cudaMallocHost(reinterpret_cast<void**>(&data_), bytes), "cudaMallocHost");
            capacity_ = bytes;
        }
        return data_;
    }
    std::size_t capacity_bytes() const { return capacity_; }

private:
    unsigned char* data_ = nullptr;
    std::size_t capacity_ = 0;
};

/// @brief Stage times from events recorded on the stream as the frame is enqueued. Recording costs
/// no synchronisation; the times are read once, when the frame's last mark has completed.
class CudaStageClock {
public:
    static constexpr int mark_count = 8;

    explicit CudaStageClock(cudaStream_t stream) : stream_(stream) {
        for (cudaEvent_t& e : events_) cuda_check(cudaEventCreate(&e), "cudaEventCreate");
    }
    ~CudaStageClock() {
        for (cudaEvent_t e : events_) cudaEventDestroy(e);
    }
    CudaStageClock(const CudaStageClock&) = delete;
    CudaStageClock& operator=(const CudaStageClock&) = delete;

    void begin_frame() { recorded_ = 0; }
    void mark(int k) {
        cuda_check(cudaEventRecord(events_[k], stream_), "cudaEventRecord");
        recorded_ |= 1u << k;
    }
    /// @brief Waits for mark k (a host synchronisation when the stream is still busy).
    void wait(int k) { cuda_check(cudaEventSynchronize(events_[k]), "cudaEventSynchronize"); }
    /// @brief Milliseconds from mark `from` to mark `to`, 0 when either was not recorded this frame.
    double between_ms(int from, int to) const {
        if (!(recorded_ >> from & 1u) || !(recorded_ >> to & 1u)) return 0;
        float ms = 0;
        cuda_check(cudaEventElapsedTime(&ms, events_[from], events_[to]), "cudaEventElapsedTime");
        return ms;
    }

private:
    cudaStream_t stream_;
    cudaEvent_t events_[mark_count]{};
    unsigned recorded_ = 0;
};

template <class F>
__global__ void for_each_kernel(std::uint64_t n, F f) {
    const std::uint64_t stride = static_cast<std::uint64_t>(gridDim.x) * blockDim.x;
    for (std::uint64_t i = static_cast<std::uint64_t>(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += stride) f(i);
}

/// @brief for_each_kernel over a count that an earlier kernel left in device memory, at most `capacity`,
/// divided by `per_item` (rounded up).
template <class F>
__global__ void for_each_counted_kernel(const unsigned long long* count, std::uint64_t capacity, std::uint32_t per_item, F f) {
    const std::uint64_t keys = *count < capacity ? *count : capacity;
    const std::uint64_t n = keys / per_item + (keys % per_item != 0);
    const std::uint64_t stride = static_cast<std::uint64_t>(gridDim.x) * blockDim.x;
    for (std::uint64_t i = static_cast<std::uint64_t>(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += stride) f(i);
}

/// @brief Sets the keys after the first *count (up to capacity) to all ones, which sort after every key
/// below 2^bits whatever bits the sort looks at.
struct PadKeysKernel {
    std::uint64_t* keys;
    const unsigned long long* count;
    __device__ void operator()(std::uint64_t i) const {
        if (i >= *count) keys[i] = ~0ull;
    }
};

/// @brief For sort_lists: the first key of each non-empty list i marked with i + 1 (non-empty lists
/// start at distinct keys; the other keys keep 0).
struct MarkListStartsKernel {
    const std::uint32_t* begin;
    const std::uint32_t* end;
    std::uint32_t* mark;
    __device__ void operator()(std::uint64_t i) const {
        if (end[i] > begin[i]) mark[begin[i]] = static_cast<std::uint32_t>(i) + 1u;
    }
};

/// @brief For sort_lists' scan of the marks: the later mark, so that every key gets the mark of the
/// last list that starts at or before it.
struct LaterMark {
    __device__ std::uint32_t operator()(std::uint32_t earlier, std::uint32_t later) const { return later ? later : earlier; }
};

/// @brief For sort_lists: key k prefixed by the start of its list (the list whose mark it carries,
/// when k lies before that list's end); a key outside every list becomes all ones, which sorts last.
struct PrefixListKeysKernel {
    const std::uint32_t* keys;
    const std::uint32_t* begin;
    const std::uint32_t* end;
    const std::uint32_t* mark;
    std::uint64_t* prefixed;
    __device__ void operator()(std::uint64_t k) const {
        const std::uint32_t list = mark[k];
        prefixed[k] = list && k < end[list - 1] ? std::uint64_t{begin[list - 1]} << 32 | keys[k] : ~0ull;
    }
};

/// @brief For sort_lists: the sorted keys without their lists' starts.
struct LowHalvesKernel {
    const std::uint64_t* prefixed;
    std::uint32_t* keys;
    __device__ void operator()(std::uint64_t k) const { keys[k] = static_cast<std::uint32_t>(prefixed[k]); }
};

class CudaExec {
public:
    template <class T>
    using buffer = DeviceBuffer<T>;
    using stage_clock = CudaStageClock;
    /// How the pipeline divides its work on this backend.
    using tuning = CudaTuning;
    /// The layer's buffers are GPU memory: results reach the host by download.
    static constexpr bool memory_is_host = false;

    explicit CudaExec(const DetectorOptions& options)
        : block_size_(options.block_size), stream_(static_cast<cudaStream_t>(options.cuda_stream)) {
        int devices = 0;
        if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0)
            throw Error("backend 'cuda' needs a CUDA device, and none is available");
    }

    stage_clock make_stage_clock() const { return stage_clock(stream_); }

    template <class F>
    void for_each(std::uint64_t n, const F& f, std::uint32_t /*work_per_item: a thread an item whatever it holds*/ = 1) const {
        if (n == 0) return;
        const int block = launchable_block_size(for_each_kernel<F>);
        for_each_kernel<<<blocks_for(n, block), block, 0, stream_>>>(n, f);
        cuda_check(cudaGetLastError(), "kernel launch");
    }

    /// @brief for_each: on the GPU a thread takes one item whatever its neighbours write (the CPU's
    /// threads share out long runs instead).
    template <class F>
    void for_each_in_runs(std::uint64_t n, const F& f) const {
        for_each(n, f);
    }

    /// @brief Runs f(i) for every i below the count in device memory (at most `capacity`), divided by
    /// `per_item` (rounded up) when each item takes that many: a stage whose size an earlier stage
    /// counted is launched without the host reading the count. The grid covers at most counted_blocks
    /// blocks; their threads stride over the rest.
    template <class F>
    void for_each_counted(const unsigned long long* count, std::uint64_t capacity, const F& f,
                          std::uint32_t per_item = 1) const {
        if (capacity == 0) return;
        const int block = launchable_block_size(for_each_counted_kernel<F>);
        const unsigned blocks = std::min(blocks_for(capacity / per_item + 1, block), counted_blocks);
        for_each_counted_kernel<<<blocks, block, 0, stream_>>>(count, capacity, per_item, f);
        cuda_check(cudaGetLastError(), "kernel launch");
    }

    /// @brief The requested block size, capped at what `kernel` can launch with: heavy kernels need so
    /// many registers per thread that 1024 (or 512) threads do not fit a block.
    template <class Kernel>
    int launchable_block_size(Kernel kernel) const {
        static const int kernel_limit = [kernel] {
            cudaFuncAttributes attributes{};
            cuda_check(cudaFuncGetAttributes(&attributes, kernel), "cudaFuncGetAttributes");
            return attributes.maxThreadsPerBlock;
        }();
        if (block_size_ <= kernel_limit) return block_size_;
        return kernel_limit >= 32 ? kernel_limit / 32 * 32 : kernel_limit; // whole warps
    }

    /// @brief Sorts the first min(*count, capacity) keys ascending, the count in device memory; every key
    /// is below 2^bits, so the radix passes stop there. The host does not know the count, so all
    /// `capacity` keys are sorted, those after the count set to all ones first: they sort last (and
    /// fill their low words, so the passes cannot skip the low word's unused bits as the CPU's do).
    /// The double-buffer form needs `capacity` spare keys and no copy of the keys inside CUB's scratch.
    void sort(std::uint64_t* keys, std::size_t capacity, const unsigned long long* count, int bits,
              int /*low_word_bits*/ = 32) const {
        if (capacity < 2) return;
        for_each(capacity, PadKeysKernel{keys, count});
        sort_keys(keys, capacity, 0, bits);
    }
    /// @brief As CpuExec's: by the high words alone, stably (CUB's radix sort over bits 32 .. bits).
    void sort_by_high_word(std::uint64_t* keys, std::size_t capacity, const unsigned long long* count, int bits) const {
        if (capacity < 2) return;
        for_each(capacity, PadKeysKernel{keys, count});
        sort_keys(keys, capacity, 32, bits);
    }

    /// @brief Copies each list [begin[i], end[i]) of `keys`, i < lists, to the same places of `sorted`,
    /// sorted ascending; the lists are disjoint and lie within the first `capacity` keys, and where
    /// they do not tile a prefix of them `sorted` is left undefined (a grid whose lists did not all
    /// fit, which fills again). One radix sort of all keys, each prefixed by its list's start: a long
    /// list is shared among many threads, where one thread sorting it took milliseconds, and nothing
    /// waits for the host (CUB's segmented sort reads its segment groups' sizes back to the host once
    /// there are more than a few hundred segments). Each key finds its list through a scan of the
    /// lists' marks, a thread a key: a thread prefixing a whole list waited on the longest lists.
    void sort_lists(const std::uint32_t* keys, std::uint32_t* sorted, std::size_t capacity, const std::uint32_t* begin,
                    const std::uint32_t* end, std::size_t lists) const {
        if (capacity == 0) return;
        list_marks_.resize_discard(capacity);
        prefixed_keys_.resize_discard(capacity);
        cuda_check(cudaMemsetAsync(list_marks_.data(), 0, capacity * sizeof(std::uint32_t), stream_), "memset");
        for_each(lists, MarkListStartsKernel{begin, end, list_marks_.data()});
        std::size_t bytes = 0;
        cub::DeviceScan::InclusiveScan(nullptr, bytes, list_marks_.data(), list_marks_.data(), LaterMark{}, capacity, stream_);
        temp_.resize_discard(bytes);
        cuda_check(cub::DeviceScan::InclusiveScan(temp_.data(), bytes, list_marks_.data(), list_marks_.data(), LaterMark{},
                                                  capacity, stream_),
                   "scan");
        for_each(capacity, PrefixListKeysKernel{keys, begin, end, list_marks_.data(), prefixed_keys_.data()});
        // A list's start is below capacity; the keys outside every list (all ones) still sort last.
        sort_keys(prefixed_keys_.data(), capacity, 0, high_word_key_bits(capacity));
        for_each(capacity, LowHalvesKernel{prefixed_keys_.data(), sorted});
    }

    /// @brief *total = the sum of in[0, n), left in device memory.
    void sum(const std::uint32_t* in, std::size_t n, unsigned long long* total) const {
        if (n == 0) {
            cuda_check(cudaMemsetAsync(total, 0, sizeof *total, stream_), "memset");
            return;
        }
        std::size_t bytes = 0;
        cub::DeviceReduce::Sum(nullptr, bytes, in, total, n, stream_);
        temp_.resize_discard(bytes);
        cuda_check(cub::DeviceReduce::Sum(temp_.data(), bytes, in, total, n, stream_), "sum");
    }

    /// @brief Reduces each run of equal consecutive keys: run r's key and the merge of value_of(i) over
    /// its items go to run_keys[r] and run_values[r], the number of runs to *run_count (device memory:
    /// nothing is read back). Parallel over the items, however long the runs.
    template <class Key, class Value, class ValueOf, class Merge>
    void reduce_runs(const Key* keys, const ValueOf& value_of, std::size_t n, const Merge& merge, Key* run_keys,
                     Value* run_values, std::uint32_t* run_count) const {
        if (n == 0) {
            cuda_check(cudaMemsetAsync(run_count, 0, sizeof(std::uint32_t), stream_), "memset");
            return;
        }
        const auto values = thrust::make_transform_iterator(thrust::make_counting_iterator<std::uint64_t>(0), value_of);
        const auto items = static_cast<std::int64_t>(n);
        std::size_t bytes = 0;
        cub::DeviceReduce::ReduceByKey(nullptr, bytes, keys, run_keys, values, run_values, run_count, merge, items,
                                       stream_);
        temp_.resize_discard(bytes);
        cuda_check(cub::DeviceReduce::ReduceByKey(temp_.data(), bytes, keys, run_keys, values, run_values, run_count,
                                                  merge, items, stream_),
                   "reduce by key");
    }

    /// @brief Enqueues a copy from the library's own pageable host memory, which the driver stages
    /// before returning: the source may be reused at once.
    template <class T>
    void upload(T* device, const T* host, std::size_t n) const {
        if (n) cuda_check(cudaMemcpyAsync(device, host, n * sizeof(T), cudaMemcpyHostToDevice, stream_), "upload");
    }
    /// @brief Copies to the host through pinned memory; waits for the stream (a host synchronisation).
    template <class T>
    void download(T* host, const T* device, std::size_t n) const {
        if (!n) return;
        unsigned char* staging = staging_.reserve(n * sizeof(T));
        cuda_check(cudaMemcpyAsync(staging, device, n * sizeof(T), cudaMemcpyDeviceToHost, stream_), "download");
        wait_for_stream();
        std::memcpy(static_cast<void*>(host), staging, n * sizeof(T));
    }
    /// @brief Queues a copy to the host; every queued copy is done by the next finish_downloads(),
    /// with one wait for all of them.
    template <class T>
    void download_later(T* host, const T* device, std::size_t n) const {
        if (n) pending_.push_back(PendingDownload{host, device, n * sizeof(T)});
    }
    /// @brief Queues a download that the host reads where it lands, and returns its number: after the
    /// next finish_downloads(), landed(number) points at its n elements in the pinned buffer until
    /// the one after or a download(): the host copies nothing out of it.
    template <class T>
    std::size_t download_view_later(const T* device, std::size_t n) const {
        pending_views_.push_back(PendingDownload{nullptr, device, n * sizeof(T)});
        return pending_views_.size() - 1;
    }
    template <class T>
    const T* landed(std::size_t view) const {
        return reinterpret_cast<const T*>(landed_views_[view]);
    }
    /// @brief Enqueues the queued copies into one pinned buffer, waits once (none when nothing was
    /// queued), and hands each download_later its bytes (the views stay where they landed).
    void finish_downloads() const {
        if (pending_.empty() && pending_views_.empty()) return;
        const auto room = [](std::size_t bytes) { return (bytes + 15) / 16 * 16; };
        std::size_t total = 0;
        for (const auto* queue : {&pending_, &pending_views_})
            for (const PendingDownload& d : *queue) total += room(d.bytes);
        unsigned char* staging = staging_.reserve(total);
        std::size_t offset = 0;
        for (const auto* queue : {&pending_, &pending_views_})
            for (const PendingDownload& d : *queue) {
                if (d.bytes)
                    cuda_check(cudaMemcpyAsync(staging + offset, d.device, d.bytes, cudaMemcpyDeviceToHost, stream_),
                               "download");
                offset += room(d.bytes);
            }
        wait_for_stream();
        offset = 0;
        for (const PendingDownload& d : pending_) {
            std::memcpy(d.host, staging + offset, d.bytes);
            offset += room(d.bytes);
        }
        landed_views_.clear();
        for (const PendingDownload& d : pending_views_) {
            landed_views_.push_back(staging + offset);
            offset += room(d.bytes);
        }
        pending_.clear();
        pending_views_.clear();
    }
    /// @brief Copies within device memory.
    template <class T>
    void copy(T* destination, const T* source, std::size_t n) const {
        if (n)
            cuda_check(cudaMemcpyAsync(destination, source, n * sizeof(T), cudaMemcpyDeviceToDevice, stream_),
                       "device copy");
    }
    /// @brief Throws kdet::Error when `data`, handed in as device memory, is memory the current
    /// device's kernels would fault on: another CUDA device's, or pageable host memory where the
    /// device cannot read it (no HMM or ATS); `what` names it in the message.
    void check_readable(const void* data, const char* what) const {
        cudaPointerAttributes attributes{};
        if (cudaPointerGetAttributes(&attributes, data) != cudaSuccess) {
            cudaGetLastError(); // not memory CUDA knows: clear the error, the copy reports its own
            return;
        }
        int device = 0;
        cuda_check(cudaGetDevice(&device), "cudaGetDevice");
        if (attributes.type == cudaMemoryTypeUnregistered) {
            int pageable_access = 0;
            cuda_check(cudaDeviceGetAttribute(&pageable_access, cudaDevAttrPageableMemoryAccess, device),
                       "cudaDeviceGetAttribute");
            if (!pageable_access)
                throw Error(std::string(what) +
                            " lie in pageable host memory, which this GPU cannot read: hand host memory to "
                            "set_positions() or locate(), or allocate it with cudaMalloc, cudaMallocManaged or "
                            "cudaMallocHost");
            return;
        }
        if (attributes.type != cudaMemoryTypeDevice && attributes.type != cudaMemoryTypeManaged) return;
        if (attributes.device != device)
            throw Error(std::string(what) + " lie in the memory of CUDA device " + std::to_string(attributes.device) +
                        ", the detector runs on device " + std::to_string(device));
    }
    /// @brief Times the host has waited for the device so far: once per download and per
    /// finish_downloads().
    std::uint64_t host_waits() const { return host_waits_; }

    std::string device_name() const {
        int device = 0;
        cudaDeviceProp properties{};
        cuda_check(cudaGetDevice(&device), "cudaGetDevice");
        cuda_check(cudaGetDeviceProperties(&properties, device), "cudaGetDeviceProperties");
        return properties.name;
    }

    /// @brief Holds the spare keys sort() needs for `capacity` keys now (as CpuExec::reserve_sort); false
    /// when the device cannot hold them.
    bool reserve_sort(std::size_t capacity) const {
        return spare_keys_.size() >= capacity || spare_keys_.try_resize_discard(capacity);
    }
    std::size_t sort_spare_bytes() const { return spare_keys_.capacity_bytes(); }
    void release_sort() const { DeviceBuffer<std::uint64_t>().swap(spare_keys_); }

    /// @brief Bytes of the scratch buffers CUB needs, for memory reports (device memory only).
    std::size_t scratch_bytes() const {
        return temp_.capacity_bytes() + spare_keys_.capacity_bytes() + prefixed_keys_.capacity_bytes() +
               list_marks_.capacity_bytes();
    }

private:
    static constexpr unsigned counted_blocks = 4096;

    struct PendingDownload {
        void* host;
        const void* device;
        std::size_t bytes;
    };

    static unsigned blocks_for(std::uint64_t n, int block) {
        const std::uint64_t wanted = (n + block - 1) / block;
        return static_cast<unsigned>(wanted < (1u << 30) ? wanted : (1u << 30));
    }

    /// @brief Sorts n keys ascending by their bits below 2^bits (CUB's radix sort through spare_keys_).
    void sort_keys(std::uint64_t* keys, std::size_t n, int first_bit, int bits) const {
        spare_keys_.resize_discard(n);
        cub::DoubleBuffer<std::uint64_t> buffers(keys, spare_keys_.data());
        std::size_t bytes = 0;
        cub::DeviceRadixSort::SortKeys(nullptr, bytes, buffers, n, first_bit, bits, stream_);
        temp_.resize_discard(bytes);
        cuda_check(cub::DeviceRadixSort::SortKeys(temp_.data(), bytes, buffers, n, first_bit, bits, stream_), "radix sort");
        if (buffers.Current() != keys) copy(keys, buffers.Current(), n);
    }

    void wait_for_stream() const {
        ++host_waits_;
        cuda_check(cudaStreamSynchronize(stream_), "synchronize");
    }

    int block_size_;
    cudaStream_t stream_;
    mutable PinnedBuffer staging_;
    mutable std::vector<PendingDownload> pending_, pending_views_;
    mutable std::vector<const unsigned char*> landed_views_;
    mutable std::uint64_t host_waits_ = 0;
    mutable DeviceBuffer<unsigned char> temp_;
    mutable DeviceBuffer<std::uint64_t> spare_keys_;
    mutable DeviceBuffer<std::uint64_t> prefixed_keys_; ///< sort_lists' keys with their lists' starts
    mutable DeviceBuffer<std::uint32_t> list_marks_;    ///< sort_lists' list of each key (its number + 1)
};

} // namespace kdet
