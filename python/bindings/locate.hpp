#pragma once
/// @file locate.hpp
/// @brief Point location in Python: kdet.locate() and Detector.locate(), NumPy arrays out (or DLPack
/// arrays of the detector's buffers).

#include <kdet/detector.hpp>
#include <kdet/options.hpp>

#include <nanobind/nanobind.h>

#include <mutex>

namespace kdet::python {

namespace nb = nanobind;

/// @brief Detector.locate(points, object=None, within=None, device_results=False) on the detector
/// that @p owner (the Python object) holds; the call holds @p mutex without the GIL.
nb::object detector_locate(nb::handle owner, Detector& detector, std::mutex& mutex, nb::handle points, nb::handle object,
                           nb::handle within, bool device_results);

/// @brief Binds LocateResult and kdet.locate(mesh, points, within=None, **options); @p options_from
/// reads Detector's keywords.
void bind_locate(nb::module_& m, DetectorOptions (*options_from)(const nb::kwargs&));

} // namespace kdet::python
