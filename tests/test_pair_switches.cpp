// The detector's per-pair switches: what each add_object gives, kept through the table's regrowths, and
// the row-major table the pipeline reads.

#include "pipeline/pair_switches.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace kdet {
namespace {

TEST(PairSwitches, AddedObjectsCollideWithOthersNotThemselvesAndKeepEarlierSwitches) {
    PairSwitches switches;
    std::vector<std::uint8_t> expected; // row-major, rebuilt in full after every add
    std::size_t n = 0;
    for (std::size_t added = 0; added < 37; ++added) { // across several regrowths of the stride
        switches.add_object();
        std::vector<std::uint8_t> grown((n + 1) * (n + 1));
        for (std::size_t a = 0; a <= n; ++a)
            for (std::size_t b = 0; b <= n; ++b) grown[a * (n + 1) + b] = a < n && b < n ? expected[a * n + b] : a != b;
        expected.swap(grown);
        ++n;
        // Some switches changed between adds: self-collision of every third object, a pair off now and then.
        if (added % 3 == 0) switches(added, added) = expected[added * n + added] = 1;
        if (added % 5 == 4) switches(added, added - 2) = switches(added - 2, added) = expected[added * n + added - 2] = expected[(added - 2) * n + added] = 0;
        ASSERT_EQ(switches.objects(), n);
        ASSERT_EQ(switches.table(), expected) << n << " objects";
    }
}

TEST(PairSwitches, NoObjectsNoTable) { EXPECT_TRUE(PairSwitches{}.table().empty()); }

} // namespace
} // namespace kdet
