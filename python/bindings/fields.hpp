#pragma once
/// @file fields.hpp
/// @brief FrameCounts and StageTimes as Python classes: one read-only attribute per field, as_dict() and
/// a repr. The fields are listed once, here; a static_assert counts the struct's fields, so a field added
/// to results.hpp without a line here stops the build instead of going missing in Python.

#include <kdet/results.hpp>

#include <nanobind/nanobind.h>
#include <nanobind/stl/string.h>

#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

namespace kdet::python {

namespace nb = nanobind;

template <class Struct, class Value>
struct Field {
    const char* name;
    Value Struct::*member;
};
template <class Struct, class Value>
Field(const char*, Value Struct::*) -> Field<Struct, Value>;

template <class Struct>
constexpr auto fields_of();

template <>
constexpr auto fields_of<FrameCounts>() {
    using C = FrameCounts;
    return std::make_tuple(Field{"candidates", &C::candidates}, Field{"narrow_phase_candidates", &C::narrow_phase_candidates},
                           Field{"colliding_pairs", &C::colliding_pairs}, Field{"colliding_tets", &C::colliding_tets},
                           Field{"exact_stage_pairs", &C::exact_stage_pairs},
                           Field{"buffer_regrows", &C::buffer_regrows}, Field{"grid_cells", &C::grid_cells},
                           Field{"grid_slots", &C::grid_slots},
                           Field{"grid_overflow_buckets", &C::grid_overflow_buckets},
                           Field{"grid_bucket_capacity", &C::grid_bucket_capacity},
                           Field{"host_waits", &C::host_waits});
}

template <>
constexpr auto fields_of<StageTimes>() {
    using T = StageTimes;
    return std::make_tuple(Field{"bounding_boxes", &T::bounding_boxes}, Field{"populate_grid", &T::populate_grid},
                           Field{"find_candidates", &T::find_candidates}, Field{"sort_pairs", &T::sort_pairs},
                           Field{"narrow_phase", &T::narrow_phase}, Field{"total", &T::total});
}

/// Converts to any field type: T{AnyField{}, ...} compiles for as many initializers as T has fields.
struct AnyField {
    template <class T>
    constexpr operator T() const { return T{}; }
};

template <class T, class Indices, class = void>
struct brace_initializable : std::false_type {};
template <class T, std::size_t... I>
struct brace_initializable<T, std::index_sequence<I...>, std::void_t<decltype(T{(void(I), AnyField{})...})>>
    : std::true_type {};

/// The number of fields of the aggregate T.
template <class T, std::size_t N = 0>
constexpr std::size_t field_count() {
    if constexpr (brace_initializable<T, std::make_index_sequence<N + 1>>::value)
        return field_count<T, N + 1>();
    else
        return N;
}

template <class Struct>
void bind_fields(nb::module_& m, const char* name, const char* doc) {
    constexpr auto fields = fields_of<Struct>();
    static_assert(std::tuple_size_v<decltype(fields)> == field_count<Struct>(),
                  "a field of FrameCounts or StageTimes is missing from fields_of<> in python/bindings/fields.hpp");
    auto cls = nb::class_<Struct>(m, name, doc);
    std::apply([&](auto... field) { (cls.def_ro(field.name, field.member), ...); }, fields);
    cls.def(
        "as_dict",
        [](const Struct& s) {
            nb::dict d;
            std::apply([&](auto... field) { ((d[field.name] = s.*(field.member)), ...); }, fields_of<Struct>());
            return d;
        },
        "The fields as a dict, in declaration order.");
    cls.def("__repr__", [name](const Struct& s) {
        std::string out = std::string(name) + "(";
        bool first = true;
        std::apply(
            [&](auto... field) {
                ((out += (first ? "" : ", ") + std::string(field.name) + "=" +
                         nb::cast<std::string>(nb::repr(nb::cast(s.*(field.member)))),
                  first = false),
                 ...);
            },
            fields_of<Struct>());
        return out + ")";
    });
}

} // namespace kdet::python
