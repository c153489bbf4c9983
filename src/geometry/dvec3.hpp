#pragma once
/// @file dvec3.hpp
/// @brief A double 3-vector for the double levels of the exact tests and for closest points.

#include "geometry/vec3.hpp"

namespace kdet::narrow {

struct dvec3 {
    double x, y, z;
};
KDET_HD inline dvec3 widen(vec3 v) { return {v.x, v.y, v.z}; }
KDET_HD inline dvec3 operator-(dvec3 a, dvec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
KDET_HD inline dvec3 operator+(dvec3 a, dvec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
KDET_HD inline dvec3 operator*(double s, dvec3 v) { return {s * v.x, s * v.y, s * v.z}; }
KDET_HD inline double dot(dvec3 a, dvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
KDET_HD inline dvec3 cross(dvec3 a, dvec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
KDET_HD inline double norm1(dvec3 v) { return fabs(v.x) + fabs(v.y) + fabs(v.z); }
KDET_HD inline double max_d(double a, double b) { return a > b ? a : b; }
KDET_HD inline double norm_inf(dvec3 v) { return max_d(fabs(v.x), max_d(fabs(v.y), fabs(v.z))); }
KDET_HD inline double component(dvec3 v, int axis) { return axis == 0 ? v.x : (axis == 1 ? v.y : v.z); }

} // namespace kdet::narrow
