// The execution layer's primitives and the pipeline's helpers around them, on the CPU backend.
#include "exec/cpu_exec.hpp"
#include "exec/radix_sort.hpp"
#include "pipeline/bounding_boxes.hpp"
#include "pipeline/pair_keys.hpp"
#include "pipeline/scene_view.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

namespace kdet {
namespace {

TEST(ShareVertex, IsTrueExactlyWhenSomeIndexOfOneTetIsAnIndexOfTheOther) {
    std::mt19937 rng(17);
    std::uniform_int_distribution<std::uint32_t> index(0, 9); // few values: about half the pairs share one
    int shared = 0;
    for (int round = 0; round < 20000; ++round) {
        TetIndices a, b;
        for (int k = 0; k < 4; ++k) {
            a.v[k] = index(rng);
            b.v[k] = index(rng) | (round % 3 == 0 ? 0x80000000u : 0u); // high bits matter too
        }
        bool expected = false;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) expected = expected || a.v[i] == b.v[j];
        ASSERT_EQ(share_vertex(a, b), expected) << round;
        ASSERT_EQ(share_vertex(b, a), expected) << round;
        shared += expected;
    }
    EXPECT_GT(shared, 5000);
    EXPECT_LT(shared, 15000);
}

TEST(PairKeyBits, EveryKeyOfTheTetsFitsAndNoBitIsSpare) {
    for (std::uint32_t tets : {2u, 3u, 4u, 5u, 1000u, 1u << 20, (1u << 20) + 2, 0xfffffff0u}) {
        const int bits = pair_key_bits(tets);
        const std::uint64_t largest = pair_key(tets - 2, tets - 1);
        EXPECT_LT(largest, bits == 64 ? ~0ull : 1ull << bits) << tets << " tets";
        EXPECT_LE(bits, 64);
    }
    // When the lower id of the largest pair has its own top bit set, the bound is tight.
    EXPECT_EQ(pair_key(1u << 20, (1u << 20) + 1) >> (pair_key_bits((1u << 20) + 2) - 1), 1u);
    EXPECT_EQ(pair_key_bits(2), 33);
    EXPECT_EQ(pair_key_bits(1000), 42);
}

TEST(CpuSort, SortsTheCountedKeysOfEveryWidthAndLeavesNoKeyOut) {
    std::mt19937_64 random(11);
    // Small counts take the comparison sort, larger ones the radix passes, on up to `threads` slices
    // of at least 32k keys (100,003 keys: three slices of unequal size on three threads); pair keys
    // leave bits 20-31 zero (a pass every key shares, or, told so, bits the passes skip: then digits
    // span the gap), 64 bits use every digit.
    struct Width {
        int bits, low_word_bits;
    };
    for (const int threads : {1, 2, 3})
        for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1000}, std::size_t{100003}})
            for (const Width w : {Width{1, 32}, Width{11, 32}, Width{12, 32}, Width{33, 32}, Width{52, 32}, Width{52, 20},
                                  Width{49, 17}, Width{38, 0}, Width{64, 32}}) {
                DetectorOptions options;
                options.threads = threads;
                const CpuExec exec(options);
                std::vector<std::uint64_t> keys(n + 5, 0x5555u); // 5 slots past the count, not sorted
                for (std::size_t i = 0; i < n; ++i) {
                    std::uint64_t key = w.bits == 64 ? random() : random() & ((std::uint64_t{1} << w.bits) - 1);
                    if (w.bits == 52) key &= ~(std::uint64_t{0xfff} << 20);
                    if (w.bits > 32) key &= ~(((std::uint64_t{1} << 32) - 1) & ~((std::uint64_t{1} << w.low_word_bits) - 1));
                    keys[i] = key;
                }
                std::vector<std::uint64_t> expected(keys.begin(), keys.begin() + static_cast<std::ptrdiff_t>(n));
                std::sort(expected.begin(), expected.end());
                const unsigned long long count = n;
                exec.sort(keys.data(), keys.size(), &count, w.bits, w.low_word_bits);
                EXPECT_TRUE(std::equal(expected.begin(), expected.end(), keys.begin()))
                    << n << " keys of " << w.bits << " bits (low word " << w.low_word_bits << "), " << threads << " threads";
            }
}

TEST(RadixSort, SortsByTheBitsFromFirstBitOnAndKeepsTheOrderOfKeysEqualThere) {
    // Few distinct high words, so most keys tie there; low words in no order, which a sort of whole
    // keys would reorder. Small counts take the comparison sort, larger ones the passes (three unequal
    // slices on three threads).
    std::mt19937_64 random(5);
    for (const int threads : {1, 2, 3})
        for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1000}, std::size_t{100003}})
            for (const int first_bit : {20, 32}) {
                std::vector<std::uint64_t> keys(n), scratch(n);
                for (std::uint64_t& key : keys) key = (random() % 97) << 32 | (random() & 0xffffffffu);
                std::vector<std::uint64_t> expected = keys;
                std::stable_sort(expected.begin(), expected.end(),
                                 [first_bit](std::uint64_t a, std::uint64_t b) { return a >> first_bit < b >> first_bit; });
                radix_sort(keys.data(), n, 39, scratch.data(), threads, first_bit);
                EXPECT_EQ(keys, expected) << n << " keys from bit " << first_bit << ", " << threads << " threads";
            }
}

TEST(CpuSort, ByHighWordKeepsTheOrderOfKeysOfOneHighWord) {
    // What point location's sorts rely on: keys of one high word (a slot, a point) stay in the order
    // they were written; the slots past the count (small keys here) are not sorted in.
    std::mt19937_64 random(3);
    for (const int threads : {1, 2})
        for (const std::size_t n : {std::size_t{0}, std::size_t{1000}, std::size_t{100003}}) {
            DetectorOptions options;
            options.threads = threads;
            const CpuExec exec(options);
            std::vector<std::uint64_t> keys(n + 5, 0x5555u);
            for (std::size_t i = 0; i < n; ++i) keys[i] = (random() % 211) << 32 | (random() & 0xffffffffu);
            std::vector<std::uint64_t> expected(keys.begin(), keys.begin() + static_cast<std::ptrdiff_t>(n));
            std::stable_sort(expected.begin(), expected.end(), [](std::uint64_t a, std::uint64_t b) { return a >> 32 < b >> 32; });
            const unsigned long long count = n;
            exec.sort_by_high_word(keys.data(), keys.size(), &count, 40);
            EXPECT_TRUE(std::equal(expected.begin(), expected.end(), keys.begin())) << n << " keys, " << threads << " threads";
        }
}

TEST(CpuExec, UploadsCopyEveryElementWhateverTheSlices) {
    // Below 1 MiB one copy; above it a slice per thread (3 MiB + 3 elements: slices of unequal size).
    for (const int threads : {1, 2, 3})
        for (const std::size_t n : {std::size_t{0}, std::size_t{1000}, std::size_t{3 * (1u << 20) / 4 + 3}}) {
            DetectorOptions options;
            options.threads = threads;
            const CpuExec exec(options);
            std::vector<std::uint32_t> host(n), device(n + 2, 7u);
            std::iota(host.begin(), host.end(), 1u);
            exec.upload(device.data(), host.data(), n);
            EXPECT_TRUE(std::equal(host.begin(), host.end(), device.begin())) << n << " elements, " << threads << " threads";
            EXPECT_EQ(device[n], 7u) << "written past the end";
            EXPECT_EQ(device[n + 1], 7u) << "written past the end";
        }
}

TEST(ReduceRuns, MergesEachRunOfEqualKeysWhereverTheThreadsSplitTheItems) {
    // Runs of every length, one crossing each slice boundary, and a key that comes back after another
    // (a run of its own, as on the GPU).
    std::vector<std::uint32_t> keys;
    std::mt19937 random(7);
    for (std::uint32_t key : {0u, 1u, 2u, 5u, 1u, 6u, 7u})
        keys.insert(keys.end(), key == 2u ? 1u : 1u + random() % 9000u, key);
    std::vector<Aabb> boxes(keys.size());
    std::uniform_real_distribution<float> coordinate(-10.0f, 10.0f);
    for (Aabb& b : boxes) {
        b.lo = vec3{coordinate(random), coordinate(random), coordinate(random)};
        b.hi = b.lo + vec3{1.0f, 2.0f, 3.0f};
    }
    std::vector<std::uint32_t> expected_keys;
    std::vector<Aabb> expected_boxes;
    for (std::size_t i = 0; i < keys.size(); ++i) {
        if (i == 0 || keys[i] != keys[i - 1]) {
            expected_keys.push_back(keys[i]);
            expected_boxes.push_back(boxes[i]);
        } else {
            expected_boxes.back() = BoxUnion{}(expected_boxes.back(), boxes[i]);
        }
    }
    ASSERT_EQ(expected_keys.size(), 7u);
    for (int threads : {1, 2, 3}) {
        DetectorOptions options;
        options.threads = threads;
        const CpuExec exec(options);
        std::vector<std::uint32_t> run_keys(keys.size(), 99);
        std::vector<Aabb> run_boxes(keys.size());
        std::uint32_t runs = 0;
        exec.reduce_runs(keys.data(), [&](std::uint64_t i) { return boxes[i]; }, keys.size(), BoxUnion{},
                         run_keys.data(), run_boxes.data(), &runs);
        ASSERT_EQ(runs, expected_keys.size()) << threads << " threads";
        for (std::uint32_t r = 0; r < runs; ++r) {
            EXPECT_EQ(run_keys[r], expected_keys[r]);
            for (int a = 0; a < 3; ++a) {
                EXPECT_EQ(component(run_boxes[r].lo, a), component(expected_boxes[r].lo, a)) << "run " << r;
                EXPECT_EQ(component(run_boxes[r].hi, a), component(expected_boxes[r].hi, a)) << "run " << r;
            }
        }
    }
}

} // namespace
} // namespace kdet
