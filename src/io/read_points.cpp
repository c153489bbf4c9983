#include "io/text_reader.hpp"

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace kdet {

namespace {

bool ends_with(const std::string& text, const std::string& suffix) {
    return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// A mesh file by its extension (as read_tet_mesh reads them), or a TetGen stem with its .node beside it.
bool is_mesh_file(const std::string& path) {
    const std::string extension = io::lowercase_extension(path);
    for (const char* known : {".mesh", ".msh", ".vtk"})
        if (extension == known) return true;
    if (ends_with(path, ".node") || ends_with(path, ".ele")) return true;
    std::error_code ignored;
    return !std::filesystem::exists(path, ignored) && std::filesystem::is_regular_file(path + ".node", ignored);
}

} // namespace

std::vector<double> read_points(const std::string& path) {
    // Only the vertices are read as points: a degenerate tet is no mistake of theirs.
    ReadOptions vertices_only;
    vertices_only.allow_degenerate = true;
    if (is_mesh_file(path)) return read_tet_mesh(path, vertices_only).positions;
    io::TextFile file(path);
    std::vector<double> xyz;
    std::vector<io::Token> tokens;
    while (file.next_line(tokens)) {
        if (tokens.size() != 3)
            file.fail(tokens.front(), "expected 3 coordinates x y z, found " + std::to_string(tokens.size()) + " values");
        for (const io::Token& token : tokens) xyz.push_back(io::read_coordinate(file, token));
    }
    return xyz;
}

} // namespace kdet
