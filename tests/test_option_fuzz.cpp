// Property test of the option table's text parsing, which every front end's flags go through: for every
// option, random strings (digits, signs, spaces, letters, huge numbers, bytes of any value) are either
// read into a value the option accepts or refused with the one-line "invalid value" message naming
// the flag (control characters in it escaped); never a crash, an exception of another kind, or a
// value out of range.

#include "random_text.hpp"

#include <kdet/error.hpp>
#include <kdet/option_table.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

namespace kdet {
namespace {

TEST(OptionFuzz, EveryOptionReadsRandomTextIntoItsRangeOrRefusesItInOneLine) {
    std::mt19937 rng(48);
    for (const OptionInfo& option : option_table()) {
        const std::string shown = option.flag[0] ? option.flag : option.name;
        std::size_t accepted = 0;
        for (int draw = 0; draw < 4000; ++draw) {
            const std::string text = test::random_text(rng);
            DetectorOptions options;
            try {
                option.parse(text, options, shown);
            } catch (const Error& error) {
                const std::string message = error.what();
                EXPECT_EQ(message.find('\n'), std::string::npos) << option.name << ": " << message;
                EXPECT_EQ(message.rfind("invalid value '", 0), 0u) << option.name << ": " << message;
                EXPECT_NE(message.find("' for " + shown + ": expected "), std::string::npos) << option.name << ": " << message;
                continue;
            }
            ++accepted;
            const long long value = option.get(options);
            if (option.type == OptionType::choice) {
                EXPECT_GE(value, 0) << option.name << " <- '" << text << "'";
                EXPECT_LT(value, static_cast<long long>(option.names().size())) << option.name << " <- '" << text << "'";
            } else {
                if (option.type == OptionType::real) {
                    // A real's value is its float's bits: the number itself must be a finite distance.
                    const double real = option.real(options);
                    EXPECT_TRUE(std::isfinite(real) && real >= 0.0) << option.name << " <- '" << text << "': " << real;
                } else {
                    EXPECT_GE(value, option.min) << option.name << " <- '" << text << "'";
                    EXPECT_LE(value, option.max) << option.name << " <- '" << text << "'";
                }
                // What was read reads back the same (text() is what help and --json show).
                DetectorOptions again;
                option.parse(option.text(options), again, shown);
                EXPECT_EQ(option.get(again), value) << option.name << " <- '" << text << "'";
            }
        }
        // The draws include accepted values for every option, so both branches are exercised.
        EXPECT_GT(accepted, 0u) << option.name;
    }
}

} // namespace
} // namespace kdet
