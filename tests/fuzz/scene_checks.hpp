#pragma once
/// What a scene file must get from parse_scene whatever its bytes (the fuzzer's and the replay test's
/// oracle), and the hand-written seed that uses every statement of docs/scenes.md once.

#include "scenes/scripted_scene.hpp"

#include <kdet/error.hpp>

#include <string>

namespace kdet::test {

/// A scene that uses every statement, the new scenes' `static` among them, with comments and odd spacing.
inline const char* const every_statement_scene = "kdet-scene 1   # version\n"
                                                 "name all\nframes 90\n\n"
                                                 "object floor\n  mesh bunny\n  resolution 2\n  static\n"
                                                 "  scale 2.5\n  rotate 90 0 -45\n  translate 0 -1e-3 4E+2\n"
                                                 "object cloth\n\tfile cloth.msh\n  bend x y\n  twist z\n  squash y\n"
                                                 "  wobble 0.05 30\n"
                                                 "  key 0 move 0 0 0 turn 0 0 0 bend 0 twist 0 squash 0.5\n"
                                                 "  key 45.5 move 1 2 3 bend 0.5\n  key 89 twist 180 squash 0.25\n"
                                                 "collide floor cloth\nself cloth\n";

/// What is wrong with parse_scene's answer to @p text, or "" when it is what any input must get: a
/// spec within the format's limits, or a kdet::Error of one line that starts "SOURCE:LINE: ".
inline std::string scene_parse_problem(const std::string& text) {
    const std::string source = "fuzz.scene";
    scenes::SceneSpec spec;
    try {
        spec = scenes::parse_scene(text, source);
    } catch (const Error& error) {
        const std::string message = error.what();
        if (message.find('\n') != std::string::npos) return "error of more than one line: " + message;
        if (message.rfind(source + ":", 0) != 0) return "error that does not name the file: " + message;
        const std::size_t digits = message.find_first_not_of("0123456789", source.size() + 1);
        if (digits == source.size() + 1 || digits == std::string::npos || message.compare(digits, 2, ": ") != 0)
            return "error that does not name the line: " + message;
        return "";
    }
    if (spec.frames < 1 || spec.frames > 1000000) return "frames out of range: " + std::to_string(spec.frames);
    if (spec.objects.empty()) return "a scene without objects";
    for (const scenes::ObjectSpec& o : spec.objects) {
        if (o.model.empty() == o.file.empty()) return "object " + o.name + " without exactly one mesh";
        if (o.resolution < 0 || o.resolution > 4) return "object " + o.name + " with resolution " + std::to_string(o.resolution);
        if (!(o.scale > 0)) return "object " + o.name + " with a scale that is not positive";
        if (o.wobble_amplitude < 0 || (o.wobble_amplitude > 0 && !(o.wobble_period > 0)))
            return "object " + o.name + " with a wobble out of range";
        if (o.bend_along >= 0 && o.bend_along == o.bend_toward) return "object " + o.name + " bends along one axis";
        for (const auto& keys : o.keys) {
            for (std::size_t k = 0; k < keys.size(); ++k)
                if (keys[k].frame < 0 || (k > 0 && !(keys[k - 1].frame < keys[k].frame)))
                    return "object " + o.name + " with keys out of order";
            if (o.is_static && !keys.empty()) return "static object " + o.name + " with keys";
        }
        if (o.is_static && o.wobble_amplitude > 0) return "static object " + o.name + " that wobbles";
    }
    for (const auto& [a, b] : spec.pairs)
        if (!(a < b && b < spec.objects.size())) return "a pair of objects out of range";
    for (const std::size_t o : spec.self)
        if (o >= spec.objects.size()) return "self-collision of an object out of range";
    return "";
}

} // namespace kdet::test
