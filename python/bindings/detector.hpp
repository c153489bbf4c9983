#pragma once
/// @file detector.hpp
/// @brief The binding's Detector (kdet.Detector) as the files that bind its methods share it.

#include <kdet/detector.hpp>
#include <kdet/error.hpp>

#include "scalars.hpp"

#include <nanobind/nanobind.h>

#include <cstdint>
#include <mutex>
#include <string>

namespace kdet::python {

namespace nb = nanobind;

/// A Detector and what the binding keeps beside it. Every call holds `mutex` with the GIL released, so
/// that detect() can run while other Python threads work, and two threads never use the detector at once.
struct PyDetector {
    explicit PyDetector(const DetectorOptions& options) : detector(options) {}
    Detector detector;
    std::mutex mutex;
};

/// An object id from Python, refused with the library's message when out of range (negative included).
inline ObjectId object_id(PyDetector& self, std::int64_t object) {
    if (object < 0 || static_cast<std::uint64_t>(object) >= self.detector.object_count())
        throw Error("object id " + std::to_string(object) + " out of range (" +
                    std::to_string(self.detector.object_count()) + " objects)");
    return static_cast<ObjectId>(object);
}

/// The argument @p name as an object id (a TypeError for a value that is no int).
inline ObjectId object_id(PyDetector& self, Arg<std::int64_t> object, const char* name = "object") {
    return object_id(self, read_arg(object, name));
}

/// Calls @p f with the lock held and the GIL released.
template <class F>
auto locked(PyDetector& self, F&& f) {
    nb::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(self.mutex);
    return f();
}

/// Binds the collision filters and topology changes (filters.cpp) on kdet.Detector.
void bind_filters(nb::class_<PyDetector>& detector);

} // namespace kdet::python
