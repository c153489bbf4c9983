// The CPU execution layer's buffers: the host twin of the CUDA layer's device buffers.

#include "exec/cpu_exec.hpp"
#include "pipeline/capacity.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <new>

namespace kdet {
namespace {

TEST(HostBuffer, AFailedGrowthLeavesAnEmptyBufferThatCanGrowAgain) {
    HostBuffer<std::uint64_t> buffer;
    buffer.resize_discard(1000);
    ASSERT_NE(buffer.data(), nullptr);
    // A size whose byte count overflows: the allocation fails deterministically (even under sanitizers).
    const std::size_t too_many = std::numeric_limits<std::size_t>::max() / 4;
    EXPECT_THROW(buffer.resize_discard(too_many), std::bad_alloc);
    EXPECT_EQ(buffer.size(), 0u);
    EXPECT_EQ(buffer.data(), nullptr);
    EXPECT_EQ(buffer.capacity_bytes(), 0u);
    buffer.resize_discard(10);
    ASSERT_NE(buffer.data(), nullptr);
    buffer.data()[9] = 7;
    EXPECT_EQ(buffer.size(), 10u);
}

TEST(HostBuffer, TryResizeReportsAFailedGrowthInsteadOfThrowing) {
    HostBuffer<std::uint64_t> buffer;
    EXPECT_TRUE(buffer.try_resize_discard(1000));
    EXPECT_EQ(buffer.size(), 1000u);
    EXPECT_FALSE(buffer.try_resize_discard(std::numeric_limits<std::size_t>::max() / 4));
    EXPECT_EQ(buffer.size(), 0u);
    EXPECT_EQ(buffer.data(), nullptr);
    EXPECT_TRUE(buffer.try_resize_discard(10));
    ASSERT_NE(buffer.data(), nullptr);
    EXPECT_EQ(buffer.size(), 10u);
}

TEST(HostBuffer, ShrinkingKeepsTheMemory) {
    HostBuffer<std::uint32_t> buffer;
    buffer.resize_discard(100);
    const std::uint32_t* memory = buffer.data();
    buffer.resize_discard(5);
    EXPECT_EQ(buffer.data(), memory);
    EXPECT_EQ(buffer.size(), 5u);
    EXPECT_EQ(buffer.capacity_bytes(), 100u * sizeof(std::uint32_t));
}

TEST(HostBuffer, HoldsOverAlignedRowsOnTheirAlignmentAtEverySize) {
    // Rows aligned beyond what malloc promises (the grid's block bounds, the slabs), in buffers of
    // every size: each must keep the alignment.
    struct alignas(64) Row {
        float lanes[16];
    };
    for (std::size_t n : {std::size_t{1}, std::size_t{3}, std::size_t{1000}, std::size_t{40000}}) {
        for (int attempt = 0; attempt < 8; ++attempt) {
            HostBuffer<Row> buffer;
            buffer.resize_discard(n);
            EXPECT_EQ(reinterpret_cast<std::uintptr_t>(buffer.data()) % alignof(Row), 0u) << n << " rows";
        }
    }
}

TEST(GrownCapacity, KeepsWhatSufficesAndOtherwiseGrowsByAQuarterAtLeast) {
    EXPECT_EQ(grown_capacity(0, 1000, 1u << 30), 1000u);        // the first sizing: what is asked for
    EXPECT_EQ(grown_capacity(1000, 1000, 1u << 30), 1000u);     // enough: unchanged
    EXPECT_EQ(grown_capacity(1000, 10, 1u << 30), 1000u);       // never shrinks
    EXPECT_EQ(grown_capacity(1000, 1001, 1u << 30), 1250u);     // a little more: a quarter more
    EXPECT_EQ(grown_capacity(1000, 5000, 1u << 30), 5000u);     // much more: what is asked for
    EXPECT_EQ(grown_capacity(1000, 1001, 1100), 1100u);         // never beyond the limit
    // A need that creeps up by 0.1 % a frame for 1,000 frames reallocates a few times, not every frame.
    std::uint64_t capacity = 0, growths = 0;
    double need = 100000.0;
    for (int frame = 0; frame < 1000; ++frame, need *= 1.001) {
        const std::uint64_t grown = grown_capacity(capacity, static_cast<std::uint64_t>(need), 1ull << 40);
        growths += grown != capacity;
        capacity = grown;
        EXPECT_GE(capacity, static_cast<std::uint64_t>(need));
        EXPECT_LE(capacity, static_cast<std::uint64_t>(1.25 * need) + 1);
    }
    EXPECT_LE(growths, 6u);
}

TEST(RerunCapacity, KeepsWhatSufficesAndOtherwiseAtLeastDoubles) {
    EXPECT_EQ(rerun_capacity(0, 1000), 1250u);       // the first sizing: a quarter over the need
    EXPECT_EQ(rerun_capacity(1000, 1000), 1000u);    // enough: unchanged
    EXPECT_EQ(rerun_capacity(1000, 10), 1000u);      // never shrinks
    EXPECT_EQ(rerun_capacity(1000, 1001), 2000u);    // a little more: twice as much
    EXPECT_EQ(rerun_capacity(1000, 5000), 6250u);    // much more: a quarter over the need
    // A need that grows by a fifth a frame (a deepening overlap) for 40 frames outgrows the buffer
    // every few frames, not every frame, and the buffer stays within twice the need.
    std::uint64_t capacity = 1000, growths = 0;
    double need = 1000.0;
    for (int frame = 0; frame < 40; ++frame, need *= 1.2) {
        const std::uint64_t grown = rerun_capacity(capacity, static_cast<std::uint64_t>(need));
        growths += grown != capacity;
        capacity = grown;
        EXPECT_GE(capacity, static_cast<std::uint64_t>(need));
        EXPECT_LE(capacity, 2 * static_cast<std::uint64_t>(need) + 1);
    }
    EXPECT_LE(growths, 11u);
}

/// A buffer with room for at most `limit` elements, as memory near its end; counts its allocations.
struct LimitedBuffer {
    std::size_t limit, elements = 0, allocations = 0;
    std::size_t size() const { return elements; }
    bool try_resize_discard(std::size_t n) {
        ++allocations;
        elements = n <= limit ? n : 0;
        return n <= limit;
    }
    void resize_discard(std::size_t n) {
        if (!try_resize_discard(n)) throw std::bad_alloc();
    }
};

TEST(GrowForRerun, TakesRerunCapacitysRoomWhereItFitsElseTheNeed) {
    constexpr std::size_t unlimited = std::numeric_limits<std::size_t>::max();
    LimitedBuffer ample{100000, 1000};
    EXPECT_TRUE(grow_for_rerun(ample, 1001, unlimited));
    EXPECT_EQ(ample.size(), rerun_capacity(1000, 1001)); // twice as much
    EXPECT_EQ(ample.allocations, 1u);
    LimitedBuffer tight{1500, 1000};
    EXPECT_TRUE(grow_for_rerun(tight, 1001, unlimited)); // twice as much does not fit, the need does
    EXPECT_EQ(tight.size(), 1001u);
    EXPECT_TRUE(grow_for_rerun(tight, 900, unlimited)); // enough room: nothing allocated
    EXPECT_EQ(tight.size(), 1001u);
    EXPECT_EQ(tight.allocations, 2u);
    LimitedBuffer full{1000, 1000};
    EXPECT_FALSE(grow_for_rerun(full, 1001, unlimited)); // not even the need
    EXPECT_EQ(full.size(), 0u);
}

TEST(GrowForRerun, StaysWithinTheRoomOfTheMemoryLimitAndAsksNothingBeyondIt) {
    LimitedBuffer headroom{100000, 1000};
    EXPECT_TRUE(grow_for_rerun(headroom, 1001, 1500)); // twice as much is beyond the room: as much as it allows
    EXPECT_EQ(headroom.size(), 1500u);
    LimitedBuffer over{100000, 1000};
    EXPECT_FALSE(grow_for_rerun(over, 1600, 1500)); // the need itself is beyond: no allocation tried
    EXPECT_EQ(over.allocations, 0u);
    EXPECT_EQ(over.size(), 1000u);
}

TEST(RoomFor, CountsTheElementsTheLimitLeavesBesideTheRest) {
    EXPECT_EQ(room_for(0, 123456, 8), std::numeric_limits<std::size_t>::max()); // no limit
    EXPECT_EQ(room_for(1000, 200, 8), 100u);
    EXPECT_EQ(room_for(1000, 1000, 8), 0u);
    EXPECT_EQ(room_for(1000, 5000, 8), 0u); // the rest alone is over it
}

TEST(PairsWindowForCandidates, GrowsByTheCandidatesFactor) {
    EXPECT_EQ(pairs_window_for_candidates(400, 1000, 2500), 1000u);   // the candidates grew 2.5 times
    EXPECT_EQ(pairs_window_for_candidates(1, 3, 10), 4u);             // rounds up
    EXPECT_EQ(pairs_window_for_candidates(400, 1000, 1000), 400u);    // no growth: unchanged
    EXPECT_EQ(pairs_window_for_candidates(400, 0, 2500), 400u);       // no buffer before: nothing to go by
    // A deepening overlap (pass_through_armadillos r2 on the CPU): 311,057 candidates outran a buffer
    // of 262,144 whose pairs had filled a window of 262,144; the window of the candidates' rerun holds
    // the 280,032 pairs of the next frames, where a window grown only for its own overflow ran out a
    // frame later.
    const std::uint64_t capacity = rerun_capacity(262144, 311057);
    EXPECT_GE(pairs_window_for_candidates(262144, 262144, capacity), 280032u);
}

} // namespace
} // namespace kdet
