#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

namespace kdet {

std::vector<std::string> scene_names() { return {"procedural"}; }

std::unique_ptr<Scene> open_scene(const std::string& name, const SceneRequest& request) {
    if (name == "procedural") return std::make_unique<ProceduralScene>(request.procedural);
    std::string known;
    for (const std::string& n : scene_names()) known += (known.empty() ? "" : ", ") + n;
    throw Error("unknown scene '" + name + "' (known scenes: " + known + ")");
}

} // namespace kdet
