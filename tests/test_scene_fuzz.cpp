// The scene-file reader's fuzz seeds replayed in the test command, where the libFuzzer run
// (tests/fuzz, clang only) may be skipped: the seeds, and systematic mutations of the one that uses every
// statement (each line dropped, each word replaced by a value parsers trip over), get a spec within the
// format's limits or a one-line "file:line: " error (fuzz/scene_checks.hpp, the fuzzer's own oracle).

#include "fuzz/scene_checks.hpp"

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

namespace kdet::test {
namespace {

std::vector<std::string> seeds() {
    std::vector<std::string> texts = {every_statement_scene};
    for (const auto& [name, text] : scenes::builtin_scene_files()) texts.push_back(text);
    return texts;
}

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

std::string joined(const std::vector<std::string>& lines) {
    std::string text;
    for (const std::string& line : lines) text += line + "\n";
    return text;
}

TEST(SceneFileFuzz, SeedsParse) {
    for (const std::string& text : seeds()) {
        EXPECT_EQ(scene_parse_problem(text), "") << text;
        EXPECT_NO_THROW(scenes::parse_scene(text, "seed.scene")) << text;
    }
}

TEST(SceneFileFuzz, MutatedSeedsGetASpecOrAOneLineError) {
    const char* const replacements[] = {"",     "-1",  "0",   "1e999", "nan",  "inf",        "2147483648", "-0",
                                        "0x10", "1.5", "x",   "y",     "w",    "object",     "static",     "key",
                                        "move", "#",   "\x01", "\xff",  "9e-324", "1000001", "a b"};
    std::size_t errors = 0, specs = 0;
    const std::string seed = every_statement_scene;
    const std::vector<std::string> lines = lines_of(seed);
    for (std::size_t l = 0; l < lines.size(); ++l) {
        std::vector<std::string> dropped = lines;
        dropped.erase(dropped.begin() + static_cast<std::ptrdiff_t>(l));
        EXPECT_EQ(scene_parse_problem(joined(dropped)), "") << "line " << l + 1 << " dropped from\n" << seed;
        // Each word of the line in turn replaced.
        std::istringstream in(lines[l]);
        std::vector<std::string> words;
        for (std::string w; in >> w;) words.push_back(w);
        for (std::size_t w = 0; w < words.size(); ++w)
            for (const char* replacement : replacements) {
                std::vector<std::string> changed = lines;
                std::string line;
                for (std::size_t k = 0; k < words.size(); ++k) line += (k ? " " : "") + (k == w ? replacement : words[k]);
                changed[l] = line;
                const std::string text = joined(changed);
                EXPECT_EQ(scene_parse_problem(text), "") << text;
                try {
                    scenes::parse_scene(text, "s.scene");
                    ++specs;
                } catch (const Error&) {
                    ++errors;
                }
            }
    }
    // Both answers occur, so the oracle's two branches are exercised.
    EXPECT_GT(errors, 0u);
    EXPECT_GT(specs, 0u);
}

} // namespace
} // namespace kdet::test
