// libFuzzer harness for the scene-file reader (scenes::parse_scene, docs/scenes.md): every input gets
// a spec within the format's limits or a one-line "file:line: " error (scene_checks.hpp); anything
// else, a crash or a sanitizer report is a finding.

#include "scene_checks.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string problem = kdet::test::scene_parse_problem(std::string(reinterpret_cast<const char*>(data), size));
    if (!problem.empty()) {
        std::fprintf(stderr, "scene file reader: %s\n", problem.c_str());
        std::abort();
    }
    return 0;
}
