#include <kdet/options.hpp>

#include <cctype>

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

} // namespace kdet
