/// @file text_reader.cpp
/// @brief Tokens, binary values, numbers and tetrahedron checks shared by the readers.

#include "io/text_reader.hpp"

#include <kdet/error.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>

namespace kdet::io {

std::string lowercase_extension(const std::string& path) {
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension;
}

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

void check_whole_entries(const TetMesh& mesh, const std::string& source) {
    if (mesh.positions.size() % 3 != 0)
        throw Error(source + ": the mesh's positions hold " + std::to_string(mesh.positions.size()) +
                    " values, not a multiple of 3");
    if (mesh.tets.size() % 4 != 0)
        throw Error(source + ": the mesh's tets hold " + std::to_string(mesh.tets.size()) + " indices, not a multiple of 4");
}

std::string short_number(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", value);
    return text;
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

std::size_t scalar_size(Scalar type) {
    switch (type) {
    case Scalar::int8:
    case Scalar::uint8: return 1;
    case Scalar::int16:
    case Scalar::uint16: return 2;
    case Scalar::int32:
    case Scalar::uint32:
    case Scalar::float32: return 4;
    case Scalar::int64:
    case Scalar::uint64:
    case Scalar::float64: return 8;
    }
    return 8;
}

// ---------------------------------------------------------------------------------------------
// TextFile

TextFile::TextFile(std::string path, char comment)
    : path_(std::move(path)), text_(load_file(path_)), comment_(comment) {}

void TextFile::fail(std::size_t line, const std::string& what) const {
    throw Error(path_ + ":" + std::to_string(line) + ": " + what);
}

void TextFile::fail_at_byte(std::size_t offset, const std::string& what) const {
    throw Error(path_ + ": byte " + std::to_string(offset) + ": " + what);
}

void TextFile::fail(const Token& where, const std::string& what) const {
    if (byte_offsets_) fail_at_byte(where.offset, what);
    fail(where.line, what);
}

void TextFile::fail_here(const std::string& what) const {
    if (byte_offsets_) fail_at_byte(position_, what);
    fail(last_token_line_, what);
}

bool TextFile::next_token(Token& token) {
    skip_blanks_and_comments();
    if (position_ == text_.size()) return false;
    const std::size_t start = position_;
    while (position_ < text_.size() && !is_blank(text_[position_]) &&
           (comment_ == '\0' || text_[position_] != comment_))
        ++position_;
    token = Token{std::string_view(text_).substr(start, position_ - start), line_, start};
    last_token_line_ = line_;
    return true;
}

Token TextFile::expect_token(const std::string& what) {
    Token token;
    if (!next_token(token)) fail_here("file ends early: expected " + what);
    return token;
}

void TextFile::expect_keyword(std::string_view keyword) {
    const Token token = expect_token(std::string(keyword));
    if (token.text != keyword) fail(token, "expected " + std::string(keyword) + ", found " + excerpt(token.text));
}

bool TextFile::next_line(std::vector<Token>& tokens) {
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

bool TextFile::next_raw_line(Token& line) {
    if (position_ == text_.size()) return false;
    const std::size_t start = position_;
    const std::size_t end = std::min(text_.find('\n', start), text_.size());
    std::size_t stop = end;
    if (stop > start && text_[stop - 1] == '\r') --stop;
    line = Token{std::string_view(text_).substr(start, stop - start), line_, start};
    last_token_line_ = line_;
    position_ = end;
    if (position_ < text_.size()) {
        ++position_;
        ++line_;
    }
    return true;
}

bool TextFile::at_end() {
    skip_blanks_and_comments();
    return position_ == text_.size();
}

void TextFile::skip_line_end() {
    while (position_ < text_.size() && text_[position_] != '\n') {
        if (!is_blank(text_[position_]))
            fail_here("expected the end of the line, found " + excerpt(std::string_view(text_).substr(position_)));
        ++position_;
    }
    if (position_ == text_.size()) fail_here("file ends early: expected a line break before the data");
    ++position_;
    ++line_;
}

bool TextFile::skip_past_line(std::string_view marker) {
    for (std::size_t at = position_; at < text_.size();) {
        const std::size_t found = text_.find(marker, at);
        if (found == std::string::npos) return false;
        const std::size_t after = found + marker.size();
        if (after == text_.size() || is_blank(text_[after])) {
            line_ += static_cast<std::size_t>(std::count(text_.begin() + static_cast<std::ptrdiff_t>(position_),
                                                         text_.begin() + static_cast<std::ptrdiff_t>(after), '\n'));
            position_ = after;
            last_token_line_ = line_;
            return true;
        }
        at = found + 1;
    }
    return false;
}

const unsigned char* TextFile::take_bytes(std::size_t size, const std::string& what) {
    if (size > remaining_bytes()) {
        fail_at_byte(position_, "file ends inside " + what + " (" + std::to_string(size) + " bytes needed, " +
                                    std::to_string(remaining_bytes()) + " left)");
    }
    const auto* bytes = reinterpret_cast<const unsigned char*>(text_.data() + position_);
    position_ += size;
    return bytes;
}

void TextFile::skip_blanks_and_comments() {
    while (position_ < text_.size()) {
        const char c = text_[position_];
        if (comment_ != '\0' && c == comment_) {
            while (position_ < text_.size() && text_[position_] != '\n') ++position_;
        } else if (is_blank(c)) {
            if (c == '\n') ++line_;
            ++position_;
        } else {
            return;
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Numbers in text

namespace {

/// @brief Start of a number for std::from_chars, which rejects the leading '+' that files may have.
/// Returns nullptr for "+-", which from_chars would otherwise take as a negative number.
const char* skip_plus_sign(const char* first, const char* last) {
    if (first == last || *first != '+') return first;
    ++first;
    return (first != last && *first == '-') ? nullptr : first;
}

} // namespace

bool parse_integer(std::string_view text, long long& value) {
    const char* last = text.data() + text.size();
    const char* first = skip_plus_sign(text.data(), last);
    if (first == nullptr) return false;
    const auto [end, error] = std::from_chars(first, last, value);
    return error == std::errc() && end == last;
}

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
        file.fail(token, std::string("expected ") + what + ", found " + excerpt(token.text));
    return value;
}

std::size_t read_count(const TextFile& file, const Token& token, const char* what) {
    const long long value = read_integer(file, token, what);
    if (value < 0) file.fail(token, std::string(what) + " must not be negative, found " + excerpt(token.text));
    static_assert(sizeof(std::size_t) >= sizeof(long long), "every non-negative count fits in size_t");
    return static_cast<std::size_t>(value);
}

void check_vertex_count(const TextFile& file, const Token& token, std::size_t count) {
    if (count == 0) file.fail(token, "no vertices");
    if (count > std::numeric_limits<std::uint32_t>::max()) {
        file.fail(token, "too many vertices: " + std::to_string(count) + ", at most " +
                             std::to_string(std::numeric_limits<std::uint32_t>::max()));
    }
}

std::size_t read_vertex_count(const TextFile& file, const Token& token, const char* what) {
    const std::size_t count = read_count(file, token, what);
    check_vertex_count(file, token, count);
    return count;
}

void check_number(const TextFile& file, const Token& token) {
    double unused = 0.0;
    if (parse_double(token.text, unused) != NumberParse::ok)
        file.fail(token, "expected a number, found " + excerpt(token.text));
}

double read_coordinate(const TextFile& file, const Token& token) {
    double value = 0.0;
    switch (parse_double(token.text, value)) {
    case NumberParse::not_a_number: file.fail(token, "expected a coordinate, found " + excerpt(token.text));
    case NumberParse::out_of_range: file.fail(token, "coordinate " + excerpt(token.text) + " does not fit in a double");
    case NumberParse::ok: break;
    }
    if (!std::isfinite(value)) file.fail(token, "coordinate " + excerpt(token.text) + " is not finite");
    if (!fits_float(value)) file.fail(token, "coordinate " + excerpt(token.text) + " is " + float_range);
    return value;
}

std::string index_out_of_range(long long index, long long base, std::size_t vertex_count) {
    if (vertex_count == 0) return "vertex index " + std::to_string(index) + " refers to a mesh without vertices";
    const long long last = base + static_cast<long long>(vertex_count) - 1;
    return "vertex index " + std::to_string(index) + " out of range [" + std::to_string(base) + ", " +
           std::to_string(last) + "]";
}

namespace {

/// @brief @p index numbered from @p base, 0-based; fails at @p where when it is out of range.
std::uint32_t checked_vertex_index(const TextFile& file, const Token& where, long long index, long long base,
                                   std::size_t vertex_count) {
    // index >= base first, so index - base cannot overflow.
    if (index < base || static_cast<unsigned long long>(index - base) >= vertex_count)
        file.fail(where, index_out_of_range(index, base, vertex_count));
    return static_cast<std::uint32_t>(index - base);
}

} // namespace

std::uint32_t read_vertex_index(const TextFile& file, const Token& token, long long base, std::size_t vertex_count) {
    return checked_vertex_index(file, token, read_integer(file, token, "a vertex index"), base, vertex_count);
}

std::size_t reservable(std::size_t count, std::size_t fields_per_record, const TextFile& file) {
    return std::min(count, file.remaining_bytes() / (2 * fields_per_record));
}

void fail_truncated(const TextFile& file, std::size_t line, std::size_t expected, std::size_t found,
                    const std::string& what) {
    file.fail(line, "expected " + std::to_string(expected) + " " + what + ", found " + std::to_string(found));
}

void reject_trailing_data(TextFile& file, std::size_t count, const char* what) {
    Token extra;
    if (file.next_token(extra)) {
        file.fail(extra, "more data after the " + std::to_string(count) + " " + what +
                             " the header announces: " + excerpt(extra.text));
    }
}

// ---------------------------------------------------------------------------------------------
// NumberStream

NumberStream::NumberStream(TextFile& file, bool binary, Endian order) : file_(file), binary_(binary), order_(order) {
    if (binary_) file_.use_byte_offsets();
}

Token NumberStream::text_value(const std::string& what) {
    last_ = file_.expect_token(what);
    return last_;
}

long long NumberStream::integer(Scalar type, const std::string& what) {
    if (!binary_) return read_integer(file_, text_value(what), what.c_str());
    last_ = Token{{}, 0, file_.offset()};
    switch (type) {
    case Scalar::int8: return file_.read_binary<std::int8_t>(order_, what);
    case Scalar::uint8: return file_.read_binary<std::uint8_t>(order_, what);
    case Scalar::int16: return file_.read_binary<std::int16_t>(order_, what);
    case Scalar::uint16: return file_.read_binary<std::uint16_t>(order_, what);
    case Scalar::int32: return file_.read_binary<std::int32_t>(order_, what);
    case Scalar::uint32: return file_.read_binary<std::uint32_t>(order_, what);
    case Scalar::int64: return file_.read_binary<std::int64_t>(order_, what);
    case Scalar::uint64: {
        const std::uint64_t value = file_.read_binary<std::uint64_t>(order_, what);
        if (value > static_cast<std::uint64_t>(std::numeric_limits<long long>::max()))
            fail(what + " " + std::to_string(value) + " is too large");
        return static_cast<long long>(value);
    }
    case Scalar::float32:
    case Scalar::float64: break;
    }
    fail("expected " + what + ", found a floating-point field");
}

std::size_t NumberStream::count(Scalar type, const std::string& what) {
    const long long value = integer(type, what);
    if (value < 0) fail(what + " must not be negative, found " + std::to_string(value));
    return static_cast<std::size_t>(value);
}

double NumberStream::real(Scalar type, const std::string& what) {
    if (!binary_) {
        const Token token = text_value(what);
        double value = 0.0;
        if (parse_double(token.text, value) == NumberParse::not_a_number)
            fail("expected " + what + ", found " + excerpt(token.text));
        return value;
    }
    if (type == Scalar::float32) {
        last_ = Token{{}, 0, file_.offset()};
        return file_.read_binary<float>(order_, what);
    }
    if (type == Scalar::float64) {
        last_ = Token{{}, 0, file_.offset()};
        return file_.read_binary<double>(order_, what);
    }
    return static_cast<double>(integer(type, what));
}

double NumberStream::coordinate(Scalar type) {
    if (!binary_) {
        last_ = file_.expect_token("a coordinate");
        return read_coordinate(file_, last_);
    }
    const double value = real(type, "a coordinate");
    if (!std::isfinite(value)) fail("coordinate " + short_number(value) + " is not finite");
    if (!fits_float(value)) fail("coordinate " + short_number(value) + " is " + float_range);
    return value;
}

std::uint32_t NumberStream::vertex_index(Scalar type, long long base, std::size_t vertex_count) {
    const long long index = integer(type, "a vertex index");
    return checked_vertex_index(file_, last_, index, base, vertex_count);
}

void NumberStream::expect_records(std::size_t count, std::size_t bytes_each, const std::string& what) {
    if (!binary_ || count <= file_.remaining_bytes() / bytes_each) return;
    file_.fail_at_byte(file_.offset(), std::to_string(count) + " " + what + " need " +
                                           (count > std::numeric_limits<std::size_t>::max() / bytes_each
                                                ? std::string("more than 2^64")
                                                : std::to_string(count * bytes_each)) +
                                           " bytes, only " + std::to_string(file_.remaining_bytes()) + " left");
}

std::size_t NumberStream::reservable(std::size_t count, std::size_t fields, Scalar type) const {
    const std::size_t bytes_each = fields * (binary_ ? scalar_size(type) : 2);
    return std::min(count, file_.remaining_bytes() / bytes_each);
}

// ---------------------------------------------------------------------------------------------
// Tetrahedra

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
           " <= 1e-12 * longest edge^3 = " + short_number(tolerance) +
           "; accepted with --allow-degenerate, allow_degenerate=True or ReadOptions::allow_degenerate)";
}

void check_last_tet(const TextFile& file, const Token& where, const TetMesh& mesh, long long base,
                    const ReadOptions& options) {
    if (options.allow_degenerate) return;
    const std::string problem = degeneracy(mesh, mesh.num_tets() - 1, base);
    if (!problem.empty()) file.fail(where, problem);
}

} // namespace kdet::io
