/// @file gmsh.cpp
/// @brief The Gmsh MSH reader and writer: versions 2.2 and 4.1, ASCII and binary.
///
/// In version 2.2 binary files the section headers (counts) are text and the records binary; in
/// version 4.1 binary files everything between the section keywords is binary, with 4-byte ints for
/// entity dimensions, entity tags and element types and 8-byte size_t for counts and tags.

#include "io/output_file.hpp"
#include "io/text_reader.hpp"

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

namespace kdet {
namespace {

using namespace io;

constexpr long long gmsh_tet = 4;       // 4-node tetrahedron
constexpr long long gmsh_tet10 = 11;    // 10-node tetrahedron: its first 4 nodes are the corners
constexpr long long gmsh_volume = 3;    // entity dimension of a volume
constexpr std::int32_t gmsh_entity = 1; // the one volume entity the writer puts everything in

/// @brief The number of nodes of each MSH element type, 0 for an unknown type. Binary blocks of
/// elements the reader skips still have to be stepped over, which needs this count.
std::size_t element_node_count(long long type) {
    static constexpr std::size_t counts[] = {0, 2,  3,  4,  4, 8,  6,  5,  3,  6,  9, 10, 27, 18, 14, 1,
                                             8, 20, 15, 13, 9, 10, 12, 15, 15, 21, 4, 5,  6,  20, 35, 56};
    if (type >= 0 && type < static_cast<long long>(std::size(counts))) return counts[type];
    if (type == 92) return 64;
    if (type == 93) return 125;
    return 0;
}

/// @brief The state of one read: the input, the node tag map and the mesh being built.
struct GmshInput {
    NumberStream in;
    bool version_4;
    const ReadOptions& options;
    std::unordered_map<long long, std::uint32_t> node_index; ///< node tag -> 0-based vertex
    TetMesh mesh;

    /// @brief Node tags: size_t in version 4.1, int in version 2.2.
    Scalar size_type() const { return version_4 ? Scalar::uint64 : Scalar::int32; }
};

/// @brief Reads the coordinates of the next node and maps @p tag to it.
void read_node_coordinates(GmshInput& input, long long tag) {
    for (int axis = 0; axis < 3; ++axis) input.mesh.positions.push_back(input.in.coordinate(Scalar::float64));
    const auto index = static_cast<std::uint32_t>(input.mesh.num_vertices() - 1);
    if (!input.node_index.emplace(tag, index).second) input.in.fail("duplicate node tag " + std::to_string(tag));
}

/// @brief Reads the node tags of one element of @p type, which has @p nodes nodes; keeps tetrahedra.
void read_element_nodes(GmshInput& input, long long type, std::size_t nodes) {
    const bool tet = type == gmsh_tet || type == gmsh_tet10;
    const Token start = input.in.last();
    for (std::size_t k = 0; k < nodes; ++k) {
        const long long tag = input.in.integer(input.size_type(), "a node tag");
        if (!tet) continue;
        const auto found = input.node_index.find(tag);
        if (found == input.node_index.end()) input.in.fail("node tag " + std::to_string(tag) + " is not in $Nodes");
        if (k < 4) input.mesh.tets.push_back(found->second);
    }
    if (tet) check_last_tet(input.in.file(), start, input.mesh, 0, input.options);
}

std::size_t known_node_count(GmshInput& input, long long type) {
    const std::size_t nodes = element_node_count(type);
    if (nodes == 0) input.in.fail("unknown element type " + std::to_string(type));
    return nodes;
}

/// @brief Reads a version 2.2 section count into @p count and returns its token: the count is text
/// even in binary files, where the records follow its line break.
Token read_v2_count(GmshInput& input, const char* what, std::size_t& count) {
    TextFile& file = input.in.file();
    const Token token = file.expect_token(what);
    count = read_count(file, token, what);
    if (input.in.binary()) file.skip_line_end();
    return token;
}

void read_nodes_v2(GmshInput& input) {
    TextFile& file = input.in.file();
    std::size_t count = 0;
    const Token count_token = read_v2_count(input, "a node count", count);
    check_vertex_count(file, count_token, count);
    constexpr std::size_t record_bytes = 4 + 3 * 8; // int tag, 3 doubles
    input.in.expect_records(count, record_bytes, "nodes");
    input.mesh.positions.reserve(3 * input.in.reservable(count, 4, Scalar::float64));
    for (std::size_t i = 0; i < count; ++i) read_node_coordinates(input, input.in.integer(Scalar::int32, "a node tag"));
}

void read_nodes_v4(GmshInput& input) {
    NumberStream& in = input.in;
    if (in.binary()) in.file().skip_line_end();
    const std::size_t blocks = in.count(Scalar::uint64, "an entity block count");
    const std::size_t count = in.count(Scalar::uint64, "a node count");
    check_vertex_count(in.file(), in.last(), count);
    in.integer(Scalar::uint64, "the smallest node tag");
    in.integer(Scalar::uint64, "the largest node tag");
    in.expect_records(count, 8 + 3 * 8, "nodes");
    input.mesh.positions.reserve(3 * in.reservable(count, 4, Scalar::float64));
    std::vector<long long> tags;
    std::size_t read = 0;
    for (std::size_t block = 0; block < blocks; ++block) {
        const long long dimension = in.integer(Scalar::int32, "an entity dimension");
        if (dimension < 0 || dimension > 3)
            in.fail("entity dimension must be 0 to 3, found " + std::to_string(dimension));
        in.integer(Scalar::int32, "an entity tag");
        const long long parametric = in.integer(Scalar::int32, "a parametric flag");
        if (parametric != 0 && parametric != 1)
            in.fail("parametric flag must be 0 or 1, found " + std::to_string(parametric));
        const std::size_t in_block = in.count(Scalar::uint64, "a node count");
        if (in_block > count - read)
            in.fail("node blocks hold more than the " + std::to_string(count) + " nodes announced");
        // Nodes on curves and surfaces may carry their parametric coordinates after x, y, z.
        const std::size_t parameters = parametric == 1 ? static_cast<std::size_t>(dimension) : 0;
        in.expect_records(in_block, 8 + (3 + parameters) * 8, "nodes");
        tags.clear();
        tags.reserve(in.reservable(in_block, 1, Scalar::uint64));
        for (std::size_t k = 0; k < in_block; ++k) tags.push_back(in.integer(Scalar::uint64, "a node tag"));
        for (const long long tag : tags) {
            read_node_coordinates(input, tag);
            for (std::size_t p = 0; p < parameters; ++p) in.real(Scalar::float64, "a parametric coordinate");
        }
        read += in_block;
    }
    if (read != count) in.fail("expected " + std::to_string(count) + " nodes, found " + std::to_string(read));
}

void read_elements_v2(GmshInput& input) {
    NumberStream& in = input.in;
    std::size_t count = 0;
    read_v2_count(input, "an element count", count);
    if (!in.binary()) {
        for (std::size_t i = 0; i < count; ++i) {
            in.integer(Scalar::int32, "an element number");
            const long long type = in.integer(Scalar::int32, "an element type");
            const std::size_t nodes = known_node_count(input, type);
            const std::size_t tags = in.count(Scalar::int32, "a tag count");
            for (std::size_t k = 0; k < tags; ++k) in.integer(Scalar::int32, "an element tag");
            read_element_nodes(input, type, nodes);
        }
        return;
    }
    // Binary: blocks of elements of one type, each led by (type, number of elements, number of tags).
    for (std::size_t done = 0; done < count;) {
        const long long type = in.integer(Scalar::int32, "an element type");
        const std::size_t nodes = known_node_count(input, type);
        const std::size_t in_block = in.count(Scalar::int32, "an element count");
        if (in_block == 0 || in_block > count - done) {
            in.fail("element block of " + std::to_string(in_block) + " elements where " + std::to_string(count - done) +
                    " remain to be read");
        }
        const std::size_t tags = in.count(Scalar::int32, "a tag count");
        in.expect_records(in_block, 4 * (1 + tags + nodes), "elements");
        for (std::size_t e = 0; e < in_block; ++e) {
            in.integer(Scalar::int32, "an element number");
            for (std::size_t k = 0; k < tags; ++k) in.integer(Scalar::int32, "an element tag");
            read_element_nodes(input, type, nodes);
        }
        done += in_block;
    }
}

void read_elements_v4(GmshInput& input) {
    NumberStream& in = input.in;
    if (in.binary()) in.file().skip_line_end();
    const std::size_t blocks = in.count(Scalar::uint64, "an entity block count");
    const std::size_t count = in.count(Scalar::uint64, "an element count");
    in.integer(Scalar::uint64, "the smallest element tag");
    in.integer(Scalar::uint64, "the largest element tag");
    std::size_t read = 0;
    for (std::size_t block = 0; block < blocks; ++block) {
        in.integer(Scalar::int32, "an entity dimension");
        in.integer(Scalar::int32, "an entity tag");
        const long long type = in.integer(Scalar::int32, "an element type");
        const std::size_t nodes = known_node_count(input, type);
        const std::size_t in_block = in.count(Scalar::uint64, "an element count");
        if (in_block > count - read)
            in.fail("element blocks hold more than the " + std::to_string(count) + " elements announced");
        in.expect_records(in_block, 8 * (1 + nodes), "elements");
        for (std::size_t e = 0; e < in_block; ++e) {
            in.integer(Scalar::uint64, "an element tag");
            read_element_nodes(input, type, nodes);
        }
        read += in_block;
    }
    if (read != count) in.fail("expected " + std::to_string(count) + " elements, found " + std::to_string(read));
}

/// @brief Reads $MeshFormat up to its end; returns whether the file is binary and sets @p version_4.
bool read_mesh_format(TextFile& file, bool& version_4) {
    Token first;
    if (!file.next_token(first)) file.fail(1, "empty file");
    if (first.text != "$MeshFormat") file.fail(first, "expected $MeshFormat, found " + excerpt(first.text));
    const Token version = file.expect_token("a format version");
    if (version.text != "2.2" && version.text != "4.1")
        file.fail(version, "unsupported MSH version " + excerpt(version.text) + "; supported: 2.2 and 4.1");
    version_4 = version.text == "4.1";
    const Token type = file.expect_token("a file type");
    const long long file_type = read_integer(file, type, "a file type");
    if (file_type != 0 && file_type != 1)
        file.fail(type, "file type must be 0 (ASCII) or 1 (binary), found " + excerpt(type.text));
    const Token size = file.expect_token("a data size");
    const long long data_size = read_integer(file, size, "a data size");
    const bool binary = file_type == 1;
    if (binary && data_size != 8) file.fail(size, "data size must be 8 in binary files, found " + excerpt(size.text));
    if (binary) {
        file.skip_line_end();
        file.use_byte_offsets();
        const std::size_t at = file.offset();
        const unsigned char* marker = file.take_bytes(4, "the endianness marker");
        const std::int32_t one = decode<std::int32_t>(marker, Endian::little);
        if (one != 1 && decode<std::int32_t>(marker, Endian::big) == 1) {
            file.fail_at_byte(at, "endianness marker 1 is stored big-endian: the file was written on a big-endian "
                                  "machine; only little-endian binary files are read");
        }
        if (one != 1) file.fail_at_byte(at, "endianness marker reads " + std::to_string(one) + ", expected 1");
    }
    file.expect_keyword("$EndMeshFormat");
    return binary;
}

// ---------------------------------------------------------------------------------------------
// Writer

void write_gmsh_v2(OutputFile& out, RecordWriter& records, const TetMesh& mesh, bool binary) {
    out.text("$Nodes\n");
    out.number(mesh.num_vertices());
    out.text("\n");
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
        records.field(static_cast<std::int32_t>(v + 1));
        for (std::size_t axis = 0; axis < 3; ++axis) records.field(mesh.positions[3 * v + axis]);
        records.end_record();
    }
    records.end_section("$EndNodes\n$Elements\n");
    out.number(mesh.num_tets());
    out.text("\n");
    // Two tags, physical group 1 and elementary entity 1, as Gmsh itself writes them.
    constexpr std::int32_t tag_count = 2, physical = 1;
    if (binary) {
        records.field(static_cast<std::int32_t>(gmsh_tet));
        records.field(static_cast<std::int32_t>(mesh.num_tets()));
        records.field(tag_count);
    }
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        records.field(static_cast<std::int32_t>(t + 1));
        if (!binary) {
            records.field(static_cast<std::int32_t>(gmsh_tet));
            records.field(tag_count);
        }
        records.field(physical);
        records.field(gmsh_entity);
        for (std::size_t k = 0; k < 4; ++k) records.field(static_cast<std::int32_t>(mesh.tets[4 * t + k] + 1));
        records.end_record();
    }
    records.end_section("$EndElements\n");
}

/// @brief Writes the header of a version 4.1 $Nodes or $Elements section that holds one block of
/// @p count entries tagged 1..count, and that block's header: the volume entity, @p block_value (the
/// parametric flag of nodes, the type of elements) and the count.
void write_v4_single_block(RecordWriter& records, std::uint64_t count, std::int32_t block_value) {
    for (const std::uint64_t value : {std::uint64_t{1}, count, std::uint64_t{1}, count}) records.field(value);
    records.end_record();
    records.field(static_cast<std::int32_t>(gmsh_volume));
    records.field(gmsh_entity);
    records.field(block_value);
    records.field(count);
    records.end_record();
}

void write_gmsh_v4(RecordWriter& records, OutputFile& out, const TetMesh& mesh) {
    const std::uint64_t vertices = mesh.num_vertices(), tets = mesh.num_tets();
    // The volume entity, with the mesh's bounding box.
    double box[6] = {mesh.positions[0], mesh.positions[1], mesh.positions[2],
                     mesh.positions[0], mesh.positions[1], mesh.positions[2]};
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        box[i % 3] = std::min(box[i % 3], mesh.positions[i]);
        box[3 + i % 3] = std::max(box[3 + i % 3], mesh.positions[i]);
    }
    out.text("$Entities\n");
    for (const std::uint64_t count : {0, 0, 0, 1}) records.field(count); // points, curves, surfaces, volumes
    records.end_record();
    records.field(gmsh_entity);
    for (const double bound : box) records.field(bound);
    records.field(std::uint64_t{0}); // physical tags
    records.field(std::uint64_t{0}); // bounding surfaces
    records.end_record();
    records.end_section("$EndEntities\n$Nodes\n");

    write_v4_single_block(records, vertices, 0); // no parametric coordinates
    for (std::uint64_t v = 0; v < vertices; ++v) {
        records.field(v + 1);
        records.end_record();
    }
    for (std::size_t v = 0; v < vertices; ++v) {
        for (std::size_t axis = 0; axis < 3; ++axis) records.field(mesh.positions[3 * v + axis]);
        records.end_record();
    }
    records.end_section("$EndNodes\n$Elements\n");

    write_v4_single_block(records, tets, static_cast<std::int32_t>(gmsh_tet));
    for (std::uint64_t t = 0; t < tets; ++t) {
        records.field(t + 1);
        for (std::size_t k = 0; k < 4; ++k) records.field(std::uint64_t{mesh.tets[4 * t + k]} + 1);
        records.end_record();
    }
    records.end_section("$EndElements\n");
}

} // namespace

TetMesh read_gmsh(const std::string& path, const ReadOptions& options) {
    TextFile file(path, '\0'); // MSH has no comments
    bool version_4 = false;
    const bool binary = read_mesh_format(file, version_4);
    GmshInput input{NumberStream(file, binary, Endian::little), version_4, options, {}, {}};
    bool have_nodes = false, have_elements = false;
    Token section;
    while (file.next_token(section)) {
        if (section.text == "$Nodes") {
            if (have_nodes) file.fail(section, "second $Nodes section");
            version_4 ? read_nodes_v4(input) : read_nodes_v2(input);
            file.expect_keyword("$EndNodes");
            have_nodes = true;
        } else if (section.text == "$Elements") {
            // Element nodes are mapped as they are read, which needs the nodes first (Gmsh writes them so).
            if (!have_nodes) file.fail(section, "$Elements before $Nodes");
            if (have_elements) file.fail(section, "second $Elements section");
            version_4 ? read_elements_v4(input) : read_elements_v2(input);
            file.expect_keyword("$EndElements");
            have_elements = true;
        } else if (section.text.size() > 1 && section.text[0] == '$' && section.text.substr(0, 4) != "$End") {
            // Other sections ($Entities, $PhysicalNames, $ElementData, ...) end at their $End line.
            const std::string end = "$End" + std::string(section.text.substr(1));
            if (!file.skip_past_line(end)) file.fail(section, "section " + excerpt(section.text) + " has no " + end);
        } else {
            file.fail(section, "expected a section such as $Nodes or $Elements, found " + excerpt(section.text));
        }
    }
    if (!have_elements) file.fail_here("no $Elements section");
    if (input.mesh.tets.empty()) file.fail_here("no tetrahedra (no element of type 4 or 11)");
    return std::move(input.mesh);
}

void write_gmsh(const TetMesh& mesh, const std::string& path, const GmshFormat& format) {
    check_writable(mesh, path);
    const bool version_4 = format.version == GmshVersion::v4_1;
    constexpr std::size_t int_tags = std::numeric_limits<std::int32_t>::max();
    if (!version_4 && (mesh.num_vertices() >= int_tags || mesh.num_tets() >= int_tags))
        throw Error(path + ": too many vertices or tetrahedra for MSH 2.2, whose tags are 32-bit ints; use 4.1");
    OutputFile out(path);
    out.text(version_4 ? "$MeshFormat\n4.1 " : "$MeshFormat\n2.2 ");
    out.text(format.binary ? "1 8\n" : "0 8\n");
    if (format.binary) {
        out.binary(std::int32_t{1}, Endian::little); // the endianness marker
        out.text("\n");
    }
    out.text("$EndMeshFormat\n");
    RecordWriter records(out, format.binary, Endian::little);
    if (version_4) {
        write_gmsh_v4(records, out, mesh);
    } else {
        write_gmsh_v2(out, records, mesh, format.binary);
    }
    out.close();
}

} // namespace kdet
