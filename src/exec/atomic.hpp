#pragma once
/// @file atomic.hpp
/// @brief The few atomic operations the per-element code needs, one spelling for host and device.
/// Device code uses cuda::atomic_ref; host code (OpenMP threads) uses the GCC/Clang __atomic builtins.

#include <kdet/config.hpp>

#include <cstdint>

#if defined(__CUDACC__)
#include <cuda/atomic>
#endif

namespace kdet {

#if defined(__CUDA_ARCH__)
template <class T>
using device_atomic_ref = cuda::atomic_ref<T, cuda::thread_scope_device>;
#endif

template <class T>
KDET_HD inline T atomic_fetch_add(T* address, T value) {
#if defined(__CUDA_ARCH__)
    return device_atomic_ref<T>(*address).fetch_add(value, cuda::memory_order_relaxed);
#else
    return __atomic_fetch_add(address, value, __ATOMIC_RELAXED);
#endif
}

template <class T>
KDET_HD inline T atomic_fetch_or(T* address, T value) {
#if defined(__CUDA_ARCH__)
    return device_atomic_ref<T>(*address).fetch_or(value, cuda::memory_order_relaxed);
#else
    return __atomic_fetch_or(address, value, __ATOMIC_RELAXED);
#endif
}

template <class T>
KDET_HD inline T atomic_load_acquire(T* address) {
#if defined(__CUDA_ARCH__)
    return device_atomic_ref<T>(*address).load(cuda::memory_order_acquire);
#else
    return __atomic_load_n(address, __ATOMIC_ACQUIRE);
#endif
}

template <class T>
KDET_HD inline void atomic_store_release(T* address, T value) {
#if defined(__CUDA_ARCH__)
    device_atomic_ref<T>(*address).store(value, cuda::memory_order_release);
#else
    __atomic_store_n(address, value, __ATOMIC_RELEASE);
#endif
}

template <class T>
KDET_HD inline void atomic_store_relaxed(T* address, T value) {
#if defined(__CUDA_ARCH__)
    device_atomic_ref<T>(*address).store(value, cuda::memory_order_relaxed);
#else
    __atomic_store_n(address, value, __ATOMIC_RELAXED);
#endif
}

/// @brief Compare-and-swap; on failure `expected` receives the current value.
template <class T>
KDET_HD inline bool atomic_compare_exchange(T* address, T& expected, T desired) {
#if defined(__CUDA_ARCH__)
    return device_atomic_ref<T>(*address).compare_exchange_strong(expected, desired, cuda::memory_order_acq_rel,
                                                                  cuda::memory_order_acquire);
#else
    return __atomic_compare_exchange_n(address, &expected, desired, false, __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE);
#endif
}

template <class T>
KDET_HD inline void atomic_min(T* address, T value) {
#if defined(__CUDA_ARCH__)
    device_atomic_ref<T>(*address).fetch_min(value, cuda::memory_order_relaxed);
#else
    T current = __atomic_load_n(address, __ATOMIC_RELAXED);
    while (value < current && !__atomic_compare_exchange_n(address, &current, value, true, __ATOMIC_RELAXED,
                                                           __ATOMIC_RELAXED)) {
    }
#endif
}

template <class T>
KDET_HD inline void atomic_max(T* address, T value) {
#if defined(__CUDA_ARCH__)
    device_atomic_ref<T>(*address).fetch_max(value, cuda::memory_order_relaxed);
#else
    T current = __atomic_load_n(address, __ATOMIC_RELAXED);
    while (value > current && !__atomic_compare_exchange_n(address, &current, value, true, __ATOMIC_RELAXED,
                                                           __ATOMIC_RELAXED)) {
    }
#endif
}

/// @brief atomic_fetch_add on a counter that the threads of a warp often add to at once (the
/// candidates' count, the rejected pairs): on the GPU the lanes that arrive together at one address add
/// their sum through one atomic, the lowest lane's, and each gets what it would have got adding in
/// lane order, since atomics on one address queue one after the other at the L2. The host adds plainly.
template <class T>
KDET_HD inline T atomic_fetch_add_gathered(T* address, T value) {
#if defined(__CUDA_ARCH__)
    const unsigned same = __match_any_sync(__activemask(), reinterpret_cast<unsigned long long>(address));
    unsigned lane;
    asm("mov.u32 %0, %%laneid;" : "=r"(lane));
    T sum = 0, below = 0;
    for (unsigned rest = same; rest; rest &= rest - 1u) {
        const unsigned other = static_cast<unsigned>(__ffs(static_cast<int>(rest)) - 1);
        const T v = __shfl_sync(same, value, static_cast<int>(other));
        sum += v;
        if (other < lane) below += v;
    }
    const int leader = __ffs(static_cast<int>(same)) - 1;
    T first = 0;
    if (static_cast<int>(lane) == leader) first = atomic_fetch_add(address, sum);
    return __shfl_sync(same, first, leader) + below;
#else
    return atomic_fetch_add(address, value);
#endif
}

/// @brief atomic_min and atomic_max after a plain read, for a running extreme that few values move
/// once the first have arrived: most threads then only read (a GPU's fetch_min writes either way).
template <class T>
KDET_HD inline void atomic_lower_to(T* address, T value) {
    if (value < atomic_load_acquire(address)) atomic_min(address, value);
}
template <class T>
KDET_HD inline void atomic_raise_to(T* address, T value) {
    if (value > atomic_load_acquire(address)) atomic_max(address, value);
}

/// @brief Maps a float to an unsigned integer with the same order, so float min/max can use integer atomics.
KDET_HD inline std::uint32_t float_to_ordered(float value) {
    std::uint32_t bits;
    __builtin_memcpy(&bits, &value, sizeof bits);
    return (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
}

KDET_HD inline float ordered_to_float(std::uint32_t ordered) {
    std::uint32_t bits = (ordered & 0x80000000u) ? (ordered & 0x7fffffffu) : ~ordered;
    float value;
    __builtin_memcpy(&value, &bits, sizeof value);
    return value;
}

} // namespace kdet
