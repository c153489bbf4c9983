#pragma once
/// @file scenes.hpp
/// @brief The benchmark scenes in Python: kdet.Scene, kdet.open_scene(), kdet.scene_names() and
/// kdet.add_scene_objects().

#include <nanobind/nanobind.h>

namespace kdet::python {

/// @brief Binds the scenes on @p m, after kdet.Detector and kdet.TetMesh.
void bind_scenes(nanobind::module_& m);

} // namespace kdet::python
