/// @file test_options.cpp
/// @brief The library's table of option names, which the command line, the viewer and Python share.

#include <kdet/options.hpp>

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace kdet {
namespace {

/// Every canonical name reads back as the value whose name it is, in any spelling the table allows.
template <class Option>
void expect_names_round_trip(std::size_t value_count) {
    const std::vector<std::string>& names = option_names<Option>();
    ASSERT_EQ(names.size(), value_count);
    for (std::size_t i = 0; i < names.size(); ++i) {
        Option value{};
        ASSERT_TRUE(parse(names[i], value)) << names[i];
        EXPECT_EQ(static_cast<std::size_t>(value), i) << names[i]; // declaration order
        EXPECT_EQ(names[i], to_string(value));
        std::string shouted = names[i], other_separator = names[i];
        for (char& c : shouted) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        for (char& c : other_separator) c = c == '_' ? '-' : (c == '-' ? '_' : c);
        for (const std::string& spelling : {shouted, other_separator}) {
            Option again{};
            EXPECT_TRUE(parse(spelling, again)) << spelling;
            EXPECT_EQ(again, value) << spelling;
        }
    }
}

TEST(Options, EveryNameReadsBackInAnyCaseAndWithEitherSeparator) {
    expect_names_round_trip<Backend>(2);
    expect_names_round_trip<Method>(4);
    expect_names_round_trip<NarrowPhase>(6);
    expect_names_round_trip<HashFunction>(4);
}

TEST(Options, TheThesissSpellingsAreAccepted) {
    Method method{};
    ASSERT_TRUE(parse("gpu", method));
    EXPECT_EQ(method, Method::brute_force_loop);
    ASSERT_TRUE(parse("GPU_NO_LOOP", method));
    EXPECT_EQ(method, Method::brute_force_pairs);
    EXPECT_EQ(aliases(Method::brute_force_pairs), std::vector<std::string>{"gpu_no_loop"});
    EXPECT_TRUE(aliases(Method::kdet).empty());
    NarrowPhase test{};
    ASSERT_TRUE(parse("sat-mtv", test));
    EXPECT_EQ(test, NarrowPhase::sat_mtv);
    ASSERT_TRUE(parse("SAT-No-Edges", test));
    EXPECT_EQ(test, NarrowPhase::sat_no_edges);
    HashFunction hash{};
    ASSERT_TRUE(parse("FNV-1a", hash));
    EXPECT_EQ(hash, HashFunction::fnv1a);
}

TEST(Options, UnknownNamesLeaveTheValueUnchanged) {
    NarrowPhase test = NarrowPhase::gjk;
    for (const char* name : {"", "sat ", "satmtv", "sat.mtv", "gpu"}) {
        EXPECT_FALSE(parse(name, test)) << name;
        EXPECT_EQ(test, NarrowPhase::gjk);
    }
    Backend backend = Backend::cpu;
    EXPECT_FALSE(parse("gpu", backend)); // a method's alias, not a backend
    EXPECT_EQ(backend, Backend::cpu);
}

} // namespace
} // namespace kdet
