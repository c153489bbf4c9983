/// @file scene_registry.cpp
/// @brief open_scene: the built-in scenes by name, and scene files, recordings and frame folders by path.

#include "scenes/scripted_scene.hpp"
#include "scenes/tearing_scene.hpp"

#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/scenes.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace kdet {
namespace {

bool ends_with(const std::string& text, const std::string& suffix) {
    return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::unique_ptr<Scene> play(scenes::SceneSpec spec, const std::string& default_name, const SceneRequest& request,
                            const std::string& base_dir, bool user_file) {
    if (spec.name.empty()) spec.name = default_name;
    return std::make_unique<scenes::ScriptedScene>(std::move(spec), request.resolution, base_dir, user_file);
}

} // namespace

std::vector<std::string> scene_names() {
    std::vector<std::string> names = {"procedural"};
    for (const auto& [name, text] : scenes::builtin_scene_files()) names.push_back(name);
    names.insert(names.end(), {"tearing", "heap", "drape", "graded"});
    return names;
}

bool names_a_scene(const std::string& argument) {
    const std::vector<std::string> names = scene_names();
    if (std::find(names.begin(), names.end(), argument) != names.end()) return true;
    if (ends_with(argument, ".scene") || ends_with(argument, ".kdetrec")) return true;
    std::error_code ignored;
    return std::filesystem::is_directory(argument, ignored);
}

std::unique_ptr<Scene> read_scene_file(const std::string& path, const SceneRequest& request) {
    std::error_code ignored;
    if (std::filesystem::is_directory(path, ignored)) throw Error(path + ": cannot open scene file (it is a directory)");
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot open scene file");
    std::ostringstream text;
    text << in.rdbuf();
    const std::filesystem::path file(path);
    return play(scenes::parse_scene(text.str(), path), file.stem().string(), request, file.parent_path().string(), true);
}

std::unique_ptr<Scene> open_scene(const std::string& name, const SceneRequest& request) {
    if (request.resolution < 1 || request.resolution > 4)
        throw Error(name + ": resolution " + std::to_string(request.resolution) + " out of range [1, 4]");
    if (name == "procedural") return std::make_unique<ProceduralScene>(request.procedural);
    if (name == "tearing") return std::make_unique<scenes::TearingScene>(120);
    if (name == "heap") return make_heap_scene(request.resolution);
    if (name == "drape") return make_drape_scene(request.resolution);
    if (name == "graded") return make_graded_scene(request.resolution);
    for (const auto& [builtin, text] : scenes::builtin_scene_files())
        if (name == builtin) return play(scenes::parse_scene(text, "scenes/" + builtin + ".scene"), builtin, request, ".", false);
    if (names_a_scene(name)) {
        if (ends_with(name, ".scene")) return read_scene_file(name, request);
        if (ends_with(name, ".kdetrec")) return read_recording(name);
        return read_frame_folder(name);
    }
    std::string known;
    for (const std::string& n : scene_names()) known += (known.empty() ? "" : ", ") + n;
    throw Error("unknown scene '" + name + "' (known scenes: " + known +
                "; or a .scene file, a .kdetrec recording or a folder of frames)");
}

} // namespace kdet
