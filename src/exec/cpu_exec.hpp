#pragma once
/// @file cpu_exec.hpp
/// @brief The CPU execution layer: OpenMP loops over the same per-element functors the CUDA layer launches.

#include "exec/tuning.hpp"

#include <kdet/options.hpp>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace kdet {

namespace host_memory {

/// @brief The heap: HostBuffer's memory unless it is given another source (the tests give one).
struct Heap {
    /// Uninitialised memory for `count` objects of `size` bytes aligned to `alignment` (a power of
    /// two); throws std::bad_alloc when it cannot. Plain pages, no huge-page advice: since layer 0's
    /// cells hold dozens of tets the frames gain little from it, where a one-off query's first touch of
    /// fresh memory took far longer with it in a VM that returns free memory to its host
    /// (docs/performance.md).
    static void* allocate(std::size_t count, std::size_t size, std::size_t alignment) {
        if (count > std::numeric_limits<std::size_t>::max() / size) throw std::bad_alloc();
        const std::size_t bytes = count * size;
        void* p = nullptr;
        if (alignment > alignof(std::max_align_t)) {
            p = std::aligned_alloc(alignment, (std::max<std::size_t>(bytes, 1) + alignment - 1) / alignment * alignment);
        } else {
            p = std::malloc(bytes == 0 ? 1 : bytes);
        }
        if (!p) throw std::bad_alloc();
        return p;
    }
    static void release(void* p, std::size_t /*bytes*/) { std::free(p); }
};

} // namespace host_memory

/// @brief Growable array that keeps its memory between frames; contents are not preserved on growth.
/// Elements are left uninitialised (every buffer of the pipeline is written before it is read).
/// `Memory` provides allocate(count, size, alignment), throwing std::bad_alloc, and release(p, bytes).
template <class T, class Memory = host_memory::Heap>
class HostBuffer {
    static_assert(std::is_trivially_default_constructible<T>::value && std::is_trivially_destructible<T>::value,
                  "HostBuffer holds plain data: its memory is neither constructed nor destroyed");

public:
    HostBuffer() = default;
    HostBuffer(const HostBuffer&) = delete;
    HostBuffer& operator=(const HostBuffer&) = delete;
    HostBuffer(HostBuffer&& other) noexcept { swap(other); }
    HostBuffer& operator=(HostBuffer&& other) noexcept {
        swap(other);
        return *this;
    }
    ~HostBuffer() { Memory::release(data_, capacity_ * sizeof(T)); }

    /// @brief Makes room for n elements; discards the old contents when it has to reallocate.
    /// A failed allocation (std::bad_alloc) leaves the buffer empty, never a size without memory.
    void resize_discard(std::size_t n) {
        if (n > capacity_) {
            Memory::release(data_, capacity_ * sizeof(T));
            data_ = nullptr;
            size_ = capacity_ = 0;
            data_ = static_cast<T*>(Memory::allocate(n, sizeof(T), alignof(T)));
            capacity_ = n;
        }
        size_ = n;
    }
    /// @brief resize_discard that returns false instead of throwing when the memory cannot be had
    /// (the buffer is then empty), so that the caller can ask for less.
    bool try_resize_discard(std::size_t n) noexcept {
        try {
            resize_discard(n);
        } catch (const std::bad_alloc&) {
            return false;
        }
        return true;
    }
    /// @brief Exchanges the memory of two buffers (growing one while keeping its contents).
    void swap(HostBuffer& other) noexcept {
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

/// @brief Stage times in milliseconds of wall-clock time, from marks set as the frame runs
/// (the CPU twin of CudaStageClock).
class CpuStageClock {
public:
    static constexpr int mark_count = 8;

    void begin_frame() { recorded_ = 0; }
    void mark(int k) {
        marks_[k] = std::chrono::steady_clock::now();
        recorded_ |= 1u << k;
    }
    void wait(int) const {}
    /// @brief Milliseconds from mark `from` to mark `to`, 0 when either was not recorded this frame.
    double between_ms(int from, int to) const {
        if (!(recorded_ >> from & 1u) || !(recorded_ >> to & 1u)) return 0;
        return std::chrono::duration<double, std::milli>(marks_[to] - marks_[from]).count();
    }

private:
    std::chrono::steady_clock::time_point marks_[mark_count]{};
    unsigned recorded_ = 0;
};

class CpuExec {
public:
    template <class T>
    using buffer = HostBuffer<T>;
    using stage_clock = CpuStageClock;
    /// How the pipeline divides its work on this backend.
    using tuning = CpuTuning;
    /// The layer's buffers are host memory: a step may write its results where the host reads them.
    static constexpr bool memory_is_host = true;

    /// @brief options.threads = 0 keeps OpenMP's default; the block size and stream only matter on the GPU.
    explicit CpuExec(const DetectorOptions& options);

    stage_clock make_stage_clock() const { return stage_clock(); }

    /// @brief Runs f(i) for every i in [0, n) on all threads; each item holds `work_per_item` elements
    /// (tets, keys), so that a stage of few heavy items is shared like one of many light ones: on one
    /// thread below 512 elements, else in dynamic chunks of about 256 elements.
    template <class F>
    void for_each(std::uint64_t n, const F& f, std::uint32_t work_per_item = 1) const {
        const auto count = static_cast<std::int64_t>(n);
        for_each_in_chunks(count, std::max<std::int64_t>(1, 256 / std::int64_t{work_per_item}), count * work_per_item > 512, f);
    }

    /// @brief for_each for a stage whose neighbouring items write to the same places (populating, where
    /// tets next to each other in the storage order share most of their cells): each thread takes runs
    /// of consecutive items, eight per thread in all (at least 256 items each), still shared out
    /// dynamically. With for_each's chunks of 256 the threads inserted into the same cells at once,
    /// contending for their buckets' lines and interleaving their ids, which then left most of the
    /// cells' lists to be sorted.
    template <class F>
    void for_each_in_runs(std::uint64_t n, const F& f) const {
        const auto count = static_cast<std::int64_t>(n);
        for_each_in_chunks(count, std::max<std::int64_t>(256, count / (8 * std::int64_t{threads_})), count > 512, f);
    }

    /// @brief Runs f(i) for every i below the count in the backend's memory (at most `capacity`),
    /// divided by `per_item` (rounded up) when each item takes that many: a stage whose size an earlier
    /// stage counted is launched without the host reading the count.
    template <class F>
    void for_each_counted(const unsigned long long* count, std::uint64_t capacity, const F& f,
                          std::uint32_t per_item = 1) const {
        const std::uint64_t n = std::min<std::uint64_t>(*count, capacity);
        for_each(n / per_item + (n % per_item != 0), f);
    }

    /// @brief Sorts the first min(*count, capacity) keys ascending (the count in the backend's memory);
    /// keys after them up to `capacity` may change. Every key is below 2^bits and its low word below
    /// 2^low_word_bits, which shortens the radix sort (one pass per 12 bits used here, per 8 bits
    /// below 2^bits in CUB's).
    void sort(std::uint64_t* keys, std::size_t capacity, const unsigned long long* count, int bits, int low_word_bits = 32) const;
    /// @brief As sort, by the high words alone (every key below 2^bits), stably: keys of one high word
    /// keep their order, in half the passes where the low words need not be ordered.
    void sort_by_high_word(std::uint64_t* keys, std::size_t capacity, const unsigned long long* count, int bits) const;
    /// @brief Holds the spare keys sort() needs for `capacity` keys now, so that a window of colliding
    /// pairs is refused before a frame's narrow phase rather than when it sorts; false when the memory
    /// cannot hold them.
    bool reserve_sort(std::size_t capacity) const {
        return sort_scratch_.size() >= capacity || sort_scratch_.try_resize_discard(capacity);
    }
    std::size_t sort_spare_bytes() const { return sort_scratch_.capacity_bytes(); }
    void release_sort() const { HostBuffer<std::uint64_t>().swap(sort_scratch_); }

    /// @brief Copies each list [begin[i], end[i]) of `keys`, i < lists, to the same places of `sorted`,
    /// sorted ascending (the grid's lists by id); the lists are disjoint and lie within the first
    /// `capacity` keys (the GPU's sort needs them to tile a prefix of them as well). A thread a list:
    /// the CPU's threads fill the lists in about ascending order, so most arrive sorted and are only
    /// checked; the others take a Shell sort (the lists are short).
    void sort_lists(const std::uint32_t* keys, std::uint32_t* sorted, std::size_t capacity, const std::uint32_t* begin,
                    const std::uint32_t* end, std::size_t lists) const;

    /// @brief *total = the sum of in[0, n), left in the backend's memory.
    void sum(const std::uint32_t* in, std::size_t n, unsigned long long* total) const;

    /// @brief Reduces each run of equal consecutive keys: run r's key and the merge of value_of(i) over
    /// its items go to run_keys[r] and run_values[r], the number of runs to *run_count (in the
    /// backend's memory: nothing is read back). Each thread reduces a slice; runs that cross a
    /// slice's end are merged afterwards.
    template <class Key, class Value, class ValueOf, class Merge>
    void reduce_runs(const Key* keys, const ValueOf& value_of, std::size_t n, const Merge& merge, Key* run_keys,
                     Value* run_values, std::uint32_t* run_count) const {
        const int slices = std::max(1, std::min<int>(threads_, static_cast<int>(n / 4096)));
        const std::size_t per_slice = (n + slices - 1) / slices;
        std::vector<std::vector<std::pair<Key, Value>>> slice_runs(static_cast<std::size_t>(slices));
#pragma omp parallel for num_threads(slices)
        for (int s = 0; s < slices; ++s) {
            auto& runs = slice_runs[static_cast<std::size_t>(s)];
            const std::size_t lo = std::min(n, s * per_slice), hi = std::min(n, lo + per_slice);
            for (std::size_t i = lo; i < hi; ++i) {
                if (runs.empty() || !(runs.back().first == keys[i]))
                    runs.emplace_back(keys[i], value_of(i));
                else
                    runs.back().second = merge(runs.back().second, value_of(i));
            }
        }
        std::uint32_t runs = 0;
        for (const auto& slice : slice_runs)
            for (const auto& [key, value] : slice) {
                if (runs && run_keys[runs - 1] == key) {
                    run_values[runs - 1] = merge(run_values[runs - 1], value);
                    continue;
                }
                run_keys[runs] = key;
                run_values[runs] = value;
                ++runs;
            }
        *run_count = runs;
    }

    /// @brief Copies into the backend's memory; a large copy (a big scene's positions, every frame) in
    /// slices of 1 MiB or more on the layer's threads.
    template <class T>
    void upload(T* device, const T* host, std::size_t n) const {
        const std::size_t bytes = n * sizeof(T);
        const int slices = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(threads_), bytes >> 20));
        if (slices <= 1) {
            if (n) std::memcpy(device, host, bytes);
            return;
        }
#pragma omp parallel for num_threads(slices)
        for (int s = 0; s < slices; ++s) {
            const std::size_t first = n * static_cast<std::size_t>(s) / static_cast<std::size_t>(slices);
            const std::size_t end = n * static_cast<std::size_t>(s + 1) / static_cast<std::size_t>(slices);
            std::memcpy(device + first, host + first, (end - first) * sizeof(T));
        }
    }
    /// @brief Copies out of the backend's memory: a point where the GPU backend waits for the device,
    /// counted here too so that both backends report the same number of host waits.
    template <class T>
    void download(T* host, const T* device, std::size_t n) const {
        if (!n) return;
        ++host_waits_;
        std::memcpy(host, device, n * sizeof(T));
    }
    /// @brief Queues a copy out of the backend's memory; every queued copy is done by the next
    /// finish_downloads(), with one wait for all of them.
    template <class T>
    void download_later(T* host, const T* device, std::size_t n) const {
        if (n) pending_.push_back(PendingDownload{host, device, n * sizeof(T)});
    }
    /// @brief Queues a download that the host reads where it lands, and returns its number: after the
    /// next finish_downloads(), landed(number) points at its n elements until the one after. The
    /// backend's memory is the host's, so it lands where it is: a copy of the whole pairs' window
    /// cost one thread's time every frame.
    template <class T>
    std::size_t download_view_later(const T* device, std::size_t /*n: read in place*/) const {
        pending_views_.push_back(device);
        return pending_views_.size() - 1;
    }
    template <class T>
    const T* landed(std::size_t view) const {
        return static_cast<const T*>(landed_views_[view]);
    }
    /// @brief Does the queued copies: one host wait (none when nothing was queued).
    void finish_downloads() const {
        if (pending_.empty() && pending_views_.empty()) return;
        ++host_waits_;
        for (const PendingDownload& d : pending_) std::memcpy(d.host, d.device, d.bytes);
        pending_.clear();
        landed_views_.swap(pending_views_);
        pending_views_.clear();
    }
    /// @brief Copies within the backend's memory.
    template <class T>
    void copy(T* destination, const T* source, std::size_t n) const {
        if (n) std::memmove(destination, source, n * sizeof(T));
    }
    /// @brief Memory handed in as the backend's: any host address is (see CudaExec's).
    void check_readable(const void* /*data*/, const char* /*what*/) const {}
    /// @brief Times the host has waited for the backend so far: once per download and per
    /// finish_downloads().
    std::uint64_t host_waits() const { return host_waits_; }

    /// @brief Bytes of scratch memory the layer keeps (the sort's second buffer of keys).
    std::size_t scratch_bytes() const { return sort_scratch_.capacity_bytes(); }

    int threads() const { return threads_; }
    std::string device_name() const;

private:
    /// @brief f(i) for i in [0, count), shared out in dynamic chunks of `chunk` items, on one thread
    /// unless `parallel`.
    template <class F>
    void for_each_in_chunks(std::int64_t count, std::int64_t chunk, bool parallel, const F& f) const {
#pragma omp parallel for schedule(dynamic, chunk) num_threads(threads_) if (parallel)
        for (std::int64_t i = 0; i < count; ++i) f(static_cast<std::uint64_t>(i));
    }

    struct PendingDownload {
        void* host;
        const void* device;
        std::size_t bytes;
    };
    int threads_;
    mutable std::uint64_t host_waits_ = 0;
    mutable std::vector<PendingDownload> pending_;
    mutable std::vector<const void*> pending_views_, landed_views_;
    /// The radix sort's other buffer, kept between frames so that a frame allocates nothing.
    mutable HostBuffer<std::uint64_t> sort_scratch_;
};

} // namespace kdet
