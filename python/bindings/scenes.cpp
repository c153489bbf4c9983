// The benchmark scenes in Python: kdet.open_scene(), kdet.Scene and kdet.add_scene_objects(), as the
// C++ scene API (kdet/scenes.hpp, the kdet_scenes target) gives them to `kdet bench`; the frame loop
// that plays a scene into a Detector is kdet.run_scene() in the pure-Python part.
#include "arrays.hpp"
#include "detector.hpp"
#include "scalars.hpp"
#include "scenes.hpp"

#include <kdet/scenes.hpp>

#include <nanobind/ndarray.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace kdet::python {

namespace {

using namespace nb::literals;

struct PyScene {
    std::unique_ptr<Scene> scene;
};

std::size_t object_of(const PyScene& self, Arg<std::int64_t> object_arg, const char* name = "object") {
    const std::int64_t object = read_arg(object_arg, name);
    if (object < 0 || static_cast<std::uint64_t>(object) >= self.scene->num_objects())
        throw Error("scene " + self.scene->name() + ": object " + std::to_string(object) + " out of range (" +
                    std::to_string(self.scene->num_objects()) + " objects)");
    return static_cast<std::size_t>(object);
}

/// add_scene_objects' self_collision: True, False, or 'scene' for the objects the scene marks.
SceneSelfCollision self_collision_arg(nb::handle value) {
    if (nb::isinstance<nb::str>(value)) {
        if (nb::cast<std::string>(value) == "scene") return SceneSelfCollision::marked;
        throw Error("self_collision: '" + nb::cast<std::string>(value) + "' is not a choice (True, False or 'scene')");
    }
    bool every = false;
    if (!read_bool(value, every))
        throw nb::type_error(("self_collision: expected a bool or 'scene', got " + type_label(value)).c_str());
    return every ? SceneSelfCollision::every : SceneSelfCollision::none;
}

int frame_of(const PyScene& self, Arg<std::int64_t> frame_arg) {
    const std::int64_t frame = read_arg(frame_arg, "frame");
    if (frame < 0 || frame >= self.scene->num_frames())
        throw Error("scene " + self.scene->name() + ": frame " + std::to_string(frame) + " out of range (" +
                    std::to_string(self.scene->num_frames()) + " frames)");
    return static_cast<int>(frame);
}

/// @brief @p values as a (rows, Columns) NumPy array that owns them.
template <class Scalar, std::size_t Columns>
nb::ndarray<nb::numpy, Scalar, nb::shape<-1, static_cast<nb::ssize_t>(Columns)>> owned_rows(std::vector<Scalar>&& values) {
    auto* held = new std::vector<Scalar>(std::move(values));
    const std::size_t rows = held->size() / Columns;
    held->reserve(held->size() + 1); // never a null pointer, even when empty
    nb::capsule owner(held, [](void* p) noexcept { delete static_cast<std::vector<Scalar>*>(p); });
    return {held->data(), {rows, Columns}, owner};
}

} // namespace

void bind_scenes(nb::module_& m) {
    nb::class_<PyScene>(m, "Scene",
                        "A benchmark scene as `kdet bench` runs it (kdet.open_scene()): objects with rest meshes whose "
                        "vertices move every frame, the pairs of objects it checks, their collision filters, its static "
                        "objects and, in a scene such as tearing, tets that change between frames. Object and frame "
                        "numbers start at 0.")
        .def_prop_ro("name", [](const PyScene& s) { return s.scene->name(); })
        .def_prop_ro("num_objects", [](const PyScene& s) { return s.scene->num_objects(); })
        .def_prop_ro("num_frames", [](const PyScene& s) { return s.scene->num_frames(); })
        .def_prop_ro(
            "resolution", [](const PyScene& s) { return s.scene->resolution(); },
            "The resolution (1-4) its meshes were built at, 0 for a scene without one (procedural, recordings).")
        .def_prop_ro("changes_tets", [](const PyScene& s) { return s.scene->changes_tets(); },
                     "Whether some object's tets change between frames (then use tets(object, frame)).")
        .def(
            "rest_mesh", [](const PyScene& s, Arg<std::int64_t> object) { return s.scene->rest_mesh(object_of(s, object)); },
            "object"_a, "A copy of the object's rest mesh: the tets and vertices it is added with.")
        .def(
            "positions",
            [](const PyScene& s, Arg<std::int64_t> object, Arg<std::int64_t> frame) {
                std::vector<float> xyz;
                s.scene->positions(object_of(s, object), frame_of(s, frame), xyz);
                return owned_rows<float, 3>(std::move(xyz));
            },
            "object"_a, "frame"_a, "The object's vertex positions at the frame, (n, 3) float32.")
        .def(
            "tets",
            [](const PyScene& s, Arg<std::int64_t> object, Arg<std::int64_t> frame) {
                std::vector<std::uint32_t> tets;
                s.scene->tets(object_of(s, object), frame_of(s, frame), tets);
                return owned_rows<std::uint32_t, 4>(std::move(tets));
            },
            "object"_a, "frame"_a, "The object's tets at the frame, (m, 4) uint32 into the rest mesh's vertices.")
        .def(
            "is_static", [](const PyScene& s, Arg<std::int64_t> object) { return s.scene->is_static(object_of(s, object)); },
            "object"_a, "Whether the object never moves (added static, its positions given once).")
        .def(
            "checks_self", [](const PyScene& s, Arg<std::int64_t> object) { return s.scene->checks_self(object_of(s, object)); },
            "object"_a)
        .def(
            "checks_pair",
            [](const PyScene& s, Arg<std::int64_t> a, Arg<std::int64_t> b) {
                return s.scene->checks_pair(object_of(s, a, "a"), object_of(s, b, "b"));
            },
            "a"_a, "b"_a, "Whether the scene checks collisions between objects a and b.")
        .def(
            "collision_filter",
            [](const PyScene& s, Arg<std::int64_t> object) {
                const CollisionFilter f = s.scene->collision_filter(object_of(s, object));
                return std::make_pair(f.group, f.mask);
            },
            "object"_a, "The object's (group, mask), as Detector.set_collision_filter() takes them.")
        .def("__repr__", [](const PyScene& s) {
            return "kdet.Scene('" + s.scene->name() + "', " + std::to_string(s.scene->num_objects()) + " objects, " +
                   std::to_string(s.scene->num_frames()) + " frames)";
        });

    m.def(
        "open_scene",
        [](const std::filesystem::path& name, Arg<int> resolution_arg, Arg<std::int64_t> tets_arg, Arg<int> frames_arg) {
            const int resolution = read_arg(resolution_arg, "resolution"), frames = read_arg(frames_arg, "frames");
            const std::int64_t tets = read_arg(tets_arg, "tets");
            if (tets < 0) throw Error("tets: " + std::to_string(tets) + " is negative");
            SceneRequest request;
            request.resolution = resolution;
            request.procedural = ProceduralSceneOptions{static_cast<std::size_t>(tets), frames};
            nb::gil_scoped_release release;
            return PyScene{open_scene(name.string(), request)};
        },
        "name"_a, "resolution"_a = 1, "tets"_a = ProceduralSceneOptions{}.total_tets,
        "frames"_a = ProceduralSceneOptions{}.frames,
        "Opens a scene as `kdet bench NAME -r RESOLUTION` does: a name of scene_names() or the path of a scene file, "
        "recording or folder of frames. tets and frames size the procedural scene. The thesis scenes read the meshes "
        "`kdet prepare` made.");
    m.def("scene_names", &scene_names, "The scene names open_scene() knows.");
    m.def(
        "write_recording",
        [](const PyScene& s, const std::filesystem::path& path) {
            nb::gil_scoped_release release;
            kdet::write_recording(*s.scene, path.string());
        },
        "scene"_a, "path"_a,
        "Records every frame of a scene into a .kdetrec file (docs/scenes.md), with its self-collision, checked "
        "pairs, collision filters and static objects; open_scene(path) plays it back. A scene whose tets change "
        "(changes_tets) raises kdet.Error.");
    m.def(
        "add_scene_objects",
        [](PyDetector& detector, const PyScene& s, nb::handle self_collision) {
            const SceneSelfCollision self = self_collision_arg(self_collision);
            locked(detector, [&] { add_scene_objects(detector.detector, *s.scene, self); });
        },
        "detector"_a, "scene"_a, "self_collision"_a = false,
        nb::sig("def add_scene_objects(detector: Detector, scene: Scene, self_collision: bool | str = False) -> None"),
        "Adds every object of the scene to the detector (ids in scene order from its object_count on), as `kdet bench` "
        "does: self-collision of every object (self_collision=True, `-s yes`), of none (False) or of those the scene "
        "marks ('scene', `-s scene`: a scene file's `self` lines), collisions between the object pairs the scene "
        "checks only, its collision filters, and its static objects static.");
}

} // namespace kdet::python
