/// @file read_mesh.cpp
/// @brief The TetGen and MEDIT readers and the checks they share with validate_tet_mesh.

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace kdet {
namespace {

// ---------------------------------------------------------------------------------------------
// Tokens

/// @brief A whitespace-separated word of a file and the line (1-based) it stands on.
struct Token {
    std::string_view text;
    std::size_t line = 0;
};

/// @brief Quotes file content for an error message: shortened, with unprintable bytes replaced, so
/// the message stays one readable line whatever the file holds.
std::string excerpt(std::string_view text) {
    constexpr std::size_t max_shown = 40;
    std::string out = "'";
    for (std::size_t i = 0; i < text.size() && i < max_shown; ++i) {
        const char c = text[i];
        out += (c >= ' ' && c <= '~') ? c : '?';
    }
    if (text.size() > max_shown) out += "...";
    return out + "'";
}

std::string load_file(const std::string& path) {
    std::error_code ignored;
    // An ifstream opens a directory on Linux and then reads nothing, which would read as "empty file".
    if (std::filesystem::is_directory(path, ignored)) throw Error(path + ": cannot open file (it is a directory)");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open file");
    std::ostringstream content;
    content << in.rdbuf();
    if (in.bad()) throw Error(path + ": cannot read file");
    return content.str();
}

/// @brief The text of one input file, cut into tokens on demand; `#` starts a comment that runs to
/// the end of its line.
class TextFile {
public:
    explicit TextFile(std::string path) : path_(std::move(path)), text_(load_file(path_)) {}

    const std::string& path() const { return path_; }

    /// @brief Throws the one-line "path:line: what" error.
    [[noreturn]] void fail(std::size_t line, const std::string& what) const {
        throw Error(path_ + ":" + std::to_string(line) + ": " + what);
    }

    /// @brief Reads the next token; false at the end of the file.
    bool next_token(Token& token) {
        skip_blanks_and_comments();
        if (position_ == text_.size()) return false;
        const std::size_t start = position_;
        while (position_ < text_.size() && !is_blank(text_[position_]) && text_[position_] != '#') ++position_;
        token = Token{std::string_view(text_).substr(start, position_ - start), line_};
        last_token_line_ = line_;
        return true;
    }

    /// @brief Reads the tokens of the next line that has any; false at the end of the file.
    bool next_line(std::vector<Token>& tokens) {
        tokens.clear();
        Token token;
        if (!next_token(token)) return false;
        tokens.push_back(token);
        for (;;) {
            const std::size_t saved_position = position_, saved_line = line_, saved_last = last_token_line_;
            if (!next_token(token)) break;
            if (token.line != tokens.front().line) {
                position_ = saved_position;
                line_ = saved_line;
                last_token_line_ = saved_last;
                break;
            }
            tokens.push_back(token);
        }
        return true;
    }

    /// @brief True when nothing but blanks and comments is left.
    bool at_end() {
        skip_blanks_and_comments();
        return position_ == text_.size();
    }

    /// @brief The line of the last token read: where a file that ends too early is reported.
    std::size_t last_token_line() const { return last_token_line_; }

    /// @brief Bytes not read yet; bounds how many records can still follow.
    std::size_t remaining_bytes() const { return text_.size() - position_; }

private:
    static bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

    void skip_blanks_and_comments() {
        while (position_ < text_.size()) {
            const char c = text_[position_];
            if (c == '#') {
                while (position_ < text_.size() && text_[position_] != '\n') ++position_;
            } else if (is_blank(c)) {
                if (c == '\n') ++line_;
                ++position_;
            } else {
                return;
            }
        }
    }

    std::string path_;
    std::string text_;
    std::size_t position_ = 0;
    std::size_t line_ = 1;
    std::size_t last_token_line_ = 1;
};

// ---------------------------------------------------------------------------------------------
// Numbers

/// @brief Start of a number for std::from_chars, which rejects the leading '+' that files may have.
/// Returns nullptr for "+-", which from_chars would otherwise take as a negative number.
const char* skip_plus_sign(const char* first, const char* last) {
    if (first == last || *first != '+') return first;
    ++first;
    return (first != last && *first == '-') ? nullptr : first;
}

/// @brief Parses the whole of @p text as a decimal integer; false when it is not one or does not fit.
bool parse_integer(std::string_view text, long long& value) {
    const char* last = text.data() + text.size();
    const char* first = skip_plus_sign(text.data(), last);
    if (first == nullptr) return false;
    const auto [end, error] = std::from_chars(first, last, value);
    return error == std::errc() && end == last;
}

enum class NumberParse { ok, not_a_number, out_of_range };

/// @brief Parses the whole of @p text as a double ("1.0abc" is not a number). Accepts "nan" and "inf":
/// callers that need finite values check them.
NumberParse parse_double(std::string_view text, double& value) {
    const char* last = text.data() + text.size();
    const char* first = skip_plus_sign(text.data(), last);
    if (first == nullptr) return NumberParse::not_a_number;
    const auto [end, error] = std::from_chars(first, last, value);
    if (error == std::errc::result_out_of_range && end == last) return NumberParse::out_of_range;
    return (error == std::errc() && end == last) ? NumberParse::ok : NumberParse::not_a_number;
}

long long read_integer(const TextFile& file, const Token& token, const char* what) {
    long long value = 0;
    if (!parse_integer(token.text, value))
        file.fail(token.line, std::string("expected ") + what + ", found " + excerpt(token.text));
    return value;
}

/// @brief Reads the number of records or fields a header announces: an integer >= 0.
std::size_t read_count(const TextFile& file, const Token& token, const char* what) {
    const long long value = read_integer(file, token, what);
    if (value < 0) file.fail(token.line, std::string(what) + " must not be negative, found " + excerpt(token.text));
    static_assert(sizeof(std::size_t) >= sizeof(long long), "every non-negative count fits in size_t");
    return static_cast<std::size_t>(value);
}

/// @brief Reads a vertex count, which must leave every 0-based index representable as uint32.
std::size_t read_vertex_count(const TextFile& file, const Token& token, const char* what) {
    const std::size_t count = read_count(file, token, what);
    if (count == 0) file.fail(token.line, "no vertices");
    if (count > std::numeric_limits<std::uint32_t>::max()) {
        file.fail(token.line, "too many vertices: " + std::to_string(count) + ", at most " +
                                  std::to_string(std::numeric_limits<std::uint32_t>::max()));
    }
    return count;
}

/// @brief Reads any number (an attribute or a value of a skipped section); its value is not used.
void check_number(const TextFile& file, const Token& token) {
    double unused = 0.0;
    if (parse_double(token.text, unused) != NumberParse::ok)
        file.fail(token.line, "expected a number, found " + excerpt(token.text));
}

double read_coordinate(const TextFile& file, const Token& token) {
    double value = 0.0;
    switch (parse_double(token.text, value)) {
    case NumberParse::not_a_number:
        file.fail(token.line, "expected a coordinate, found " + excerpt(token.text));
    case NumberParse::out_of_range:
        file.fail(token.line, "coordinate " + excerpt(token.text) + " does not fit in a double");
    case NumberParse::ok:
        break;
    }
    if (!std::isfinite(value)) file.fail(token.line, "coordinate " + excerpt(token.text) + " is not finite");
    return value;
}

std::string index_out_of_range(long long index, long long base, std::size_t vertex_count) {
    if (vertex_count == 0) return "vertex index " + std::to_string(index) + " refers to a mesh without vertices";
    const long long last = base + static_cast<long long>(vertex_count) - 1;
    return "vertex index " + std::to_string(index) + " out of range [" + std::to_string(base) + ", " +
           std::to_string(last) + "]";
}

/// @brief Reads a tetrahedron corner numbered from @p base and returns it 0-based.
std::uint32_t read_vertex_index(const TextFile& file, const Token& token, long long base, std::size_t vertex_count) {
    const long long index = read_integer(file, token, "a vertex index");
    // index >= base first, so index - base cannot overflow.
    if (index < base || static_cast<unsigned long long>(index - base) >= vertex_count) {
        file.fail(token.line, index_out_of_range(index, base, vertex_count));
    }
    return static_cast<std::uint32_t>(index - base);
}

/// @brief How many records to reserve room for: no more than the rest of the file can hold, so an
/// absurd header count cannot allocate absurd memory. Each field takes at least a digit and a blank.
std::size_t reservable(std::size_t count, std::size_t fields_per_record, const TextFile& file) {
    return std::min(count, file.remaining_bytes() / (2 * fields_per_record));
}

// ---------------------------------------------------------------------------------------------
// Tetrahedron checks shared by the readers and validate_tet_mesh

std::string short_number(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", value);
    return text;
}

/// @brief Why tetrahedron @p tet of @p mesh has zero volume, or "" when it has volume. Its corners must
/// be in range; @p base numbers them in the message as the input does.
///
/// Zero means |orient3d| <= 1e-12 * L^3 with L the longest edge: relative, so the verdict does not
/// change with the unit of the coordinates. A repeated corner is degenerate whatever the coordinates.
std::string degeneracy(const TetMesh& mesh, std::size_t tet, long long base) {
    const std::uint32_t* corners = &mesh.tets[4 * tet];
    for (int i = 0; i < 4; ++i) {
        for (int j = i + 1; j < 4; ++j) {
            if (corners[i] == corners[j]) {
                return "degenerate tetrahedron: vertex index " + std::to_string(corners[i] + base) + " repeated";
            }
        }
    }
    double p[4][3];
    for (int i = 0; i < 4; ++i) {
        for (int axis = 0; axis < 3; ++axis) p[i][axis] = mesh.positions[3 * std::size_t{corners[i]} + axis];
    }
    double longest_squared = 0.0;
    for (int i = 0; i < 4; ++i) {
        for (int j = i + 1; j < 4; ++j) {
            const double dx = p[j][0] - p[i][0], dy = p[j][1] - p[i][1], dz = p[j][2] - p[i][2];
            longest_squared = std::max(longest_squared, dx * dx + dy * dy + dz * dz);
        }
    }
    double e[3][3]; // edges from corner 0
    for (int i = 0; i < 3; ++i) {
        for (int axis = 0; axis < 3; ++axis) e[i][axis] = p[i + 1][axis] - p[0][axis];
    }
    const double orient = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                          e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                          e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
    const double longest = std::sqrt(longest_squared);
    const double tolerance = 1e-12 * longest * longest * longest;
    if (std::abs(orient) > tolerance) return {};
    return "degenerate tetrahedron: zero volume (|orient3d| " + short_number(std::abs(orient)) +
           " <= 1e-12 * longest edge^3 = " + short_number(tolerance) + "; ReadOptions::allow_degenerate accepts it)";
}

/// @brief Fails at @p line when the tetrahedron just appended to @p mesh is degenerate and not allowed.
void check_last_tet(const TextFile& file, std::size_t line, const TetMesh& mesh, long long base,
                    const ReadOptions& options) {
    if (options.allow_degenerate) return;
    const std::string problem = degeneracy(mesh, mesh.num_tets() - 1, base);
    if (!problem.empty()) file.fail(line, problem);
}

[[noreturn]] void fail_truncated(const TextFile& file, std::size_t line, std::size_t expected, std::size_t found,
                                 const std::string& what) {
    file.fail(line, "expected " + std::to_string(expected) + " " + what + ", found " + std::to_string(found));
}

// ---------------------------------------------------------------------------------------------
// TetGen

/// @brief Reads the next record of a TetGen file: one line of exactly @p fields tokens.
void read_tetgen_record(TextFile& file, std::vector<Token>& record, std::size_t fields, std::size_t index,
                        std::size_t count, const char* what, const char* layout) {
    if (!file.next_line(record)) fail_truncated(file, file.last_token_line(), count, index, what);
    // A short last line is where a cut-off file ends, not a malformed record.
    if (record.size() < fields && file.at_end()) fail_truncated(file, record.front().line, count, index, what);
    if (record.size() != fields) {
        file.fail(record.front().line, "expected " + std::to_string(fields) + " fields (" + layout + "), found " +
                                           std::to_string(record.size()));
    }
}

/// @brief Reads the header line of a TetGen file: 1 to @p max_fields counts, the missing ones 0.
std::vector<Token> read_tetgen_header(TextFile& file, std::size_t max_fields, const char* layout) {
    std::vector<Token> header;
    if (!file.next_line(header)) file.fail(1, "empty file");
    if (header.size() > max_fields) {
        file.fail(header.front().line, "header has " + std::to_string(header.size()) + " fields, expected " + layout);
    }
    return header;
}

/// @brief Reads the attribute count at @p position of a TetGen header, 0 when the header stops before.
/// Every attribute takes at least two bytes on every line, so a count beyond the rest of the file is
/// rejected, which also keeps the field counts computed from it far from overflow.
std::size_t read_attribute_count(const TextFile& file, const std::vector<Token>& header, std::size_t position) {
    if (header.size() <= position) return 0;
    const std::size_t count = read_count(file, header[position], "an attribute count");
    if (count > file.remaining_bytes()) {
        file.fail(header[position].line, "attribute count " + std::to_string(count) + " does not fit in the file");
    }
    return count;
}

void reject_trailing_data(TextFile& file, std::size_t count, const char* what) {
    Token extra;
    if (file.next_token(extra)) {
        file.fail(extra.line, "more data after the " + std::to_string(count) + " " + what +
                                  " the header announces: " + excerpt(extra.text));
    }
}

/// @brief Reads a .node file into @p positions; returns the index of its first point (0 or 1), the base
/// of every index of the mesh.
long long read_tetgen_points(const std::string& path, std::vector<double>& positions) {
    TextFile file(path);
    const char* layout = "<#points> <dimension> <#attributes> <#boundary markers>";
    const std::vector<Token> header = read_tetgen_header(file, 4, layout);
    const std::size_t count = read_vertex_count(file, header[0], "a point count");
    if (header.size() > 1) {
        const long long dimension = read_integer(file, header[1], "a dimension");
        if (dimension != 3) file.fail(header[1].line, "dimension must be 3, found " + std::to_string(dimension));
    }
    const std::size_t attributes = read_attribute_count(file, header, 2);
    const std::size_t markers = header.size() > 3 ? read_count(file, header[3], "a boundary marker count") : 0;
    if (markers > 1)
        file.fail(header[3].line, "boundary marker count must be 0 or 1, found " + std::to_string(markers));

    const std::size_t fields = 4 + attributes + markers;
    positions.clear();
    positions.reserve(3 * reservable(count, fields, file));
    long long base = 0;
    std::vector<Token> record;
    for (std::size_t i = 0; i < count; ++i) {
        read_tetgen_record(file, record, fields, i, count, "points", "index, x, y, z, attributes, boundary marker");
        const long long index = read_integer(file, record[0], "a point index");
        const long long expected = base + static_cast<long long>(i);
        if (i == 0) {
            if (index != 0 && index != 1)
                file.fail(record[0].line, "first point index must be 0 or 1, found " + std::to_string(index));
            base = index;
        } else if (index >= base && index < expected) {
            file.fail(record[0].line, "duplicate point index " + std::to_string(index));
        } else if (index != expected) {
            file.fail(record[0].line, "point index " + std::to_string(index) + " out of sequence, expected " +
                                          std::to_string(expected));
        }
        for (std::size_t k = 1; k < 4; ++k) positions.push_back(read_coordinate(file, record[k]));
        for (std::size_t k = 4; k < 4 + attributes; ++k) check_number(file, record[k]);
        if (markers == 1) read_integer(file, record.back(), "a boundary marker");
    }
    reject_trailing_data(file, count, "points");
    return base;
}

/// @brief Reads a .ele file into @p mesh, whose positions are already read.
void read_tetgen_tetrahedra(const std::string& path, long long base, const ReadOptions& options, TetMesh& mesh) {
    TextFile file(path);
    const std::vector<Token> header =
        read_tetgen_header(file, 3, "<#tetrahedra> <nodes per tetrahedron> <#attributes>");
    const std::size_t count = read_count(file, header[0], "a tetrahedron count");
    if (count == 0) file.fail(header[0].line, "no tetrahedra");
    const std::size_t nodes = header.size() > 1 ? read_count(file, header[1], "a node count") : 4;
    if (nodes != 4 && nodes != 10)
        file.fail(header[1].line, "nodes per tetrahedron must be 4 or 10, found " + std::to_string(nodes));
    const std::size_t attributes = read_attribute_count(file, header, 2);

    const std::size_t fields = 1 + nodes + attributes;
    const std::size_t vertex_count = mesh.num_vertices();
    mesh.tets.clear();
    mesh.tets.reserve(4 * reservable(count, fields, file));
    std::vector<Token> record;
    for (std::size_t i = 0; i < count; ++i) {
        read_tetgen_record(file, record, fields, i, count, "tetrahedra", "index, nodes, attributes");
        read_integer(file, record[0], "a tetrahedron index");
        for (std::size_t k = 1; k <= nodes; ++k) {
            // Nodes 5 to 10 of a quadratic tetrahedron are checked like the corners, then dropped.
            const std::uint32_t corner = read_vertex_index(file, record[k], base, vertex_count);
            if (k <= 4) mesh.tets.push_back(corner);
        }
        for (std::size_t k = 1 + nodes; k < fields; ++k) check_number(file, record[k]);
        check_last_tet(file, record.front().line, mesh, base, options);
    }
    reject_trailing_data(file, count, "tetrahedra");
}

/// @brief `name`, `name.node` and `name.ele` all name the pair `name.node` + `name.ele`.
std::string tetgen_stem(const std::string& path) {
    const std::string extension = std::filesystem::path(path).extension().string();
    if (extension == ".node" || extension == ".ele") return path.substr(0, path.size() - extension.size());
    return path;
}

// ---------------------------------------------------------------------------------------------
// MEDIT

/// @brief A MEDIT section the reader skips, and how many tokens each of its records has in 3D.
struct SkippedSection {
    std::string_view keyword;
    std::size_t fields;
};

constexpr SkippedSection skipped_sections[] = {
    {"Edges", 3},
    {"Triangles", 4},
    {"Quadrilaterals", 5},
    {"Prisms", 7},
    {"Pentahedra", 7},
    {"Pyramids", 6},
    {"Hexahedra", 9},
    {"EdgesP2", 4},
    {"TrianglesP2", 7},
    {"QuadrilateralsQ2", 10},
    {"TetrahedraP2", 11},
    {"HexahedraQ2", 28},
    {"Corners", 1},
    {"Ridges", 1},
    {"RequiredVertices", 1},
    {"RequiredEdges", 1},
    {"RequiredTriangles", 1},
    {"RequiredQuadrilaterals", 1},
    {"Normals", 3},
    {"Tangents", 3},
    {"NormalAtVertices", 2},
    {"NormalAtTriangleVertices", 3},
    {"NormalAtQuadrilateralVertices", 4},
    {"TangentAtEdgeVertices", 3},
};

const SkippedSection* find_skipped_section(std::string_view keyword) {
    for (const SkippedSection& section : skipped_sections) {
        if (section.keyword == keyword) return &section;
    }
    return nullptr;
}

bool is_medit_keyword(std::string_view word) {
    return word == "MeshVersionFormatted" || word == "Dimension" || word == "Vertices" || word == "Tetrahedra" ||
           word == "End" || find_skipped_section(word) != nullptr;
}

/// @brief Reads the value that follows a keyword (on the same line or a later one).
Token read_value(TextFile& file, const Token& keyword) {
    Token value;
    if (!file.next_token(value)) {
        file.fail(keyword.line, "file ends after " + std::string(keyword.text) + ", which needs a value");
    }
    return value;
}

/// @brief Calls @p handle on each of the @p count records of a MEDIT section, @p fields tokens each;
/// a record may span lines. A keyword where a value should be means the section holds fewer records
/// than announced.
template <typename Handle>
void for_each_medit_record(TextFile& file, std::size_t count, std::size_t fields, const std::string& what,
                           Handle&& handle) {
    std::vector<Token> record;
    for (std::size_t i = 0; i < count; ++i) {
        record.clear();
        Token token;
        for (std::size_t k = 0; k < fields; ++k) {
            if (!file.next_token(token)) fail_truncated(file, file.last_token_line(), count, i, what);
            if (is_medit_keyword(token.text)) {
                file.fail(token.line, "expected " + std::to_string(count) + " " + what + ", found " +
                                          std::to_string(i) + " before " + excerpt(token.text));
            }
            record.push_back(token);
        }
        handle(record);
    }
}

void read_medit_vertices(TextFile& file, const Token& keyword, TetMesh& mesh) {
    const std::size_t count = read_vertex_count(file, read_value(file, keyword), "a vertex count");
    constexpr std::size_t fields = 4; // x y z reference
    mesh.positions.reserve(3 * reservable(count, fields, file));
    for_each_medit_record(file, count, fields, "vertices", [&](const std::vector<Token>& record) {
        for (std::size_t k = 0; k < 3; ++k) mesh.positions.push_back(read_coordinate(file, record[k]));
        read_integer(file, record[3], "a vertex reference");
    });
}

void read_medit_tetrahedra(TextFile& file, const Token& keyword, const ReadOptions& options, TetMesh& mesh) {
    const Token count_token = read_value(file, keyword);
    const std::size_t count = read_count(file, count_token, "a tetrahedron count");
    if (count == 0) file.fail(count_token.line, "no tetrahedra");
    constexpr std::size_t fields = 5; // four corners and a reference
    constexpr long long base = 1;
    mesh.tets.reserve(4 * reservable(count, fields, file));
    for_each_medit_record(file, count, fields, "tetrahedra", [&](const std::vector<Token>& record) {
        for (std::size_t k = 0; k < 4; ++k)
            mesh.tets.push_back(read_vertex_index(file, record[k], base, mesh.num_vertices()));
        read_integer(file, record[4], "a tetrahedron reference");
        check_last_tet(file, record.front().line, mesh, base, options);
    });
}

void skip_medit_section(TextFile& file, const Token& keyword, const SkippedSection& section) {
    const std::size_t count = read_count(file, read_value(file, keyword), "a record count");
    for_each_medit_record(file, count, section.fields, std::string(section.keyword),
                          [&](const std::vector<Token>& record) {
                              for (const Token& value : record) check_number(file, value);
                          });
}

} // namespace

// ---------------------------------------------------------------------------------------------
// Public functions

TetMesh read_tetgen(const std::string& path, const ReadOptions& options) {
    const std::string stem = tetgen_stem(path);
    TetMesh mesh;
    const long long base = read_tetgen_points(stem + ".node", mesh.positions);
    read_tetgen_tetrahedra(stem + ".ele", base, options, mesh);
    return mesh;
}

TetMesh read_medit(const std::string& path, const ReadOptions& options) {
    TextFile file(path);
    TetMesh mesh;
    Token keyword;
    if (!file.next_token(keyword)) file.fail(1, "empty file");
    bool have_dimension = false, have_vertices = false, have_tetrahedra = false;
    do {
        if (keyword.text == "End") break;
        if (keyword.text == "MeshVersionFormatted") {
            // 1 and 2 differ only in the precision of binary files; ASCII reads the same.
            read_integer(file, read_value(file, keyword), "a format version");
        } else if (keyword.text == "Dimension") {
            const Token value = read_value(file, keyword);
            const long long dimension = read_integer(file, value, "a dimension");
            if (dimension != 3) file.fail(value.line, "dimension must be 3, found " + std::to_string(dimension));
            have_dimension = true;
        } else if (keyword.text == "Vertices") {
            if (!have_dimension) file.fail(keyword.line, "Vertices before Dimension");
            if (have_vertices) file.fail(keyword.line, "second Vertices section");
            read_medit_vertices(file, keyword, mesh);
            have_vertices = true;
        } else if (keyword.text == "Tetrahedra") {
            // Corners are checked as they are read, which needs the vertices first (every writer does so).
            if (!have_vertices) file.fail(keyword.line, "Tetrahedra before Vertices");
            if (have_tetrahedra) file.fail(keyword.line, "second Tetrahedra section");
            read_medit_tetrahedra(file, keyword, options, mesh);
            have_tetrahedra = true;
        } else if (const SkippedSection* section = find_skipped_section(keyword.text)) {
            skip_medit_section(file, keyword, *section);
        } else {
            file.fail(keyword.line, "unknown keyword " + excerpt(keyword.text));
        }
    } while (file.next_token(keyword));
    if (!have_tetrahedra) file.fail(file.last_token_line(), "no tetrahedra (no Tetrahedra section)");
    return mesh;
}

TetMesh read_tet_mesh(const std::string& path, const ReadOptions& options) {
    const std::string extension = std::filesystem::path(path).extension().string();
    if (extension == ".mesh") return read_medit(path, options);
    if (extension.empty() || extension == ".node" || extension == ".ele") return read_tetgen(path, options);
    throw Error(path + ": unsupported mesh format " + excerpt(extension) +
                "; supported: .mesh (MEDIT ASCII), .node/.ele or a name without extension (TetGen)");
}

void validate_tet_mesh(const TetMesh& mesh, const std::string& source, const ReadOptions& options) {
    const auto fail = [&source](const std::string& what) { throw Error(source + ": " + what); };
    if (mesh.positions.size() % 3 != 0) {
        fail("positions hold " + std::to_string(mesh.positions.size()) + " values, not a multiple of 3");
    }
    if (mesh.tets.size() % 4 != 0)
        fail("tets hold " + std::to_string(mesh.tets.size()) + " indices, not a multiple of 4");
    if (mesh.num_tets() == 0) fail("no tetrahedra");
    for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
        for (std::size_t axis = 0; axis < 3; ++axis) {
            const double value = mesh.positions[3 * v + axis];
            if (!std::isfinite(value)) {
                fail("vertex " + std::to_string(v) + ": coordinate " + "xyz"[axis] + " is not finite (" +
                     short_number(value) + ")");
            }
        }
    }
    for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
        const std::string tet_name = "tet " + std::to_string(t) + ": ";
        for (std::size_t k = 0; k < 4; ++k) {
            const std::uint32_t corner = mesh.tets[4 * t + k];
            if (corner >= mesh.num_vertices()) fail(tet_name + index_out_of_range(corner, 0, mesh.num_vertices()));
        }
        if (options.allow_degenerate) continue;
        const std::string problem = degeneracy(mesh, t, 0);
        if (!problem.empty()) fail(tet_name + problem);
    }
}

} // namespace kdet
