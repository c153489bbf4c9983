// The CPU execution layer's buffers: the host twin of the CUDA layer's device buffers.

#include "exec/cpu_exec.hpp"

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

TEST(HostBuffer, ShrinkingKeepsTheMemory) {
    HostBuffer<std::uint32_t> buffer;
    buffer.resize_discard(100);
    const std::uint32_t* memory = buffer.data();
    buffer.resize_discard(5);
    EXPECT_EQ(buffer.data(), memory);
    EXPECT_EQ(buffer.size(), 5u);
    EXPECT_EQ(buffer.capacity_bytes(), 100u * sizeof(std::uint32_t));
}

} // namespace
} // namespace kdet
