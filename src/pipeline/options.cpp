#include <kdet/error.hpp>
#include <kdet/option_table.hpp>
#include <kdet/options.hpp>

#include <cctype>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>

namespace kdet {

namespace {

template <class Enum>
struct Name {
    Enum value;
    const char* text;
};

// One table per option: canonical names first, in declaration order, then other accepted spellings.
constexpr Name<Backend> backend_table[] = {{Backend::cpu, "cpu"}, {Backend::cuda, "cuda"}};
constexpr Name<Method> method_table[] = {{Method::kdet, "kdet"},
                                         {Method::kdet_no_pairs, "kdet_no_pairs"},
                                         {Method::brute_force_loop, "brute_force_loop"},
                                         {Method::brute_force_pairs, "brute_force_pairs"},
                                         // The thesis named its brute-force methods after the GPU.
                                         {Method::brute_force_loop, "gpu"},
                                         {Method::brute_force_pairs, "gpu_no_loop"}};
constexpr Name<NarrowPhase> narrow_phase_table[] = {{NarrowPhase::sat, "sat"},
                                                    {NarrowPhase::sat_no_edges, "sat_no_edges"},
                                                    {NarrowPhase::sat_mtv, "sat_mtv"},
                                                    {NarrowPhase::gjk, "gjk"},
                                                    {NarrowPhase::fast, "fast"},
                                                    {NarrowPhase::exact, "exact"}};
constexpr Name<HashFunction> hash_table[] = {{HashFunction::djb2, "djb2"},
                                             {HashFunction::fnv1a, "fnv-1a"},
                                             {HashFunction::simple, "simple"},
                                             {HashFunction::morton, "morton"}};

/// Lower case, '-' as '_': the form in which two spellings of a name are compared.
std::string normalized(const std::string& text) {
    std::string out = text;
    for (char& c : out) c = c == '-' ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

template <class Enum, std::size_t N>
const char* name_of(const Name<Enum> (&table)[N], Enum value) {
    for (const auto& n : table)
        if (n.value == value) return n.text;
    return "?";
}

template <class Enum, std::size_t N>
bool value_of(const Name<Enum> (&table)[N], const std::string& text, Enum& out) {
    const std::string wanted = normalized(text);
    for (const auto& n : table)
        if (wanted == normalized(n.text)) {
            out = n.value;
            return true;
        }
    return false;
}

/// The first name of each value, the canonical one, in declaration order; built once per table.
template <class Enum, std::size_t N>
const std::vector<std::string>& canonical_names(const Name<Enum> (&table)[N]) {
    static const std::vector<std::string> names = [&] {
        std::vector<std::string> out;
        for (const auto& n : table)
            if (name_of(table, n.value) == n.text) out.emplace_back(n.text);
        return out;
    }();
    return names;
}

} // namespace

const char* to_string(Backend value) { return name_of(backend_table, value); }
const char* to_string(Method value) { return name_of(method_table, value); }
const char* to_string(NarrowPhase value) { return name_of(narrow_phase_table, value); }
const char* to_string(HashFunction value) { return name_of(hash_table, value); }

bool parse(const std::string& name, Backend& out) { return value_of(backend_table, name, out); }
bool parse(const std::string& name, Method& out) { return value_of(method_table, name, out); }
bool parse(const std::string& name, NarrowPhase& out) { return value_of(narrow_phase_table, name, out); }
bool parse(const std::string& name, HashFunction& out) { return value_of(hash_table, name, out); }

template <>
const std::vector<std::string>& option_names<Backend>() { return canonical_names(backend_table); }
template <>
const std::vector<std::string>& option_names<Method>() { return canonical_names(method_table); }
template <>
const std::vector<std::string>& option_names<NarrowPhase>() { return canonical_names(narrow_phase_table); }
template <>
const std::vector<std::string>& option_names<HashFunction>() { return canonical_names(hash_table); }

std::vector<std::string> aliases(Method value) {
    std::vector<std::string> out;
    for (const auto& n : method_table)
        if (n.value == value && name_of(method_table, value) != n.text) out.emplace_back(n.text);
    return out;
}

namespace {

/// A choice's accessors for OptionInfo, from its enum and its DetectorOptions member.
template <class Enum, Enum DetectorOptions::*member>
struct ChoiceField {
    static long long get(const DetectorOptions& o) { return static_cast<long long>(o.*member); }
    static void put(DetectorOptions& o, long long v) { o.*member = static_cast<Enum>(v); }
    static const std::vector<std::string>& names() { return option_names<Enum>(); }
    static bool read_name(const std::string& text, long long& index) {
        Enum value{};
        if (!parse(text, value)) return false;
        index = static_cast<long long>(value);
        return true;
    }
};

template <class Number, Number DetectorOptions::*member>
struct NumberField {
    static long long get(const DetectorOptions& o) { return static_cast<long long>(o.*member); }
    static void put(DetectorOptions& o, long long v) { o.*member = static_cast<Number>(v); }
};

/// A real option's accessors: get and put carry the float's bits.
template <float DetectorOptions::*member>
struct RealField {
    static long long get(const DetectorOptions& o) {
        std::uint32_t bits;
        std::memcpy(&bits, &(o.*member), sizeof bits);
        return bits;
    }
    static void put(DetectorOptions& o, long long v) {
        const auto bits = static_cast<std::uint32_t>(v);
        std::memcpy(&(o.*member), &bits, sizeof bits);
    }
};

constexpr unsigned text_front_ends = front_end_cli | front_end_bench | front_end_view;
constexpr unsigned every_front_end = text_front_ends | front_end_panel | front_end_python;
constexpr long long no_limit = std::numeric_limits<long long>::max();

template <class Enum, Enum DetectorOptions::*member>
OptionInfo choice(const char* name, const char* field, const char* flag, const char* bench_flag, const char* label,
                  const char* value_name, const char* help, unsigned front_ends) {
    using F = ChoiceField<Enum, member>;
    return OptionInfo{name, field, flag, bench_flag, label, value_name, help, OptionType::choice, 0, 0, nullptr,
                      front_ends, &F::get, &F::put, &F::names, &F::read_name};
}

template <class Number, Number DetectorOptions::*member>
OptionInfo number(const char* name, const char* flag, const char* bench_flag, const char* label, const char* help,
                  OptionType type, long long min, long long max, const char* zero_means, unsigned front_ends) {
    using F = NumberField<Number, member>;
    return OptionInfo{name, name, flag, bench_flag, label, type == OptionType::integer ? "N" : "", help, type, min, max,
                      zero_means, front_ends, &F::get, &F::put, nullptr, nullptr};
}

template <float DetectorOptions::*member>
OptionInfo real(const char* name, const char* flag, const char* label, const char* value_name, const char* help,
                unsigned front_ends) {
    using F = RealField<member>;
    return OptionInfo{name, name, flag, flag, label, value_name, help, OptionType::real, 0, 0, nullptr,
                      front_ends, &F::get, &F::put, nullptr, nullptr};
}

/// The shortest decimal text that reads back as the same float.
std::string real_text(float value) {
    char text[32];
    for (int digits = 1; digits <= 9; ++digits) {
        std::snprintf(text, sizeof text, "%.*g", digits, static_cast<double>(value));
        if (std::strtof(text, nullptr) == value) break;
    }
    return text;
}

constexpr const char* real_expected = "a finite number >= 0";

} // namespace

const std::vector<OptionInfo>& option_table() {
    using O = DetectorOptions;
    static const std::vector<OptionInfo> table = {
        choice<Backend, &O::backend>("backend", "backend", "--backend", "--backend", "backend", "B", "where detection runs",
                                     every_front_end | front_end_locate),
        choice<Method, &O::method>("method", "method", "--method", "-c", "method", "M", "pair search", every_front_end),
        choice<NarrowPhase, &O::narrow_phase>("test", "narrow_phase", "--test", "-o", "narrow phase", "T",
                                              "narrow phase", every_front_end),
        choice<HashFunction, &O::hash>("hash", "hash", "--hash", "-h", "hash", "H", "grid hash",
                                       every_front_end | front_end_locate),
        number<int, &O::threads>("threads", "--threads", "--threads", "threads", "CPU threads (default: all)",
                                 OptionType::integer, 1, 1024, nullptr, every_front_end | front_end_locate),
        number<int, &O::block_size>("block_size", "--block-size", "-g", "block size",
                                    "CUDA threads per block (default 128)", OptionType::integer, 1, 1024, nullptr,
                                    // `kdet bench -g` takes the thesis's sizes only, a few of these.
                                    (every_front_end & ~front_end_bench) | front_end_locate),
        number<std::uint32_t, &O::bucket_capacity>(
            "bucket_capacity", "--bucket-capacity", "--bucket-capacity", "bucket capacity",
            "tet ids per grid bucket before an overflow bucket is chained, 1-4096\n"
            "(default 0: chosen from the scene, 4-32)",
            OptionType::integer, 0, max_bucket_capacity, "chosen from the scene", text_front_ends | front_end_python),
        number<std::size_t, &O::initial_candidate_capacity>(
            "initial_candidate_capacity", "", "", "initial candidate capacity",
            "pairs the candidate buffer holds at first (0: sized from the tets); it grows as needed",
            OptionType::integer, 0, no_limit, "sized from the tets", front_end_python),
        number<std::size_t, &O::memory_limit>(
            "memory_limit", "--memory-limit", "--memory-limit", "memory limit",
            "bytes the detector may take for a frame's candidates and pairs; a frame that needs\n"
            "more fails at once",
            OptionType::integer, 0, no_limit, "as much as the memory holds", text_front_ends | front_end_python),
        number<bool, &O::contacts>("contacts", "", "", "contacts", "depth and direction per colliding pair",
                                   OptionType::boolean, 0, 1, nullptr, front_end_python),
        real<&O::margin>("margin", "--margin", "margin", "D",
                         "report the pairs at most D apart (default 0: touching or intersecting)",
                         every_front_end),
        number<bool, &O::distances>("distances", "", "", "distances",
                                    "distance and a closest point on each tet per pair", OptionType::boolean, 0, 1,
                                    nullptr, front_end_python),
        number<bool, &O::results_to_host>("results_to_host", "", "", "results to host",
                                          "copy pairs, flags and contacts to the host after each frame",
                                          OptionType::boolean, 0, 1, nullptr, front_end_python),
    };
    return table;
}

const OptionInfo* find_option(const std::string& name) {
    std::string wanted = normalized(name);
    wanted.erase(0, wanted.find_first_not_of('_'));
    for (const OptionInfo& o : option_table())
        if (wanted == o.name || wanted == o.field) return &o;
    return nullptr;
}

std::string join_names(const std::vector<std::string>& names) {
    std::string out;
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (i) out += i + 1 == names.size() ? " or " : ", ";
        out += names[i];
    }
    return out;
}

std::string invalid_value_message(const std::string& shown, const std::string& text, const std::string& expected) {
    // Control characters are written as \xNN, so that the message stays one line whatever was given.
    std::string echoed;
    for (const char c : text) {
        const auto byte = static_cast<unsigned char>(c);
        if (byte >= 0x20 && byte != 0x7f) {
            echoed += c;
            continue;
        }
        char escaped[8];
        std::snprintf(escaped, sizeof escaped, "\\x%02x", byte);
        echoed += escaped;
    }
    return "invalid value '" + echoed + "' for " + shown + ": expected " + expected;
}

namespace {

/// Whether @p text is a decimal number as people write one: an optional sign, digits with an optional
/// point, an optional exponent. strtod alone also takes hex, inf, nan and leading blanks.
bool is_decimal(const std::string& text, bool allow_fraction) {
    std::size_t i = 0, digits = 0;
    const auto skip_digits = [&] {
        std::size_t n = 0;
        for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i) ++n;
        return n;
    };
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    digits += skip_digits();
    if (allow_fraction && i < text.size() && text[i] == '.') {
        ++i;
        digits += skip_digits();
    }
    if (digits == 0) return false;
    if (allow_fraction && i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
        ++i;
        if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
        if (skip_digits() == 0) return false;
    }
    return i == text.size();
}

} // namespace

double parse_number(const std::string& shown, const std::string& text, double lo, double hi, const std::string& expected) {
    errno = 0;
    const double value = is_decimal(text, true) ? std::strtod(text.c_str(), nullptr) : NAN;
    if (errno == ERANGE || !(value >= lo && value <= hi)) throw Error(invalid_value_message(shown, text, expected));
    return value;
}

long long parse_integer(const std::string& shown, const std::string& text, long long lo, long long hi) {
    errno = 0;
    char* end = nullptr;
    const long long value = std::strtoll(text.c_str(), &end, 10);
    if (!is_decimal(text, false) || *end != '\0' || errno == ERANGE || value < lo || value > hi)
        throw Error(invalid_value_message(shown, text, "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]"));
    return value;
}

std::string parse_choice(const std::string& shown, const std::string& text, const std::vector<std::string>& accepted) {
    for (const std::string& a : accepted)
        if (a == text) return text;
    throw Error(invalid_value_message(shown, text, join_names(accepted)));
}

std::string OptionInfo::text(const DetectorOptions& options) const {
    const long long value = get(options);
    switch (type) {
    case OptionType::choice: return names()[static_cast<std::size_t>(value)];
    case OptionType::boolean: return value ? "true" : "false";
    case OptionType::real: return real_text(static_cast<float>(real(options)));
    case OptionType::integer: break;
    }
    return std::to_string(value);
}

std::string OptionInfo::default_text() const { return text(DetectorOptions{}); }

bool OptionInfo::unset_by_default() const {
    const long long value = get(DetectorOptions{});
    return type == OptionType::integer && (value < min || value > max);
}

std::string OptionInfo::expected() const {
    switch (type) {
    case OptionType::choice: return join_names(names());
    case OptionType::boolean: return "true or false";
    case OptionType::real: return real_expected;
    case OptionType::integer: break;
    }
    return "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
}

std::string OptionInfo::values_help(const DetectorOptions& defaults) const {
    if (type != OptionType::choice) return expected();
    const std::string chosen = text(defaults);
    std::string out;
    for (const std::string& n : names()) out += (out.empty() ? "" : ", ") + n + (n == chosen ? " (default)" : "");
    return out;
}

void OptionInfo::parse(const std::string& text, DetectorOptions& options, const std::string& shown) const {
    long long value = 0;
    switch (type) {
    case OptionType::choice:
        if (!read_name(text, value)) throw Error(invalid_value_message(shown, text, expected()));
        break;
    case OptionType::boolean: {
        const std::string word = normalized(text);
        if (word != "true" && word != "false") throw Error(invalid_value_message(shown, text, expected()));
        value = word == "true";
        break;
    }
    case OptionType::integer: value = parse_integer(shown, text, min, max); break;
    case OptionType::real: return set_real(options, parse_number(shown, text, 0.0, FLT_MAX, expected()));
    }
    put(options, value);
}

double OptionInfo::real(const DetectorOptions& options) const {
    const auto bits = static_cast<std::uint32_t>(get(options));
    float value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
}

void OptionInfo::set_real(DetectorOptions& options, double value) const {
    if (!(value >= 0.0) || value > FLT_MAX)
    {
        char text[32];
        std::snprintf(text, sizeof text, "%g", value);
        throw Error(std::string(name) + ": expected " + real_expected + ", got " + text);
    }
    const float stored = static_cast<float>(value);
    std::uint32_t bits;
    std::memcpy(&bits, &stored, sizeof bits);
    put(options, bits);
}

void check_options(const DetectorOptions& options) {
    DetectorOptions scratch = options; // the setters check into it
    for (const OptionInfo& o : option_table()) {
        const long long value = o.get(options);
        switch (o.type) {
        case OptionType::choice:
            if (value < 0 || value >= static_cast<long long>(o.names().size()))
                throw Error(std::string(o.name) + ": " + std::to_string(value) + " is not one of its values (" +
                            join_names(o.names()) + ")");
            break;
        case OptionType::integer:
            // Counts without a bound (std::size_t: bytes, pairs) take any value, SIZE_MAX as well.
            if (o.max != no_limit && !(o.unset_by_default() && value == o.get(DetectorOptions{}))) o.set_number(scratch, value);
            break;
        case OptionType::boolean: break;
        case OptionType::real: o.set_real(scratch, o.real(options)); break;
        }
    }
}

void OptionInfo::set_number(DetectorOptions& options, long long value) const {
    if (value < min) {
        const std::string zero = zero_means ? "0 (" + std::string(zero_means) + ") or " : "";
        throw Error(std::string(name) + ": expected " + (min > 1 ? "a number from " + std::to_string(min) : zero + "a positive number") +
                    ", got " + std::to_string(value));
    }
    if (value > max)
        throw Error(std::string(label) + " " + std::to_string(value) + " out of range [" + std::to_string(min) + ", " +
                    std::to_string(max) + "]");
    put(options, value);
}

} // namespace kdet

