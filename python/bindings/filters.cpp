// kdet.Detector's collision filters (groups and masks, self-exclusion rings, rest contacts) and its
// changes of topology (remove_object, set_tets), as the library's Detector has them.
#include "arrays.hpp"
#include "detector.hpp"

#include <kdet/kdet.hpp>

#include <nanobind/nanobind.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>

#include <optional>
#include <string>
#include <utility>

namespace kdet::python {

namespace {

using namespace nb::literals;

/// A 32-bit group or mask from a Python int, refused with a kdet.Error naming the argument.
std::uint32_t bits(std::int64_t value, const char* name) {
    if (value < 0 || value > 0xffffffffll)
        throw Error(std::string(name) + " " + std::to_string(value) + " out of range [0, 4294967295]");
    return static_cast<std::uint32_t>(value);
}

void set_tets(PyDetector& self, Arg<std::int64_t> object, nb::handle tets, nb::handle vertices) {
    const ObjectId id = object_id(self, object);
    const TetIndices t = tet_indices(tets, "tets");
    if (vertices.is_none()) return locked(self, [&] { self.detector.set_tets(id, t.data, t.rows); });
    const Coordinates c = coordinates(vertices, "vertices");
    if (c.on_device) throw nb::type_error("vertices: set_tets reads the vertices on the host");
    locked(self, [&] { self.detector.set_tets(id, t.data, t.rows, c.view()); });
}

} // namespace

void bind_filters(nb::class_<PyDetector>& detector) {
    detector.attr("MAX_EXCLUSION_RINGS") = max_exclusion_rings;
    detector
        .def(
            "set_collision_filter",
            [](PyDetector& self, Arg<std::int64_t> object, Arg<std::int64_t> group, Arg<std::int64_t> mask) {
                const ObjectId id = object_id(self, object);
                const std::uint32_t g = bits(read_arg(group, "group"), "group"), k = bits(read_arg(mask, "mask"), "mask");
                locked(self, [&] { self.detector.set_collision_filter(id, g, k); });
            },
            "object"_a, "group"_a, "mask"_a,
            "Sets an object's collision group and mask (32 bits each): objects a and b are checked when "
            "group_a & mask_b and group_b & mask_a are both nonzero. Objects start in group 1 with every mask bit "
            "set. set_pair_collision() wins over the filters; self-collision is set_self_collision()'s alone.")
        .def(
            "collision_filter",
            [](PyDetector& self, Arg<std::int64_t> object) {
                const CollisionFilter f = self.detector.collision_filter(object_id(self, object));
                return std::make_pair(f.group, f.mask);
            },
            "object"_a, "The object's (group, mask).")
        .def(
            "set_self_exclusion_rings",
            [](PyDetector& self, Arg<std::int64_t> object, Arg<int> rings) {
                const ObjectId id = object_id(self, object);
                const int n = read_arg(rings, "rings");
                locked(self, [&] { self.detector.set_self_exclusion_rings(id, n); });
            },
            "object"_a, "rings"_a,
            "Within the object, also leaves out tets with vertices within `rings` mesh edges of each other (0, the "
            "default: only tets sharing a vertex); at most Detector.MAX_EXCLUSION_RINGS.")
        .def(
            "self_exclusion_rings",
            [](PyDetector& self, Arg<std::int64_t> object) { return self.detector.self_exclusion_rings(object_id(self, object)); },
            "object"_a)
        .def(
            "exclude_rest_contacts",
            [](PyDetector& self, Arg<std::int64_t> object, std::optional<Arg<std::int64_t>> other) {
                const ObjectId a = object_id(self, object), b = other ? object_id(self, *other, "other") : a;
                return locked(self, [&] { return self.detector.exclude_rest_contacts(a, b); });
            },
            "object"_a, "other"_a = nb::none(),
            "Records the pairs of tets colliding now inside the object (or between it and `other`) and never "
            "reports them again; returns how many it recorded.")
        .def(
            "remove_object",
            [](PyDetector& self, Arg<std::int64_t> object) {
                const ObjectId id = object_id(self, object);
                locked(self, [&] { self.detector.remove_object(id); });
            },
            "object"_a,
            "Removes an object; its id is not given again, and using it raises kdet.Error. Its entry of "
            "FrameResult.colliding stays, empty.")
        .def(
            "set_tets",
            [](PyDetector& self, Arg<std::int64_t> object, const TetMesh& mesh) {
                const ObjectId id = object_id(self, object);
                locked(self, [&] { self.detector.set_tets(id, mesh); });
            },
            "object"_a, "mesh"_a, "Replaces the object's vertices and tets by a TetMesh's.")
        .def("set_tets", &set_tets, "object"_a, "tets"_a, "vertices"_a = nb::none(),
             "Replaces the object's tets (m, 4), keeping its vertices, or with `vertices` (n, 3) those too (their "
             "count may change). Results use the new numbering from the next detect(); the other objects keep "
             "their state.")
        .def(
            "contains",
            [](PyDetector& self, Arg<std::int64_t> object) {
                const std::int64_t id = read_arg(object, "object");
                return id >= 0 && self.detector.contains(static_cast<ObjectId>(id));
            },
            "object"_a, "Whether the id names an object that was added and not removed.");
}

} // namespace kdet::python
