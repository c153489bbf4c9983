// libFuzzer harness for one reader, chosen at compile time by KDET_FUZZ_EXTENSION (".msh", ".vtk",
// ".mesh", ".node", ".obj", ".off", ".stl", ".ply" or ".xyz", the query points of `kdet locate`): each input is written to a scratch file of that
// extension and read. kdet::Error is the expected answer to bad input; a crash, a sanitizer report or
// any other exception is a finding. For TetGen the input is the .node file, a NUL byte, the .ele file.

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>

#include <unistd.h>

#ifndef KDET_FUZZ_EXTENSION
#error "define KDET_FUZZ_EXTENSION as the extension of the format to fuzz, e.g. \".msh\""
#endif

namespace {

constexpr std::string_view extension = KDET_FUZZ_EXTENSION;

/// The stem of this process's scratch files: one per process, so parallel fuzzers do not collide.
/// In memory (/dev/shm) where there is one: writing each input to disk would dominate the run time.
const std::string& scratch_stem() {
    static const std::string stem =
        std::string(::access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp") + "/kdet_fuzz_" + std::to_string(::getpid());
    return stem;
}

/// Removes the scratch files when libFuzzer exits at the end of its time.
void remove_scratch_files() {
    for (const char* suffix : {".node", ".ele", KDET_FUZZ_EXTENSION}) std::remove((scratch_stem() + suffix).c_str());
}

void write_file(const std::string& path, std::string_view content) {
    std::ofstream(path, std::ios::binary).write(content.data(), static_cast<std::streamsize>(content.size()));
}

void read_input(std::string_view input) {
    const std::string& stem = scratch_stem();
    if (extension == ".node") {
        const std::size_t split = std::min(input.find('\0'), input.size());
        write_file(stem + ".node", input.substr(0, split));
        write_file(stem + ".ele", input.substr(std::min(split + 1, input.size())));
        kdet::read_tetgen(stem);
        return;
    }
    const std::string path = stem + std::string(extension);
    write_file(path, input);
    if (extension == ".obj" || extension == ".off" || extension == ".stl" || extension == ".ply") {
        kdet::read_surface(path);
    } else if (extension == ".xyz") {
        kdet::read_points(path);
    } else {
        kdet::read_tet_mesh(path);
    }
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    scratch_stem(); // made before the handler is registered, so it is destroyed after the handler runs
    std::atexit(remove_scratch_files);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        read_input(std::string_view(reinterpret_cast<const char*>(data), size));
    } catch (const kdet::Error&) {
        // Rejected with a message: what bad input should get.
    }
    return 0;
}
