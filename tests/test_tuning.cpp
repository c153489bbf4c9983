// Each backend's tuning keeps to what the pipeline's mechanism relies on, for every kind of scene.

#include "exec/tuning.hpp"
#include "grid/bucket_table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace kdet {
namespace {

/// Scene sizes around the GPU's switch between its splits, and one past what 32-bit item numbers
/// hold once split (the pipeline then searches whole tets).
constexpr std::size_t scene_tets[] = {0, 1, 1000, CudaTuning::split_by_blocks_max_tets,
                                      CudaTuning::split_by_blocks_max_tets + 1, std::size_t{1} << 31};

template <class Tuning>
void expect_usable(const char* name) {
    SCOPED_TRACE(name);
    // GridParamsKernel: layer 0's cells a positive, finite number of spacings wide.
    EXPECT_TRUE(std::isfinite(Tuning::grid_cell_spacings));
    EXPECT_GT(Tuning::grid_cell_spacings, 0.0f);
    // The stages divide their counts by these to launch their work items.
    EXPECT_GE(Tuning::plan_chunk, 1u);
    EXPECT_GE(Tuning::search_tets_per_item, 1u);
    EXPECT_GE(Tuning::keys_per_appending_item, 1u);
    for (const bool self_collision : {false, true})
        for (const std::size_t tets : scene_tets) {
            SCOPED_TRACE(testing::Message() << "self-collision " << self_collision << ", " << tets << " tets");
            // A search part steps over the layers by the parts' count.
            EXPECT_GE(Tuning::search_layer_parts(self_collision, tets), 1u);
            // group_blocks_of_part: the block parts divide a group's blocks, so that together they
            // read every block once.
            const std::uint32_t block_parts = Tuning::search_block_parts(self_collision, tets);
            EXPECT_GE(block_parts, 1u);
            EXPECT_EQ(bound_group % block_parts, 0u);
        }
}

TEST(Tuning, EachBackendsValuesMeetWhatThePipelineReliesOn) {
    expect_usable<CpuTuning>("CpuTuning");
    expect_usable<CudaTuning>("CudaTuning");
}

} // namespace
} // namespace kdet
