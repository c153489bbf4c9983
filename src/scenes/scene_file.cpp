/// @file scene_file.cpp
/// @brief Parsing scene files (docs/scenes.md) into a SceneSpec, and the curve through a channel's keys.

#include "scenes/scripted_scene.hpp"

#include <kdet/error.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <map>
#include <sstream>

namespace kdet::scenes {
namespace {

constexpr const char* kHeader = "kdet-scene";
constexpr int kMaxFrames = 1000000;

/// @brief One statement: its words and its line, with the means to fail there.
struct Statement {
    std::vector<std::string> words;
    std::size_t line = 0;
    const std::string* source = nullptr;

    [[noreturn]] void fail(const std::string& what) const {
        throw Error(*source + ":" + std::to_string(line) + ": " + what);
    }
    /// @brief Fails unless the statement has exactly @p count words after its keyword.
    void expect_arguments(std::size_t count, const char* usage) const {
        if (words.size() != count + 1) fail("'" + words[0] + "' expects: " + usage);
    }
    double number(std::size_t i) const {
        const std::string& text = words[i];
        // Decimal only: strtod would also take hex, "inf" and "nan". An underflow reads as the tiny value.
        const bool decimal = !text.empty() && text.find_first_not_of("0123456789+-.eE") == std::string::npos;
        errno = 0;
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (!decimal || *end != '\0' || (errno == ERANGE && std::fabs(value) > 1.0) || !std::isfinite(value))
            fail("'" + text + "' is not a finite decimal number");
        return value;
    }
    int integer(std::size_t i, int lo, int hi) const {
        const double value = number(i);
        if (value != std::floor(value) || value < lo || value > hi)
            fail("'" + words[i] + "' is not a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
        return static_cast<int>(value);
    }
    int axis(std::size_t i) const {
        const std::string& a = words[i];
        if (a == "x") return 0;
        if (a == "y") return 1;
        if (a == "z") return 2;
        fail("'" + a + "' is not an axis (x, y or z)");
    }
    std::array<double, 3> vector(std::size_t first) const {
        return {number(first), number(first + 1), number(first + 2)};
    }
};

std::vector<Statement> split_statements(const std::string& text, const std::string& source) {
    std::vector<Statement> statements;
    std::istringstream lines(text);
    std::string line;
    std::size_t number = 0;
    while (std::getline(lines, line)) {
        ++number;
        line = line.substr(0, line.find('#'));
        std::istringstream words(line);
        Statement statement{{}, number, &source};
        for (std::string word; words >> word;) statement.words.push_back(word);
        if (!statement.words.empty()) statements.push_back(std::move(statement));
    }
    return statements;
}

/// @brief A frame number as written in a scene file ("12", "12.5").
std::string short_frame(double frame) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", frame);
    return text;
}

std::size_t channel_width(Channel channel) { return channel == Channel::move || channel == Channel::turn ? 3 : 1; }

bool parse_channel(const std::string& word, Channel& channel) {
    static const char* const names[kNumChannels] = {"move", "turn", "bend", "twist", "squash"};
    for (std::size_t c = 0; c < kNumChannels; ++c)
        if (word == names[c]) {
            channel = static_cast<Channel>(c);
            return true;
        }
    return false;
}

/// @brief `key FRAME CHANNEL VALUES [CHANNEL VALUES ...]`.
void parse_key(const Statement& s, ObjectSpec& object) {
    if (s.words.size() < 4) s.fail("'key' expects: FRAME CHANNEL VALUE... (channels: move, turn, bend, twist, squash)");
    const double frame = s.number(1);
    if (frame < 0) s.fail("key frame " + s.words[1] + " is negative");
    for (std::size_t i = 2; i < s.words.size();) {
        Channel channel;
        if (!parse_channel(s.words[i], channel))
            s.fail("unknown channel '" + s.words[i] + "' (channels: move, turn, bend, twist, squash)");
        const std::size_t width = channel_width(channel);
        if (i + width >= s.words.size()) s.fail("'" + s.words[i] + "' needs " + std::to_string(width) + " value(s)");
        Key key;
        key.frame = frame;
        key.line = s.line;
        for (std::size_t k = 0; k < width; ++k) key.value[k] = s.number(i + 1 + k);
        // 0.9 keeps an object squashed to a tenth of its height and widened three times; -1 would
        // stretch it without end.
        if (channel == Channel::squash && !(key.value[0] > -1.0 && key.value[0] < 0.9))
            s.fail("squash " + s.words[i + 1] + " is outside (-1, 0.9)");
        std::vector<Key>& keys = object.keys[static_cast<std::size_t>(channel)];
        if (!keys.empty() && keys.back().frame >= frame)
            s.fail("keys of '" + s.words[i] + "' must have increasing frames (" + s.words[1] + " after " +
                   short_frame(keys.back().frame) + ")");
        keys.push_back(key);
        i += 1 + width;
    }
}

/// @brief The statements that describe the current object; false for another keyword. Each but `key`
/// stands once per object (`given` holds those seen so far, with their lines).
bool parse_object_statement(const Statement& s, ObjectSpec& object, std::map<std::string, std::size_t>& given) {
    const std::string& w = s.words[0];
    static const char* const once[] = {"resolution", "scale", "rotate", "translate", "bend", "twist", "squash", "wobble", "static"};
    if (std::find(std::begin(once), std::end(once), w) != std::end(once)) {
        const auto [at, first] = given.emplace(w, s.line);
        if (!first) s.fail("object '" + object.name + "' has '" + w + "' twice (first at line " + std::to_string(at->second) + ")");
    }
    if (w == "mesh" || w == "file") {
        s.expect_arguments(1, w == "mesh" ? "MODEL" : "PATH");
        if (!object.model.empty() || !object.file.empty()) s.fail("object '" + object.name + "' already has a mesh");
        (w == "mesh" ? object.model : object.file) = s.words[1];
        object.mesh_line = s.line;
    } else if (w == "resolution") {
        s.expect_arguments(1, "N (1-4)");
        object.resolution = s.integer(1, 1, 4);
    } else if (w == "scale") {
        s.expect_arguments(1, "FACTOR");
        object.scale = s.number(1);
        if (!(object.scale > 0)) s.fail("scale must be positive");
    } else if (w == "rotate") {
        s.expect_arguments(3, "DEG_X DEG_Y DEG_Z");
        object.rotate = s.vector(1);
    } else if (w == "translate") {
        s.expect_arguments(3, "X Y Z");
        object.translate = s.vector(1);
    } else if (w == "bend") {
        s.expect_arguments(2, "ALONG_AXIS TOWARD_AXIS");
        object.bend_along = s.axis(1);
        object.bend_toward = s.axis(2);
        if (object.bend_along == object.bend_toward) s.fail("bend needs two different axes");
    } else if (w == "twist") {
        s.expect_arguments(1, "AXIS");
        object.twist_axis = s.axis(1);
    } else if (w == "squash") {
        s.expect_arguments(1, "AXIS");
        object.squash_axis = s.axis(1);
    } else if (w == "wobble") {
        s.expect_arguments(2, "AMPLITUDE PERIOD_FRAMES");
        object.wobble_amplitude = s.number(1);
        object.wobble_period = s.number(2);
        if (object.wobble_amplitude < 0 || !(object.wobble_period > 0))
            s.fail("wobble needs an amplitude >= 0 and a positive period");
    } else if (w == "key") {
        parse_key(s, object);
    } else if (w == "static") {
        s.expect_arguments(0, "nothing");
        object.is_static = true;
    } else {
        return false;
    }
    return true;
}

/// @brief Deformation keys need their axis statement, and the squash between its keys must stay in
/// (-1, 0.9) too: the curve through the keys can overshoot them.
void check_deformation_keys(const ObjectSpec& o, int frames, const std::string& source) {
    const auto fail = [&](std::size_t line, const std::string& what) {
        throw Error(source + ":" + std::to_string(line) + ": object '" + o.name + "': " + what);
    };
    const struct {
        Channel channel;
        bool set;
        const char* statement;
    } deformations[] = {{Channel::bend, o.bend_along >= 0, "bend ALONG_AXIS TOWARD_AXIS"},
                        {Channel::twist, o.twist_axis >= 0, "twist AXIS"},
                        {Channel::squash, o.squash_axis >= 0, "squash AXIS"}};
    for (const auto& d : deformations) {
        const std::vector<Key>& keys = o.keys[static_cast<std::size_t>(d.channel)];
        if (!keys.empty() && !d.set)
            fail(keys.front().line, "its " + std::string(d.statement).substr(0, std::string(d.statement).find(' ')) +
                                        " keys need a '" + d.statement + "' statement");
    }
    const std::vector<Key>& squash = o.keys[static_cast<std::size_t>(Channel::squash)];
    for (std::size_t k = 0; k + 1 < squash.size(); ++k)
        for (double frame = std::ceil(squash[k].frame); frame < squash[k + 1].frame && frame < frames; ++frame) {
            const double value = evaluate(squash, frame)[0];
            if (!(value > -1.0 && value < 0.9)) {
                char text[32];
                std::snprintf(text, sizeof text, "%.3g", value);
                fail(squash[k + 1].line, "the squash between the keys of frames " + short_frame(squash[k].frame) + " and " +
                                             short_frame(squash[k + 1].frame) + " reaches " + text + " at frame " +
                                             short_frame(frame) + ", outside (-1, 0.9): the curve through the keys "
                                             "overshoots them (add a key or move one)");
            }
        }
}

std::size_t find_object(const SceneSpec& spec, const Statement& s, std::size_t word) {
    for (std::size_t o = 0; o < spec.objects.size(); ++o)
        if (spec.objects[o].name == s.words[word]) return o;
    s.fail("no object named '" + s.words[word] + "'");
}

} // namespace

std::array<double, 3> evaluate(const std::vector<Key>& keys, double frame) {
    if (keys.empty()) return {};
    if (frame <= keys.front().frame) return keys.front().value;
    if (frame >= keys.back().frame) return keys.back().value;
    std::size_t k = 0;
    while (keys[k + 1].frame <= frame) ++k;
    // Catmull-Rom tangents; the first and last key take the slope towards their neighbour, so that two
    // keys give a constant speed.
    const auto tangent = [&](std::size_t i, std::size_t axis) {
        const std::size_t before = i == 0 ? 0 : i - 1, after = i + 1 == keys.size() ? i : i + 1;
        return (keys[after].value[axis] - keys[before].value[axis]) / (keys[after].frame - keys[before].frame);
    };
    const double h = keys[k + 1].frame - keys[k].frame;
    const double s = (frame - keys[k].frame) / h;
    // Cubic Hermite basis.
    const double h00 = (1 + 2 * s) * (1 - s) * (1 - s), h10 = s * (1 - s) * (1 - s);
    const double h01 = s * s * (3 - 2 * s), h11 = s * s * (s - 1);
    std::array<double, 3> value{};
    for (std::size_t axis = 0; axis < 3; ++axis)
        value[axis] = h00 * keys[k].value[axis] + h10 * h * tangent(k, axis) + h01 * keys[k + 1].value[axis] +
                      h11 * h * tangent(k + 1, axis);
    return value;
}

SceneSpec parse_scene(const std::string& text, const std::string& source) {
    // A UTF-8 byte-order mark, which some editors write, is no part of the text.
    const std::string bom = "\xEF\xBB\xBF";
    const std::vector<Statement> statements =
        split_statements(text.compare(0, bom.size(), bom) == 0 ? text.substr(bom.size()) : text, source);
    if (statements.empty() || statements[0].words[0] != kHeader)
        throw Error(source + ":" + std::to_string(statements.empty() ? 1 : statements[0].line) +
                    ": a scene file starts with '" + kHeader + " 1'");
    statements[0].expect_arguments(1, "1 (the format version)");
    if (statements[0].words[1] != "1") statements[0].fail("unknown scene format version '" + statements[0].words[1] + "'");

    SceneSpec spec;
    spec.source = source;
    std::vector<const Statement*> collision_statements;  // resolved once every object is known
    std::map<std::string, std::size_t> scene_given;      // name and frames stand once
    std::vector<std::map<std::string, std::size_t>> object_given;
    for (std::size_t i = 1; i < statements.size(); ++i) {
        const Statement& s = statements[i];
        const std::string& w = s.words[0];
        if (w == "name" || w == "frames") {
            const auto [at, first] = scene_given.emplace(w, s.line);
            if (!first) s.fail("'" + w + "' is given twice (first at line " + std::to_string(at->second) + ")");
        }
        if (w == "name") {
            s.expect_arguments(1, "NAME");
            spec.name = s.words[1];
        } else if (w == "frames") {
            s.expect_arguments(1, "N");
            spec.frames = s.integer(1, 1, kMaxFrames);
        } else if (w == "object") {
            s.expect_arguments(1, "NAME");
            for (const ObjectSpec& o : spec.objects)
                if (o.name == s.words[1]) s.fail("object '" + s.words[1] + "' is declared twice");
            spec.objects.emplace_back();
            spec.objects.back().name = s.words[1];
            spec.objects.back().line = s.line;
            object_given.emplace_back();
        } else if (w == "collide" || w == "self") {
            s.expect_arguments(w == "collide" ? 2 : 1, w == "collide" ? "OBJECT OBJECT" : "OBJECT");
            collision_statements.push_back(&s);
        } else if (spec.objects.empty()) {
            ObjectSpec scratch;
            std::map<std::string, std::size_t> none;
            if (parse_object_statement(s, scratch, none)) s.fail("'" + w + "' stands before any 'object'");
            s.fail("unknown statement '" + w + "'");
        } else if (!parse_object_statement(s, spec.objects.back(), object_given.back())) {
            s.fail("unknown statement '" + w + "'");
        }
    }
    const Statement& last = statements.back();
    if (spec.frames == 0) last.fail("the scene sets no 'frames'");
    if (spec.objects.empty()) last.fail("the scene has no 'object'");
    for (const ObjectSpec& o : spec.objects) {
        if (o.model.empty() && o.file.empty())
            throw Error(source + ":" + std::to_string(o.line) + ": object '" + o.name + "' has no 'mesh' or 'file'");
        bool keyed = o.wobble_amplitude > 0;
        for (const auto& keys : o.keys) keyed = keyed || !keys.empty();
        if (o.is_static && keyed)
            throw Error(source + ":" + std::to_string(o.line) + ": object '" + o.name +
                        "' is static but has keys or a wobble: a static object never moves");
        if (!o.file.empty() && o.resolution != 0)
            throw Error(source + ":" + std::to_string(o.line) + ": object '" + o.name +
                        "' reads a 'file': 'resolution' applies to the prepared models of 'mesh' only");
        check_deformation_keys(o, spec.frames, source);
    }

    for (const Statement* s : collision_statements) {
        if (s->words[0] == "self") {
            spec.self.push_back(find_object(spec, *s, 1));
            continue;
        }
        std::size_t a = find_object(spec, *s, 1), b = find_object(spec, *s, 2);
        if (a == b) s->fail("'collide' needs two different objects (use 'self' for self-collision)");
        spec.pairs_given = true;
        spec.pairs.emplace_back(std::min(a, b), std::max(a, b));
    }
    return spec;
}

} // namespace kdet::scenes
