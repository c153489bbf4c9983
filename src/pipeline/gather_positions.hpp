#pragma once
/// @file gather_positions.hpp
/// @brief Positions as they lie in the caller's memory (a PositionsView: float32 or float64, any
/// strides), read one vertex at a time as the float32 the pipeline stores. The host's loops over the
/// caller's positions and the backend's gather of positions handed over in its memory read them
/// through the same element code.

#include "geometry/vec3.hpp"

#include <kdet/detector.hpp>

#include <cstddef>
#include <cstdint>

namespace kdet {

/// @brief Vertex v's coordinate k of a PositionsView holding `Scalar`s, as float32.
template <class Scalar>
struct StridedPositions {
    const Scalar* data;
    std::int64_t row_stride;    ///< in elements
    std::int64_t column_stride; ///< in elements

    explicit StridedPositions(const PositionsView& view)
        : data(static_cast<const Scalar*>(view.data)), row_stride(view.row_stride), column_stride(view.column_stride) {}

    /// @brief Where vertex v's x lies.
    KDET_HD const Scalar* row(std::uint64_t v) const { return data + static_cast<std::int64_t>(v) * row_stride; }
    KDET_HD vec3 operator()(std::uint64_t v) const {
        const Scalar* p = row(v);
        return vec3{static_cast<float>(p[0]), static_cast<float>(p[column_stride]),
                    static_cast<float>(p[2 * column_stride])};
    }
};

/// @brief Writes the float32 x y z of `source`'s vertex i to out[i]: positions handed over in the
/// backend's memory in a layout of their own.
template <class Source>
struct GatherPositionsKernel {
    Source source; ///< a StridedPositions
    vec3* out;
    KDET_HD void operator()(std::uint64_t i) const { out[i] = source(i); }
};

/// @brief Contiguous x y z per vertex, as the pipeline stores them and as the plain overloads take them.
inline PositionsView xyz_view(const float* xyz, std::size_t vertex_count) { return PositionsView{xyz, false, vertex_count}; }
inline PositionsView xyz_view(const double* xyz, std::size_t vertex_count) { return PositionsView{xyz, true, vertex_count}; }
inline PositionsView xyz_view(const vec3* points, std::size_t vertex_count) {
    static_assert(sizeof(vec3) == 3 * sizeof(float), "a vec3 is its three coordinates");
    return xyz_view(reinterpret_cast<const float*>(points), vertex_count);
}

/// @brief Whether `view` lies as the pipeline stores positions (float32 x y z per vertex).
inline bool is_xyz_float(const PositionsView& view) {
    return !view.is_double && (view.vertex_count <= 1 || view.row_stride == 3) && view.column_stride == 1;
}

/// @brief Calls `f(StridedPositions<float or double>)` for the scalar type `view` holds.
template <class F>
decltype(auto) with_positions(const PositionsView& view, F&& f) {
    if (view.is_double) return f(StridedPositions<double>(view));
    return f(StridedPositions<float>(view));
}

} // namespace kdet
