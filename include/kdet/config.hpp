#pragma once
/// @file config.hpp
/// @brief Compile-time configuration shared by host and device code.

/// @brief Marks a function as callable from host code and, under nvcc, from device code.
/// Every per-element step of the algorithm is written once with this macro.
#if defined(__CUDACC__)
#define KDET_HD __host__ __device__
#else
#define KDET_HD
#endif

#define KDET_VERSION_MAJOR 0
#define KDET_VERSION_MINOR 1
#define KDET_VERSION_PATCH 0
#define KDET_VERSION_STRING "0.1.0"
