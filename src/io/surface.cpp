/// @file surface.cpp
/// @brief The triangle surface readers: OBJ, OFF, STL (ASCII and binary) and PLY (ASCII and binary).

#include "io/text_reader.hpp"

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace kdet {
namespace {

using namespace io;

/// @brief Appends a polygon, fan-triangulated from its first corner; fails at @p where when it has
/// fewer than 3 corners.
void add_polygon(const TextFile& file, const Token& where, const std::vector<std::uint32_t>& corners,
                 TriangleMesh& mesh) {
    if (corners.size() < 3)
        file.fail(where, "face has " + std::to_string(corners.size()) + " vertices, at least 3 needed");
    for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
        mesh.triangles.insert(mesh.triangles.end(), {corners[0], corners[k], corners[k + 1]});
    }
}

/// @brief Fails when a vertex is added to @p mesh past what 32-bit indices can number.
void check_room_for_vertex(const TextFile& file, const Token& where, const TriangleMesh& mesh) {
    if (mesh.num_vertices() >= std::numeric_limits<std::uint32_t>::max())
        file.fail(where, "too many vertices for 32-bit indices");
}

void check_has_triangles(TextFile& file, const TriangleMesh& mesh) {
    if (mesh.triangles.empty()) file.fail_here("no triangles");
}

// ---------------------------------------------------------------------------------------------
// OBJ

/// @brief Reads the vertex of an OBJ face corner "v", "v/t", "v//n" or "v/t/n"; negative numbers
/// count back from the last vertex defined so far.
std::uint32_t read_obj_corner(const TextFile& file, const Token& token, std::size_t vertex_count) {
    const Token vertex{token.text.substr(0, token.text.find('/')), token.line, token.offset};
    const long long index = read_integer(file, vertex, "a vertex index");
    if (index < 0 && static_cast<unsigned long long>(-(index + 1)) < vertex_count)
        return static_cast<std::uint32_t>(static_cast<long long>(vertex_count) + index);
    if (index < 0) {
        file.fail(token, "vertex index " + std::to_string(index) + " reaches before the first vertex (" +
                             std::to_string(vertex_count) + " defined so far)");
    }
    if (index == 0 || static_cast<unsigned long long>(index) > vertex_count)
        file.fail(token, index_out_of_range(index, 1, vertex_count) + " (vertices defined so far)");
    return static_cast<std::uint32_t>(index - 1);
}

TriangleMesh read_obj(const std::string& path) {
    TextFile file(path);
    TriangleMesh mesh;
    std::vector<Token> line;
    std::vector<std::uint32_t> corners;
    while (file.next_line(line)) {
        const std::string_view keyword = line.front().text;
        if (keyword == "v") {
            // "v x y z", optionally followed by w or by a colour.
            if (line.size() < 4)
                file.fail(line.front(),
                          "vertex needs x, y and z, found " + std::to_string(line.size() - 1) + " values");
            check_room_for_vertex(file, line.front(), mesh);
            for (std::size_t k = 1; k < 4; ++k) mesh.positions.push_back(read_coordinate(file, line[k]));
            for (std::size_t k = 4; k < line.size(); ++k) check_number(file, line[k]);
        } else if (keyword == "f") {
            corners.clear();
            for (std::size_t k = 1; k < line.size(); ++k)
                corners.push_back(read_obj_corner(file, line[k], mesh.num_vertices()));
            add_polygon(file, line.front(), corners, mesh);
        }
        // Normals, texture coordinates, groups, materials, lines and points do not shape the surface.
    }
    check_has_triangles(file, mesh);
    return mesh;
}

// ---------------------------------------------------------------------------------------------
// OFF

TriangleMesh read_off(const std::string& path) {
    TextFile file(path);
    Token header;
    if (!file.next_token(header)) file.fail(1, "empty file");
    if (header.text != "OFF") file.fail(header, "expected OFF, found " + excerpt(header.text));
    const std::size_t vertex_count = read_vertex_count(file, file.expect_token("a vertex count"), "a vertex count");
    const std::size_t face_count = read_count(file, file.expect_token("a face count"), "a face count");
    read_count(file, file.expect_token("an edge count"), "an edge count");

    TriangleMesh mesh;
    mesh.positions.reserve(3 * reservable(vertex_count, 3, file));
    std::vector<Token> line;
    for (std::size_t v = 0; v < vertex_count; ++v) {
        if (!file.next_line(line)) fail_truncated(file, file.last_token_line(), vertex_count, v, "vertices");
        if (line.size() < 3)
            file.fail(line.front(), "vertex needs x, y and z, found " + std::to_string(line.size()) + " values");
        for (std::size_t k = 0; k < 3; ++k) mesh.positions.push_back(read_coordinate(file, line[k]));
    }
    mesh.triangles.reserve(3 * reservable(face_count, 4, file));
    std::vector<std::uint32_t> corners;
    for (std::size_t f = 0; f < face_count; ++f) {
        if (!file.next_line(line)) fail_truncated(file, file.last_token_line(), face_count, f, "faces");
        const std::size_t size = read_count(file, line.front(), "a face size");
        // A colour may follow the vertex indices.
        if (line.size() < 1 + size) {
            file.fail(line.front(), "face of " + std::to_string(size) + " vertices lists " +
                                        std::to_string(line.size() - 1) + " values");
        }
        corners.clear();
        for (std::size_t k = 1; k <= size; ++k) corners.push_back(read_vertex_index(file, line[k], 0, vertex_count));
        add_polygon(file, line.front(), corners, mesh);
    }
    reject_trailing_data(file, face_count, "faces");
    check_has_triangles(file, mesh);
    return mesh;
}

// ---------------------------------------------------------------------------------------------
// STL

/// @brief Builds a triangle mesh from triangle soup corners, one vertex per distinct position.
class VertexMerger {
public:
    explicit VertexMerger(TriangleMesh& mesh) : mesh_(mesh) {}

    void add_corner(const TextFile& file, const Token& where, const std::array<double, 3>& position) {
        const auto [found, added] = index_.emplace(position, static_cast<std::uint32_t>(mesh_.num_vertices()));
        if (added) {
            check_room_for_vertex(file, where, mesh_);
            mesh_.positions.insert(mesh_.positions.end(), position.begin(), position.end());
        }
        mesh_.triangles.push_back(found->second);
    }

private:
    TriangleMesh& mesh_;
    std::map<std::array<double, 3>, std::uint32_t> index_; // -0 and +0 compare equal, so they merge
};

constexpr std::size_t stl_header_bytes = 80;
constexpr std::size_t stl_triangle_bytes = 50; // normal, 3 corners (float32 each), 2 attribute bytes

TriangleMesh read_binary_stl(TextFile& file) {
    NumberStream in(file, true, Endian::little);
    file.take_bytes(stl_header_bytes, "the 80-byte header");
    const std::size_t count = in.count(Scalar::uint32, "a triangle count");
    in.expect_records(count, stl_triangle_bytes, "triangles");
    TriangleMesh mesh;
    mesh.triangles.reserve(3 * count);
    VertexMerger merger(mesh);
    for (std::size_t t = 0; t < count; ++t) {
        for (int k = 0; k < 3; ++k) in.real(Scalar::float32, "a normal");
        for (int corner = 0; corner < 3; ++corner) {
            std::array<double, 3> position;
            for (double& value : position) value = in.coordinate(Scalar::float32);
            merger.add_corner(file, in.last(), position);
        }
        in.integer(Scalar::uint16, "an attribute byte count");
    }
    if (file.remaining_bytes() != 0) {
        file.fail_at_byte(file.offset(), std::to_string(file.remaining_bytes()) + " bytes after the " +
                                             std::to_string(count) + " triangles the header announces");
    }
    check_has_triangles(file, mesh);
    return mesh;
}

TriangleMesh read_ascii_stl(TextFile& file) {
    TriangleMesh mesh;
    VertexMerger merger(mesh);
    Token rest;
    file.expect_keyword("solid");
    file.next_raw_line(rest); // the solid's name
    for (;;) {
        const Token token = file.expect_token("facet or endsolid");
        if (token.text == "endsolid") {
            file.next_raw_line(rest);
            if (file.at_end()) break;
            file.expect_keyword("solid"); // a file may hold several solids
            file.next_raw_line(rest);
            continue;
        }
        if (token.text != "facet") file.fail(token, "expected facet or endsolid, found " + excerpt(token.text));
        file.expect_keyword("normal");
        for (int k = 0; k < 3; ++k) check_number(file, file.expect_token("a normal"));
        file.expect_keyword("outer");
        file.expect_keyword("loop");
        for (int corner = 0; corner < 3; ++corner) {
            file.expect_keyword("vertex");
            std::array<double, 3> position;
            Token where;
            for (double& value : position) {
                where = file.expect_token("a coordinate");
                value = read_coordinate(file, where);
            }
            merger.add_corner(file, where, position);
        }
        file.expect_keyword("endloop");
        file.expect_keyword("endfacet");
    }
    check_has_triangles(file, mesh);
    return mesh;
}

/// @brief Binary when the size matches the triangle count at byte 80 (a binary header may also
/// start with "solid"), else ASCII when the file starts with "solid" and holds no NUL byte (binary
/// counts, zeros and attribute fields nearly always hold one), else binary.
TriangleMesh read_stl(const std::string& path) {
    TextFile file(path, '\0');
    const std::string_view content = file.content();
    if (content.size() >= stl_header_bytes + 4) {
        const auto* count_bytes = reinterpret_cast<const unsigned char*>(content.data() + stl_header_bytes);
        const std::uint64_t count = decode<std::uint32_t>(count_bytes, Endian::little);
        if (stl_header_bytes + 4 + stl_triangle_bytes * count == content.size()) return read_binary_stl(file);
    }
    const std::size_t start = content.find_first_not_of(" \t\r\n");
    const bool text = content.find('\0') == std::string_view::npos;
    if (text && start != std::string_view::npos && content.substr(start, 5) == "solid") return read_ascii_stl(file);
    return read_binary_stl(file);
}

// ---------------------------------------------------------------------------------------------
// PLY

struct PlyProperty {
    std::string name;
    Scalar type = Scalar::float32; ///< the value type, or the item type of a list
    bool list = false;
    Scalar count_type = Scalar::uint8; ///< the type of a list's length
};

struct PlyElement {
    std::string name;
    std::size_t count = 0;
    Token where; ///< the "element" line
    std::vector<PlyProperty> properties;
};

Scalar read_ply_type(const TextFile& file, const Token& token) {
    static const std::pair<std::string_view, Scalar> names[] = {
        {"char", Scalar::int8},       {"int8", Scalar::int8},       {"uchar", Scalar::uint8},
        {"uint8", Scalar::uint8},     {"short", Scalar::int16},     {"int16", Scalar::int16},
        {"ushort", Scalar::uint16},   {"uint16", Scalar::uint16},   {"int", Scalar::int32},
        {"int32", Scalar::int32},     {"uint", Scalar::uint32},     {"uint32", Scalar::uint32},
        {"float", Scalar::float32},   {"float32", Scalar::float32}, {"double", Scalar::float64},
        {"float64", Scalar::float64},
    };
    for (const auto& [name, type] : names) {
        if (token.text == name) return type;
    }
    file.fail(token, "unknown property type " + excerpt(token.text));
}

/// @brief Reads the header up to end_header; returns the elements and sets the encoding.
std::vector<PlyElement> read_ply_header(TextFile& file, bool& binary, Endian& order) {
    std::vector<Token> line;
    if (!file.next_line(line)) file.fail(1, "empty file");
    if (line.size() != 1 || line.front().text != "ply")
        file.fail(line.front(), "expected ply, found " + excerpt(line.front().text));
    if (!file.next_line(line) || line.front().text != "format" || line.size() != 3)
        file.fail_here("expected format ascii|binary_little_endian|binary_big_endian 1.0");
    const std::string_view format = line[1].text;
    if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
        file.fail(line[1], "unknown format " + excerpt(format));
    binary = format != "ascii";
    order = format == "binary_big_endian" ? Endian::big : Endian::little;

    std::vector<PlyElement> elements;
    while (file.next_line(line)) {
        const std::string_view keyword = line.front().text;
        if (keyword == "end_header") return elements;
        if (keyword == "comment" || keyword == "obj_info") continue;
        if (keyword == "element") {
            if (line.size() != 3) file.fail(line.front(), "expected element <name> <count>");
            elements.push_back(
                {std::string(line[1].text), read_count(file, line[2], "an element count"), line.front(), {}});
        } else if (keyword == "property") {
            if (elements.empty()) file.fail(line.front(), "property before any element");
            PlyProperty property;
            if (line.size() == 5 && line[1].text == "list") {
                property.list = true;
                property.count_type = read_ply_type(file, line[2]);
                if (!is_integer(property.count_type)) file.fail(line[2], "list length type must be an integer type");
                property.type = read_ply_type(file, line[3]);
                property.name = line[4].text;
            } else if (line.size() == 3) {
                property.type = read_ply_type(file, line[1]);
                property.name = line[2].text;
            } else {
                file.fail(line.front(), "expected property <type> <name> or property list <type> <type> <name>");
            }
            elements.back().properties.push_back(property);
        } else {
            file.fail(line.front(), "unknown header keyword " + excerpt(keyword));
        }
    }
    file.fail_here("file ends in the header (no end_header)");
}

/// @brief The position of property @p name in @p element, or fails at the element line.
std::size_t find_ply_property(const TextFile& file, const PlyElement& element, std::string_view name, bool list) {
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
        if (element.properties[p].name == name && element.properties[p].list == list) return p;
    }
    file.fail(element.where,
              "element " + element.name + " has no " + (list ? "list " : "") + "property " + std::string(name));
}

/// @brief The fewest bytes one record of @p element takes in a binary file (lists empty).
std::size_t ply_record_bytes(const PlyElement& element) {
    std::size_t bytes = 0;
    for (const PlyProperty& property : element.properties)
        bytes += scalar_size(property.list ? property.count_type : property.type);
    return bytes;
}

TriangleMesh read_ply(const std::string& path) {
    TextFile file(path, '\0');
    bool binary = false;
    Endian order = Endian::little;
    const std::vector<PlyElement> elements = read_ply_header(file, binary, order);
    if (binary) file.skip_line_end();
    NumberStream in(file, binary, order);

    TriangleMesh mesh;
    bool have_vertices = false;
    std::vector<std::uint32_t> corners;
    for (const PlyElement& element : elements) {
        const bool vertices = element.name == "vertex", faces = element.name == "face";
        std::size_t xyz[3] = {0, 0, 0}, indices = 0;
        if (vertices) {
            if (have_vertices) file.fail(element.where, "second vertex element");
            check_vertex_count(file, element.where, element.count);
            static constexpr std::string_view axes[] = {"x", "y", "z"};
            for (int axis = 0; axis < 3; ++axis) xyz[axis] = find_ply_property(file, element, axes[axis], false);
        }
        if (faces) {
            if (!have_vertices) file.fail(element.where, "face element before the vertex element");
            const bool short_name = std::any_of(element.properties.begin(), element.properties.end(),
                                                [](const PlyProperty& p) { return p.name == "vertex_index"; });
            indices = find_ply_property(file, element, short_name ? "vertex_index" : "vertex_indices", true);
        }
        // Records without properties hold nothing: do not step through an absurd count of them.
        if (element.properties.empty()) continue;
        in.expect_records(element.count, ply_record_bytes(element), element.name + " records");
        if (vertices)
            mesh.positions.reserve(3 * in.reservable(element.count, element.properties.size(), Scalar::float32));
        for (std::size_t r = 0; r < element.count; ++r) {
            double position[3] = {0, 0, 0};
            for (std::size_t p = 0; p < element.properties.size(); ++p) {
                const PlyProperty& property = element.properties[p];
                if (!property.list) {
                    const auto axis = static_cast<std::size_t>(std::find(xyz, xyz + 3, p) - xyz);
                    if (vertices && axis < 3) {
                        position[axis] = in.coordinate(property.type);
                    } else {
                        in.real(property.type, "a value of property " + property.name);
                    }
                    continue;
                }
                const std::size_t length = in.count(property.count_type, "a list length");
                const Token start = in.last();
                corners.clear();
                for (std::size_t k = 0; k < length; ++k) {
                    if (faces && p == indices) {
                        corners.push_back(in.vertex_index(property.type, 0, mesh.num_vertices()));
                    } else {
                        in.real(property.type, "a list value of property " + property.name);
                    }
                }
                if (faces && p == indices) add_polygon(file, start, corners, mesh);
            }
            if (vertices) mesh.positions.insert(mesh.positions.end(), position, position + 3);
        }
        have_vertices = have_vertices || vertices;
    }
    if (binary && file.remaining_bytes() != 0) {
        file.fail_at_byte(file.offset(), std::to_string(file.remaining_bytes()) + " bytes after the last element");
    }
    if (!binary)
        reject_trailing_data(file, elements.empty() ? 0 : elements.back().count, "records of the last element");
    check_has_triangles(file, mesh);
    return mesh;
}

} // namespace

TriangleMesh read_surface(const std::string& path) {
    const std::string extension = lowercase_extension(path);
    if (extension == ".obj") return read_obj(path);
    if (extension == ".off") return read_off(path);
    if (extension == ".stl") return read_stl(path);
    if (extension == ".ply") return read_ply(path);
    throw Error(path + ": unsupported surface format " + excerpt(extension) + "; supported: .obj, .off, .stl, .ply");
}

} // namespace kdet
