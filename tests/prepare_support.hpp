#pragma once
/// Preparing the thesis meshes from the tests, through `kdet prepare` and its cache.

#include <gtest/gtest.h>

#include <string>

namespace kdet::test {

/// @brief Runs `kdet prepare ARGUMENTS` (through the cache). Returns "" when it worked, else why not;
/// @p unavailable tells whether that is because this machine cannot prepare meshes at all (no kdet
/// command, built without CGAL, no tetgen, no models), which makes a test skip rather than fail.
std::string run_prepare(const std::string& arguments, bool& unavailable);

/// @brief Prepares through `kdet prepare`; skips the test when this machine cannot, fails it when
/// preparing went wrong.
#define KDET_PREPARE_OR_SKIP(arguments)                                   \
    do {                                                                  \
        bool unavailable_ = false;                                        \
        const std::string failure_ = run_prepare(arguments, unavailable_); \
        if (!failure_.empty()) {                                          \
            if (unavailable_) GTEST_SKIP() << failure_;                   \
            FAIL() << failure_;                                           \
        }                                                                 \
    } while (false)

} // namespace kdet::test
