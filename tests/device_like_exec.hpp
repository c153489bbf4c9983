#pragma once
/// @file device_like_exec.hpp
/// @brief The CPU backend with memory the host cannot touch, as a GPU's: DeviceLikeExec runs the CPU's
/// per-element functors, but its buffers lie in an arena that is readable only while one of the
/// execution layer's calls (a kernel, a sort, an upload or download) runs, and it says its memory is
/// not the host's, so that the pipeline takes the paths it takes on CUDA. Host code of the pipeline
/// that reads or writes a buffer directly, or reads a landed download after the staging was reused,
/// then fails on the CPU, where without a GPU it would pass unseen; a stage that reads what no stage
/// wrote likely answers otherwise. Not caught: a kernel given host memory, which a GPU cannot read.

#include "exec/cpu_exec.hpp"

#include <algorithm>
#include <csignal>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include <sys/mman.h>
#include <unistd.h>

namespace kdet::device_like {

/// @brief One reserved range of address space, handed out by pages; inaccessible except between
/// open() and close() (calls nest). A fault inside it names the cause before the process dies.
class GuardedArena {
public:
    static GuardedArena& instance() {
        static GuardedArena arena;
        return arena;
    }
    /// @brief False where the address space could not be reserved (the tests then skip).
    bool usable() const { return base_ != nullptr; }

    /// @brief `bytes` rounded up to whole pages, accessible as the arena is; nullptr when the arena
    /// has no room left (as a device whose memory is full).
    void* allocate(std::size_t bytes) {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (!base_) return nullptr;
        const std::size_t need = pages_for(bytes);
        for (auto it = free_.begin(); it != free_.end(); ++it) {
            if (it->second < need) continue;
            const std::size_t offset = it->first, left = it->second - need;
            free_.erase(it);
            if (left) free_.emplace(offset + need, left);
            return base_ + offset;
        }
        if (reserved_ - used_ < need) return nullptr;
        const std::size_t offset = used_;
        used_ += need;
        if (depth_ > 0) protect(offset, need, PROT_READ | PROT_WRITE);
        return base_ + offset;
    }
    /// @brief Gives back what allocate(bytes) returned; its pages go back to the system.
    void release(void* p, std::size_t bytes) {
        if (!p) return;
        const std::lock_guard<std::mutex> lock(mutex_);
        std::size_t offset = static_cast<std::size_t>(static_cast<char*>(p) - base_), length = pages_for(bytes);
        madvise(p, length, MADV_DONTNEED);
        const auto next = free_.lower_bound(offset);
        if (next != free_.end() && offset + length == next->first) {
            length += next->second;
            free_.erase(next);
        }
        const auto after = free_.lower_bound(offset);
        if (after != free_.begin()) {
            const auto previous = std::prev(after);
            if (previous->first + previous->second == offset) {
                offset = previous->first;
                length += previous->second;
                free_.erase(previous);
            }
        }
        free_.emplace(offset, length);
    }

    void open() {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (depth_++ == 0 && used_) protect(0, used_, PROT_READ | PROT_WRITE);
    }
    void close() {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (--depth_ == 0 && used_) protect(0, used_, PROT_NONE);
    }
    bool contains(const void* p) const {
        const char* c = static_cast<const char*>(p);
        return base_ && c >= base_ && c < base_ + reserved_;
    }

    /// @brief Opens the arena for its lifetime: what an execution-layer call does.
    class Opened {
    public:
        Opened() { instance().open(); }
        ~Opened() { instance().close(); }
        Opened(const Opened&) = delete;
        Opened& operator=(const Opened&) = delete;
    };

private:
    GuardedArena() {
        page_ = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
        // Address space only (no memory is committed): as much as the system lets one process reserve.
        for (std::size_t bytes = std::size_t{1} << 40; bytes >= std::size_t{1} << 34; bytes /= 2) {
            void* p = mmap(nullptr, bytes, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
            if (p == MAP_FAILED) continue;
            base_ = static_cast<char*>(p);
            reserved_ = bytes;
            break;
        }
        if (!base_) return;
        struct sigaction action{};
        action.sa_sigaction = &GuardedArena::on_fault;
        action.sa_flags = SA_SIGINFO;
        sigemptyset(&action.sa_mask);
        sigaction(SIGSEGV, &action, &previous_action());
    }
    std::size_t pages_for(std::size_t bytes) const { return (std::max<std::size_t>(bytes, 1) + page_ - 1) / page_ * page_; }
    void protect(std::size_t offset, std::size_t length, int protection) {
        if (mprotect(base_ + offset, length, protection) != 0) throw std::bad_alloc();
    }
    static struct sigaction& previous_action() {
        static struct sigaction previous{};
        return previous;
    }
    /// A fault in the arena: host code touched the memory of the backend outside its calls.
    static void on_fault(int signal, siginfo_t* info, void* context) {
        if (instance().contains(info->si_addr)) {
            static const char message[] =
                "kdet test: host code touched device-like memory outside an execution-layer call "
                "(on a GPU it would read device memory from the host)\n";
            [[maybe_unused]] const ssize_t written = write(STDERR_FILENO, message, sizeof message - 1);
            std::signal(SIGSEGV, SIG_DFL); // the access faults again, now fatally, where a debugger shows it
            return;
        }
        const struct sigaction& previous = previous_action();
        if (previous.sa_flags & SA_SIGINFO && previous.sa_sigaction) {
            previous.sa_sigaction(signal, info, context);
            return;
        }
        if (previous.sa_handler != SIG_DFL && previous.sa_handler != SIG_IGN && previous.sa_handler) {
            previous.sa_handler(signal);
            return;
        }
        std::signal(SIGSEGV, SIG_DFL);
    }

    std::mutex mutex_;
    char* base_ = nullptr;
    std::size_t reserved_ = 0, used_ = 0, page_ = 4096;
    int depth_ = 0;
    std::map<std::size_t, std::size_t> free_; ///< offset -> length of the ranges given back, coalesced
};

/// @brief While it lives, a test reads results left in the backend's memory (DeviceResults on the CPU
/// backend) directly, where a CUDA user would copy them out first.
using BackendMemoryReadable = GuardedArena::Opened;

/// @brief HostBuffer's memory from the guarded arena (page-aligned, so any alignment holds). Fresh
/// device memory holds whatever was there before, where the heap's large blocks come zeroed: a
/// buffer of up to 256 MiB starts filled with a pattern, so that a stage that reads what no stage
/// wrote gives other answers here (larger ones stay untouched, uncommitted, as tests of memory
/// limits ask for them).
struct GuardedMemory {
    static void* allocate(std::size_t count, std::size_t size, std::size_t /*alignment*/) {
        if (count > static_cast<std::size_t>(-1) / size) throw std::bad_alloc();
        const std::size_t bytes = count * size;
        void* p = GuardedArena::instance().allocate(bytes);
        if (!p) throw std::bad_alloc();
        if (bytes <= std::size_t{256} << 20) {
            const GuardedArena::Opened opened;
            std::memset(p, 0xA5, bytes);
        }
        return p;
    }
    static void release(void* p, std::size_t bytes) { GuardedArena::instance().release(p, bytes); }
};

/// @brief The pipeline's buffers of DeviceLikeExec.
template <class T>
using GuardedBuffer = HostBuffer<T, GuardedMemory>;

/// @brief CpuExec whose memory the host reaches only through the layer's calls, as CudaExec's: each
/// call opens the arena while it runs, and downloads the host reads in place land in staging copies
/// that the next download or finish_downloads() overwrites with a pattern, as the GPU's reuse of its
/// pinned staging would.
class DeviceLikeExec : public CpuExec {
public:
    template <class T>
    using buffer = GuardedBuffer<T>;
    static constexpr bool memory_is_host = false;

    using CpuExec::CpuExec;

    template <class F>
    void for_each(std::uint64_t n, const F& f, std::uint32_t work_per_item = 1) const {
        const GuardedArena::Opened opened;
        CpuExec::for_each(n, f, work_per_item);
    }
    template <class F>
    void for_each_in_runs(std::uint64_t n, const F& f) const {
        const GuardedArena::Opened opened;
        CpuExec::for_each_in_runs(n, f);
    }
    template <class F>
    void for_each_counted(const unsigned long long* count, std::uint64_t capacity, const F& f,
                          std::uint32_t per_item = 1) const {
        const GuardedArena::Opened opened;
        CpuExec::for_each_counted(count, capacity, f, per_item);
    }
    void sort(std::uint64_t* keys, std::size_t capacity, const unsigned long long* count, int bits,
              int low_word_bits = 32) const {
        const GuardedArena::Opened opened;
        CpuExec::sort(keys, capacity, count, bits, low_word_bits);
    }
    void sort_by_high_word(std::uint64_t* keys, std::size_t capacity, const unsigned long long* count, int bits) const {
        const GuardedArena::Opened opened;
        CpuExec::sort_by_high_word(keys, capacity, count, bits);
    }
    void sort_lists(const std::uint32_t* keys, std::uint32_t* sorted, std::size_t capacity, const std::uint32_t* begin,
                    const std::uint32_t* end, std::size_t lists) const {
        const GuardedArena::Opened opened;
        CpuExec::sort_lists(keys, sorted, capacity, begin, end, lists);
    }
    void sum(const std::uint32_t* in, std::size_t n, unsigned long long* total) const {
        const GuardedArena::Opened opened;
        CpuExec::sum(in, n, total);
    }
    template <class Key, class Value, class ValueOf, class Merge>
    void reduce_runs(const Key* keys, const ValueOf& value_of, std::size_t n, const Merge& merge, Key* run_keys,
                     Value* run_values, std::uint32_t* run_count) const {
        const GuardedArena::Opened opened;
        CpuExec::reduce_runs(keys, value_of, n, merge, run_keys, run_values, run_count);
    }
    template <class T>
    void upload(T* device, const T* host, std::size_t n) const {
        const GuardedArena::Opened opened;
        CpuExec::upload(device, host, n);
    }
    template <class T>
    void download(T* host, const T* device, std::size_t n) const {
        poison_landed_views();
        const GuardedArena::Opened opened;
        CpuExec::download(host, device, n);
    }
    template <class T>
    void copy(T* destination, const T* source, std::size_t n) const {
        const GuardedArena::Opened opened;
        CpuExec::copy(destination, source, n);
    }
    /// @brief Queues a download into a staging copy of its own, which landed() points at after the
    /// next finish_downloads() (never at the backend's memory, as on the GPU).
    template <class T>
    std::size_t download_view_later(const T* device, std::size_t n) const {
        views_.emplace_back(n * sizeof(T));
        unsigned char* staging = views_.back().data();
        CpuExec::download_later(staging, reinterpret_cast<const unsigned char*>(device), n * sizeof(T));
        CpuExec::download_view_later(staging, n); // so that a finish waits as CudaExec's does, even for n = 0
        return views_.size() - 1 - landed_count_;
    }
    template <class T>
    const T* landed(std::size_t view) const {
        return reinterpret_cast<const T*>(views_[view].data());
    }
    void finish_downloads() const {
        // The GPU reuses the staging of the finish before: its views are patterned, then dropped.
        poison_landed_views();
        views_.erase(views_.begin(), views_.begin() + static_cast<std::ptrdiff_t>(landed_count_));
        landed_count_ = views_.size();
        const GuardedArena::Opened opened;
        CpuExec::finish_downloads();
    }

private:
    void poison_landed_views() const {
        for (std::size_t v = 0; v < landed_count_; ++v) std::memset(views_[v].data(), 0xA5, views_[v].size());
    }
    /// Staging copies: the first landed_count_ landed at the last finish, the rest are queued.
    mutable std::vector<std::vector<unsigned char>> views_;
    mutable std::size_t landed_count_ = 0;
};

} // namespace kdet::device_like
