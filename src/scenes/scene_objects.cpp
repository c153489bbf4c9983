/// @file scene_objects.cpp
/// @brief add_scene_objects: a scene's objects and the collisions it checks, set up in a Detector;
/// set_scene_tets: the tets of a scene whose tets change, frame by frame.

#include <kdet/scenes.hpp>

namespace kdet {

const char* to_string(SceneSelfCollision self) {
    switch (self) {
    case SceneSelfCollision::every: return "yes";
    case SceneSelfCollision::marked: return "scene";
    default: return "no";
    }
}

bool self_collision_of(const Scene& scene, std::size_t object, SceneSelfCollision self) {
    return self == SceneSelfCollision::every || (self == SceneSelfCollision::marked && scene.checks_self(object));
}

void add_scene_objects(Detector& detector, const Scene& scene, SceneSelfCollision self) {
    const auto first = static_cast<ObjectId>(detector.object_count());
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        const ObjectId id = detector.add_object(scene.rest_mesh(o));
        detector.set_self_collision(id, self_collision_of(scene, o, self));
        detector.set_static(id, scene.is_static(o));
        const CollisionFilter filter = scene.collision_filter(o);
        if (filter.group != CollisionFilter{}.group || filter.mask != CollisionFilter{}.mask)
            detector.set_collision_filter(id, filter.group, filter.mask);
    }
    for (std::size_t a = 0; a < scene.num_objects(); ++a)
        for (std::size_t b = a + 1; b < scene.num_objects(); ++b)
            if (!scene.checks_pair(a, b))
                detector.set_pair_collision(first + static_cast<ObjectId>(a), first + static_cast<ObjectId>(b), false);
}

void set_scene_tets(Detector& detector, const Scene& scene, int frame, std::vector<std::vector<std::uint32_t>>& current,
                    ObjectId first_id) {
    if (!scene.changes_tets()) return;
    std::vector<std::uint32_t> tets;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        scene.tets(o, frame, tets);
        if (tets == current[o]) continue;
        detector.set_tets(first_id + static_cast<ObjectId>(o), tets.data(), tets.size() / 4);
        current[o].swap(tets);
    }
}

} // namespace kdet
