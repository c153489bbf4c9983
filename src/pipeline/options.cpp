#include <kdet/options.hpp>

#include <iterator>

namespace kdet {

namespace {

template <class Enum>
struct Name {
    Enum value;
    const char* text;
};

constexpr Name<Backend> backend_names[] = {{Backend::cpu, "cpu"}, {Backend::cuda, "cuda"}};
constexpr Name<Method> method_names[] = {{Method::kdet, "kdet"},
                                         {Method::kdet_no_pairs, "kdet_no_pairs"},
                                         {Method::brute_force_loop, "brute_force_loop"},
                                         {Method::brute_force_pairs, "brute_force_pairs"}};
constexpr Name<NarrowPhase> narrow_phase_names[] = {{NarrowPhase::sat, "sat"},
                                                    {NarrowPhase::sat_no_edges, "sat_no_edges"},
                                                    {NarrowPhase::sat_mtv, "sat_mtv"},
                                                    {NarrowPhase::gjk, "gjk"},
                                                    {NarrowPhase::fast, "fast"},
                                                    {NarrowPhase::exact, "exact"}};
constexpr Name<HashFunction> hash_names[] = {{HashFunction::djb2, "djb2"},
                                             {HashFunction::fnv1a, "fnv-1a"},
                                             {HashFunction::simple, "simple"},
                                             {HashFunction::morton, "morton"}};

template <class Enum, std::size_t N>
const char* name_of(const Name<Enum> (&names)[N], Enum value) {
    for (const auto& n : names)
        if (n.value == value) return n.text;
    return "?";
}

template <class Enum, std::size_t N>
bool value_of(const Name<Enum> (&names)[N], const std::string& text, Enum& out) {
    for (const auto& n : names)
        if (text == n.text) {
            out = n.value;
            return true;
        }
    return false;
}

} // namespace

const char* to_string(Backend value) { return name_of(backend_names, value); }
const char* to_string(Method value) { return name_of(method_names, value); }
const char* to_string(NarrowPhase value) { return name_of(narrow_phase_names, value); }
const char* to_string(HashFunction value) { return name_of(hash_names, value); }

bool parse(const std::string& name, Backend& out) { return value_of(backend_names, name, out); }
bool parse(const std::string& name, Method& out) { return value_of(method_names, name, out); }
bool parse(const std::string& name, NarrowPhase& out) { return value_of(narrow_phase_names, name, out); }
bool parse(const std::string& name, HashFunction& out) { return value_of(hash_names, name, out); }

} // namespace kdet
