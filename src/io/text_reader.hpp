#pragma once
/// @file text_reader.hpp
/// @brief What the readers share: a loaded input file cut into tokens or binary values, number
/// parsing, and the checks on vertex indices and tetrahedra. Private to the io module.
///
/// Error locations: a text file reports "path:line: what"; once a reader meets binary data it calls
/// TextFile::use_byte_offsets() and every later error reads "path: byte N: what".

#include <kdet/io.hpp>
#include <kdet/mesh.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace kdet::io {

/// @brief A whitespace-separated word of a file, the line (1-based) it stands on and its byte offset.
struct Token {
    std::string_view text;
    std::size_t line = 0;
    std::size_t offset = 0;
};

/// @brief Quotes file content for an error message: shortened, with unprintable bytes replaced, so
/// the message stays one readable line whatever the file holds.
std::string excerpt(std::string_view text);

/// @brief The extension of @p path in lower case (".MSH" reads as ".msh"), with its dot; empty when none.
std::string lowercase_extension(const std::string& path);

/// @brief Throws "SOURCE: the mesh's positions hold N values, not a multiple of 3" (or its tets, of 4)
/// where @p mesh holds a partial vertex or tet, which num_vertices() and num_tets() would drop.
void check_whole_entries(const TetMesh& mesh, const std::string& source);

/// @brief A double for a message, with 3 significant digits.
std::string short_number(double value);

/// @brief Whether a coordinate read as a double stays finite as the float32 the detector stores (from
/// 2^128 - 2^103 on, a double rounds to infinity); float_range names that range in messages.
inline bool fits_float(double value) { return value < 0x1.ffffffp127 && value > -0x1.ffffffp127; }
constexpr const char* float_range = "beyond float range (|x| <= 3.4e38: positions are float32)";

/// @brief The whole content of @p path; throws "path: cannot open file" and the like.
std::string load_file(const std::string& path);

/// @brief The byte order of binary data.
enum class Endian { little, big };

/// @brief The numeric types of binary files.
enum class Scalar { int8, uint8, int16, uint16, int32, uint32, int64, uint64, float32, float64 };

/// @brief Size of one @p type value in bytes.
std::size_t scalar_size(Scalar type);

/// @brief True for the integer types.
inline bool is_integer(Scalar type) { return type != Scalar::float32 && type != Scalar::float64; }

/// @brief Decodes the sizeof(T) bytes at @p bytes stored in @p order. Works on any host byte order:
/// the value is assembled byte by byte.
template <typename T>
T decode(const unsigned char* bytes, Endian order) {
    static_assert(std::is_trivially_copyable_v<T>, "plain numbers only");
    using Bits =
        std::conditional_t<sizeof(T) == 1, std::uint8_t,
                           std::conditional_t<sizeof(T) == 2, std::uint16_t,
                                              std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;
    static_assert(sizeof(Bits) == sizeof(T), "1, 2, 4 or 8 bytes");
    std::uint64_t bits = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i)
        bits = (bits << 8) | bytes[order == Endian::big ? i : sizeof(T) - 1 - i];
    const Bits narrow = static_cast<Bits>(bits);
    T value;
    std::memcpy(&value, &narrow, sizeof value);
    return value;
}

/// @brief The text of one input file, cut into tokens on demand. A comment character (none when
/// '\0') starts a comment that runs to the end of its line. Binary data is taken byte by byte.
class TextFile {
public:
    explicit TextFile(std::string path, char comment = '#');

    const std::string& path() const { return path_; }

    /// @brief Throws the one-line "path:line: what" error.
    [[noreturn]] void fail(std::size_t line, const std::string& what) const;
    /// @brief Throws the one-line "path: byte N: what" error.
    [[noreturn]] void fail_at_byte(std::size_t offset, const std::string& what) const;
    /// @brief Fails at @p where: its line, or its byte offset after use_byte_offsets().
    [[noreturn]] void fail(const Token& where, const std::string& what) const;
    /// @brief Fails where the reader stands: used when the file ends too early.
    [[noreturn]] void fail_here(const std::string& what) const;

    /// @brief From now on errors name byte offsets: line numbers mean little past binary data.
    void use_byte_offsets() { byte_offsets_ = true; }

    /// @brief Reads the next token; false at the end of the file.
    bool next_token(Token& token);
    /// @brief Reads the next token; fails with "file ends early: expected WHAT" at the end.
    Token expect_token(const std::string& what);
    /// @brief Reads the next token, which must be @p keyword.
    void expect_keyword(std::string_view keyword);
    /// @brief Reads the tokens of the next line that has any; false at the end of the file.
    bool next_line(std::vector<Token>& tokens);
    /// @brief Reads the rest of the current line as it is, without its line break; false at the end.
    bool next_raw_line(Token& line);
    /// @brief True when nothing but blanks and comments is left.
    bool at_end();

    /// @brief Moves past the line break that ends a header line; binary data starts after it. Only
    /// blanks may stand before it.
    void skip_line_end();
    /// @brief Moves to just past the next @p marker followed by a blank or the end of the file
    /// (binary data may run right up to it); false, without moving, when there is none.
    bool skip_past_line(std::string_view marker);

    /// @brief Takes @p size raw bytes; fails "file ends inside WHAT" when fewer are left.
    const unsigned char* take_bytes(std::size_t size, const std::string& what);

    /// @brief Reads one binary value of type T stored in @p order.
    template <typename T>
    T read_binary(Endian order, const std::string& what) {
        return decode<T>(take_bytes(sizeof(T), what), order);
    }

    /// @brief The line of the last token read: where a file that ends too early is reported.
    std::size_t last_token_line() const { return last_token_line_; }
    /// @brief The whole file, for readers that look ahead to choose a layout.
    std::string_view content() const { return text_; }
    /// @brief Bytes read so far.
    std::size_t offset() const { return position_; }
    /// @brief Bytes not read yet; bounds how many records can still follow.
    std::size_t remaining_bytes() const { return text_.size() - position_; }

private:
    static bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }
    void skip_blanks_and_comments();

    std::string path_;
    std::string text_;
    char comment_;
    bool byte_offsets_ = false;
    std::size_t position_ = 0;
    std::size_t line_ = 1;
    std::size_t last_token_line_ = 1;
};

// ---------------------------------------------------------------------------------------------
// Numbers in text

/// @brief Parses the whole of @p text as a decimal integer; false when it is not one or does not fit.
bool parse_integer(std::string_view text, long long& value);

enum class NumberParse { ok, not_a_number, out_of_range };

/// @brief Parses the whole of @p text as a double ("1.0abc" is not a number). Accepts "nan" and "inf":
/// callers that need finite values check them.
NumberParse parse_double(std::string_view text, double& value);

long long read_integer(const TextFile& file, const Token& token, const char* what);

/// @brief Reads the number of records or fields a header announces: an integer >= 0.
std::size_t read_count(const TextFile& file, const Token& token, const char* what);

/// @brief Fails unless @p count vertices leave every 0-based index representable as uint32.
void check_vertex_count(const TextFile& file, const Token& token, std::size_t count);

/// @brief Reads a vertex count, which must leave every 0-based index representable as uint32.
std::size_t read_vertex_count(const TextFile& file, const Token& token, const char* what);

/// @brief Reads any number (an attribute or a value of a skipped section); its value is not used.
void check_number(const TextFile& file, const Token& token);

/// @brief Reads a finite coordinate.
double read_coordinate(const TextFile& file, const Token& token);

std::string index_out_of_range(long long index, long long base, std::size_t vertex_count);

/// @brief Reads a vertex index numbered from @p base and returns it 0-based.
std::uint32_t read_vertex_index(const TextFile& file, const Token& token, long long base, std::size_t vertex_count);

/// @brief How many records to reserve room for: no more than the rest of the file can hold, so an
/// absurd header count cannot allocate absurd memory. Each field takes at least a digit and a blank.
std::size_t reservable(std::size_t count, std::size_t fields_per_record, const TextFile& file);

[[noreturn]] void fail_truncated(const TextFile& file, std::size_t line, std::size_t expected, std::size_t found,
                                 const std::string& what);

/// @brief Fails when anything but blanks and comments follows the @p count records a header announced.
void reject_trailing_data(TextFile& file, std::size_t count, const char* what);

// ---------------------------------------------------------------------------------------------
// Numbers in text or binary blocks

/// @brief The values of a data block, read as text tokens or as binary numbers of one byte order.
/// Errors are reported at the last value read.
class NumberStream {
public:
    /// @brief A text stream when @p binary is false; binary values stored in @p order otherwise.
    NumberStream(TextFile& file, bool binary, Endian order = Endian::little);

    bool binary() const { return binary_; }
    TextFile& file() { return file_; }

    /// @brief Reads an integer stored as @p type (a text token in text files).
    long long integer(Scalar type, const std::string& what);
    /// @brief Reads an integer >= 0 stored as @p type.
    std::size_t count(Scalar type, const std::string& what);
    /// @brief Reads a number stored as @p type, which may be any value (NaN included).
    double real(Scalar type, const std::string& what);
    /// @brief Reads a finite coordinate stored as @p type.
    double coordinate(Scalar type);
    /// @brief Reads a vertex index numbered from @p base and returns it 0-based.
    std::uint32_t vertex_index(Scalar type, long long base, std::size_t vertex_count);

    /// @brief In binary files, fails unless @p count records of @p bytes_each bytes fit in the rest of
    /// the file: a header's absurd count is caught before anything is allocated or read for it.
    void expect_records(std::size_t count, std::size_t bytes_each, const std::string& what);
    /// @brief How many of @p count records of @p fields values stored as @p type to reserve room for.
    std::size_t reservable(std::size_t count, std::size_t fields, Scalar type) const;

    /// @brief Where the last value stood.
    const Token& last() const { return last_; }
    [[noreturn]] void fail(const std::string& what) const { file_.fail(last_, what); }

private:
    Token text_value(const std::string& what);

    TextFile& file_;
    bool binary_;
    Endian order_;
    Token last_;
};

// ---------------------------------------------------------------------------------------------
// Tetrahedra

/// @brief Why tetrahedron @p tet of @p mesh has zero volume, or "" when it has volume. Its corners must
/// be in range; @p base numbers them in the message as the input does.
std::string degeneracy(const TetMesh& mesh, std::size_t tet, long long base);

/// @brief Fails at @p where when the tetrahedron just appended to @p mesh is degenerate and not allowed.
void check_last_tet(const TextFile& file, const Token& where, const TetMesh& mesh, long long base,
                    const ReadOptions& options);

} // namespace kdet::io
