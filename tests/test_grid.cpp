// Grid building blocks: hash functions, layer choice, cell ranges and the bucket table.

#include "exec/cpu_exec.hpp"
#include "exec/tuning.hpp"
#include "geometry/enclosing_sphere.hpp"
#include "grid/bucket_table.hpp"
#include "pipeline/bounding_boxes.hpp"
#include "pipeline/grid_sizing.hpp"
#include "pipeline/scene_view.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <random>
#include <set>
#include <tuple>
#include <vector>

namespace kdet {
namespace {

struct HashCase {
    CellCoord cell;
    std::uint32_t probe;
    std::uint32_t djb2, fnv1a, simple, morton; // from an independent Python implementation
};

TEST(Hash, MatchesIndependentReferenceValues) {
    const HashCase cases[] = {
        {{0, 0, 0, 0}, 0, 2781706629u, 3120489557u, 0u, 0u},
        {{1, 2, 3, 4}, 0, 3460325199u, 659969745u, 418111338u, 271471897u},
        {{1, 2, 3, 4}, 5, 3460504884u, 400233476u, 805388255u, 658748814u},
        {{524287, 1000, 77, 31}, 2, 4230547747u, 2168485597u, 1509067783u, 3960095325u},
    };
    for (const HashCase& c : cases) {
        EXPECT_EQ(hash_cell(HashFunction::djb2, c.cell, c.probe), c.djb2);
        EXPECT_EQ(hash_cell(HashFunction::fnv1a, c.cell, c.probe), c.fnv1a);
        EXPECT_EQ(hash_cell(HashFunction::simple, c.cell, c.probe), c.simple);
        EXPECT_EQ(hash_cell(HashFunction::morton, c.cell, c.probe), c.morton);
    }
}

TEST(Hash, Djb2EqualsItsDefinitionByteAfterByte) {
    // DJB2 adds each byte times its power of 33; the definition runs h = h * 33 + byte.
    std::mt19937 rng(5);
    for (int i = 0; i < 10000; ++i) {
        const std::uint32_t words[5] = {static_cast<std::uint32_t>(rng()), static_cast<std::uint32_t>(rng()),
                                        static_cast<std::uint32_t>(rng()), static_cast<std::uint32_t>(rng() % 32),
                                        static_cast<std::uint32_t>(rng() % 64)};
        std::uint32_t h = 5381u;
        for (std::uint32_t w : words)
            for (int byte = 0; byte < 4; ++byte) h = h * 33u + ((w >> (8 * byte)) & 0xffu);
        ASSERT_EQ(hash_cell(HashFunction::djb2, CellCoord{words[0], words[1], words[2], words[3]}, words[4]), h) << i;
    }
}

class HashSpread : public ::testing::TestWithParam<HashFunction> {};

TEST_P(HashSpread, SpreadsABlockOfCellsOverTheTable) {
    // 32^3 neighbouring cells on two layers into 2^17 slots: a decent hash fills most of the
    // expected slots and never piles many cells onto one.
    const std::uint32_t bits = 17, slots = 1u << bits;
    std::vector<std::uint32_t> load(slots, 0);
    std::uint32_t cells = 0;
    for (std::uint32_t layer = 0; layer < 2; ++layer)
        for (std::uint32_t x = 0; x < 32; ++x)
            for (std::uint32_t y = 0; y < 32; ++y)
                for (std::uint32_t z = 0; z < 32; ++z, ++cells)
                    ++load[table_slot(hash_cell(GetParam(), make_cell(x + 1000, y, z, static_cast<int>(layer)), 0), bits)];
    const auto used = static_cast<double>(std::count_if(load.begin(), load.end(), [](std::uint32_t l) { return l > 0; }));
    const double expected_used = slots * (1.0 - std::exp(-static_cast<double>(cells) / slots));
    EXPECT_GT(used, 0.8 * expected_used);
    EXPECT_LE(*std::max_element(load.begin(), load.end()), 12u);
}

TEST_P(HashSpread, ProbesVisitDifferentSlots) {
    std::set<std::uint32_t> slots;
    for (std::uint32_t probe = 0; probe < 16; ++probe)
        slots.insert(table_slot(hash_cell(GetParam(), CellCoord{5, 6, 7, 1}, probe), 10));
    EXPECT_GE(slots.size(), 14u);
}

INSTANTIATE_TEST_SUITE_P(AllHashes, HashSpread,
                         ::testing::Values(HashFunction::djb2, HashFunction::fnv1a, HashFunction::simple,
                                           HashFunction::morton));

TEST(Layer, PicksTheSmallestLayerWhoseCellHoldsTheSize) {
    const GridParams g{{0, 0, 0}, 0.5f, 2.0f, 6};
    EXPECT_EQ(layer_of(g, 0.1f), 0);
    EXPECT_EQ(layer_of(g, 0.5f), 0);
    EXPECT_EQ(layer_of(g, 0.5001f), 1);
    EXPECT_EQ(layer_of(g, 1.0f), 1);
    EXPECT_EQ(layer_of(g, 7.9f), 4);
    EXPECT_EQ(layer_of(g, 1000.0f), 5); // beyond the top layer: clamped
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> size(0.01f, 15.0f);
    for (int i = 0; i < 10000; ++i) {
        const float d = size(rng);
        const int l = layer_of(g, d);
        EXPECT_LE(d, std::ldexp(0.5f, l));
        if (l > 0) {
            EXPECT_GT(d, std::ldexp(0.5f, l - 1));
        }
    }
}

TEST(CellRange, CoversTheBoxAndSpansAtMostTwoCellsOnTheTetsLayer) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const GridParams g{{-10, -10, -10}, 0.01f, 100.0f, 12};
    for (int i = 0; i < 20000; ++i) {
        const float s = 0.01f * std::pow(100.0f, unit(rng));
        const vec3 c{20 * unit(rng) - 10, 20 * unit(rng) - 10, 20 * unit(rng) - 10};
        vec3 v[4];
        for (auto& p : v) p = c + vec3{s * unit(rng), s * unit(rng), s * unit(rng)};
        const Aabb box = tet_box(v);
        const int layer = layer_of(g, enclosing_sphere_diameter(v));
        const CellRange r = cell_range(g, box, layer);
        const float cell = std::ldexp(0.01f, layer);
        for (int a = 0; a < 3; ++a) {
            ASSERT_LE(r.hi[a] - r.lo[a], 1u);
            ASSERT_LE(static_cast<float>(r.lo[a]) * cell, component(box.lo, a) - component(g.origin, a) + 1e-4f);
            ASSERT_GE(static_cast<float>(r.hi[a] + 1) * cell, component(box.hi, a) - component(g.origin, a) - 1e-4f);
        }
    }
}

TEST(CellRange, ClampsNonFiniteAndFarCoordinates) {
    const GridParams g{{0, 0, 0}, 1e-3f, 1e3f, 4};
    EXPECT_EQ(cell_index(g, std::nanf(""), 0.0f, 0), 0u);
    EXPECT_EQ(cell_index(g, -5.0f, 0.0f, 0), 0u);
    EXPECT_EQ(cell_index(g, 1e30f, 0.0f, 0), 1u << 30);
    EXPECT_EQ(cell_index(g, 2.5f, 0.0f, 1), 1250u);
}

TEST(CellRange, ForEachCellVisitsEveryCellOnceXFastestAndStopsWhenAsked) {
    for (std::uint32_t nx = 1; nx <= 3; ++nx)
        for (std::uint32_t ny = 1; ny <= 3; ++ny)
            for (std::uint32_t nz = 1; nz <= 3; ++nz) {
                const CellRange r{{5, 7, 1u << 30}, {5 + nx - 1, 7 + ny - 1, (1u << 30) + nz - 1}};
                std::vector<std::array<std::uint32_t, 3>> expected, seen;
                for (std::uint32_t z = r.lo[2]; z <= r.hi[2]; ++z)
                    for (std::uint32_t y = r.lo[1]; y <= r.hi[1]; ++y)
                        for (std::uint32_t x = r.lo[0]; x <= r.hi[0]; ++x) expected.push_back({x, y, z});
                EXPECT_TRUE(for_each_cell(r, [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
                    seen.push_back({x, y, z});
                    return true;
                }));
                ASSERT_EQ(seen, expected) << nx << " x " << ny << " x " << nz;
                for (std::size_t stop = 1; stop <= expected.size(); ++stop) {
                    std::size_t calls = 0;
                    const bool all = for_each_cell(r, [&](std::uint32_t, std::uint32_t, std::uint32_t) { return ++calls < stop; });
                    ASSERT_EQ(calls, stop);
                    ASSERT_FALSE(all);
                }
            }
}

/// A query box that overlaps every entry's.
const Aabb everywhere{{-INFINITY, -INFINITY, -INFINITY}, {INFINITY, INFINITY, INFINITY}};

/// @brief A query's visitor that records the ids it is given, in order.
struct SeenIds {
    std::vector<std::uint32_t> ids;
    void operator()(const GridEntry& e) { ids.push_back(e.id()); }
};

/// A table on the CPU execution layer with the given geometry.
/// Visits every entry of a cell.
struct EveryEntry {
    std::multiset<std::uint32_t> found;
    void operator()(const GridEntry& e) {
        EXPECT_EQ(e.object, e.id());
        found.insert(e.id());
    }
};

struct TestTable {
    std::vector<BucketHeader> headers;
    std::vector<std::uint32_t> ids;
    std::vector<std::uint32_t> claimed_slots;
    std::uint32_t overflow_used = 0, failure = 0, claimed = 0;
    GridView view{};
    TestTable(std::uint32_t slots, std::uint32_t capacity, std::uint32_t pool, std::uint32_t probes, HashFunction hash)
        : headers(slots + pool, BucketHeader{}), ids(static_cast<std::size_t>(slots + pool) * capacity), claimed_slots(slots) {
        std::uint32_t bits = 0;
        while ((1u << bits) < slots) ++bits;
        view = GridView{headers.data(), ids.data(), nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, 0, &overflow_used, &failure, &claimed,
                        claimed_slots.data(), slots, bits, capacity, pool, 1, probes, hash};
    }
    /// A compacted copy of the table (the table itself stays open for inserts), with room for
    /// `room` entries; each entry carries its id, and its id again as the object.
    struct Compacted {
        std::vector<BucketHeader> headers;
        std::vector<std::uint32_t> list_keys, sorted_keys, list_begin, list_end;
        std::vector<EntryBlock> entry_blocks;
        std::vector<BlockBoundGroup> block_bounds;
        std::uint32_t blocks = 0;
        std::uint32_t used = 0, failure = 0;
        GridView view;
    };
    Compacted compacted(std::size_t room) const {
        return compacted(room, [](std::uint32_t id) { return GridEntry{Aabb{}, id, id}; });
    }
    template <class EntryOf>
    Compacted compacted(std::size_t room, const EntryOf& entry_of) const {
        const std::size_t blocks = (room + entry_block - 1) / entry_block;
        Compacted c{headers, std::vector<std::uint32_t>(room), std::vector<std::uint32_t>(room),
                    std::vector<std::uint32_t>(view.slot_count), std::vector<std::uint32_t>(view.slot_count),
                    std::vector<EntryBlock>(blocks), std::vector<BlockBoundGroup>((blocks + bound_group - 1) / bound_group),
                    static_cast<std::uint32_t>(blocks), 0, 0, view};
        c.view.headers = c.headers.data();
        c.view.list_keys = c.list_keys.data();
        c.view.list_begin = c.list_begin.data();
        c.view.list_end = c.list_end.data();
        c.view.entry_blocks = c.entry_blocks.data();
        c.view.block_bounds = c.block_bounds.data();
        c.view.entries_used = &c.used;
        c.view.entry_capacity = static_cast<std::uint32_t>(room);
        c.view.failure = &c.failure;
        for (std::uint32_t order = 0; order < view.slot_count; ++order)
            gather_cell(c.view, order, [&](std::uint32_t id) { return entry_of(id).object; });
        CpuExec(DetectorOptions{}).sort_lists(c.list_keys.data(), c.sorted_keys.data(), room, c.list_begin.data(),
                                              c.list_end.data(), view.slot_count);
        if (c.failure == 0)
            for (std::uint32_t k = 0; k < c.used; ++k) place_entry(c.view, c.sorted_keys.data(), k, entry_of);
        for (std::uint32_t block = 0; block < c.blocks; ++block) bound_entry_block(c.view, block, c.used);
        return c;
    }
    void next_frame() {
        ++view.stamp;
        overflow_used = failure = claimed = 0;
    }
    std::multiset<std::uint32_t> contents(CellCoord cell) const {
        const Compacted c = compacted(ids.size());
        EXPECT_EQ(c.failure, 0u);
        EveryEntry collect;
        grid_for_each_in_cell(c.view, cell, 0u, any_object, everywhere, 0u, collect);
        return collect.found;
    }
};

TEST(GridPlan, CountsEveryEntryAndBoundsTheOccupiedCellsInAnyOrder) {
    // Boxes of three sizes along a walk (neighbours share cells, as in spatial order), then the
    // same boxes shuffled: the bound on the occupied cells must hold whatever the order.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> step(-0.1f, 0.1f), unit(0.0f, 1.0f);
    std::vector<TetInfo> walk;
    vec3 at{5.0f, 5.0f, 5.0f};
    for (int i = 0; i < 3000; ++i) {
        at = at + vec3{step(rng), step(rng), step(rng)};
        const float size = (i / 100) % 3 == 0 ? 0.25f : (i / 100) % 3 == 1 ? 0.6f : 1.7f;
        const vec3 extent{size * (0.5f + 0.5f * unit(rng)), size * 0.7f, size * unit(rng)};
        walk.push_back(TetInfo{Aabb{at, at + extent}, size, 0});
    }
    std::vector<TetInfo> shuffled = walk;
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    const GridParams params{{0.0f, 0.0f, 0.0f}, 0.25f, 4.0f, 4};
    for (std::vector<TetInfo>* infos : {&walk, &shuffled}) {
        SceneView scene{};
        scene.info = infos->data();
        scene.tet_count = static_cast<std::uint32_t>(infos->size());
        unsigned long long entries[max_grid_layers] = {}, cells[max_grid_layers] = {};
        std::uint32_t mask = 0;
        const std::uint32_t chunk = 64;
        const GridPlanKernel plan{scene, &params, chunk, entries, cells, &mask};
        for (std::uint64_t c = 0; c * chunk < infos->size(); ++c) plan(c);

        std::set<std::tuple<int, std::uint32_t, std::uint32_t, std::uint32_t>> occupied[max_grid_layers];
        unsigned long long expected_entries[max_grid_layers] = {};
        for (const TetInfo& info : *infos) {
            const CellRange r = cell_range(params, info.box, info.layer);
            for (std::uint32_t z = r.lo[2]; z <= r.hi[2]; ++z)
                for (std::uint32_t y = r.lo[1]; y <= r.hi[1]; ++y)
                    for (std::uint32_t x = r.lo[0]; x <= r.hi[0]; ++x) {
                        occupied[info.layer].insert({info.layer, x, y, z});
                        ++expected_entries[info.layer];
                    }
        }
        EXPECT_EQ(mask, 0b1101u); // sizes 0.25, 0.6 and 1.7: layers 0, 2 and 3
        for (int layer = 0; layer < max_grid_layers; ++layer) {
            EXPECT_EQ(entries[layer], expected_entries[layer]) << "layer " << layer;
            EXPECT_GE(cells[layer], occupied[layer].size()) << "layer " << layer;
            EXPECT_LE(cells[layer], entries[layer]) << "layer " << layer;
        }
        if (infos == &walk) { // neighbours share cells: the bound is far below the entries
            unsigned long long total_entries = 0, total_cells = 0;
            for (int layer = 0; layer < max_grid_layers; ++layer) {
                total_entries += entries[layer];
                total_cells += cells[layer];
            }
            EXPECT_LT(2 * total_cells, total_entries);
        }
    }
}

/// One self-colliding object of tets, four consecutive corners each, sized on `threads` threads as the
/// pipeline's first stage does (TetBoundsKernel, TetSizeKernel). Holds what its SceneView points to.
struct SizedTets {
    std::vector<vec3> positions;
    std::vector<TetIndices> tets;
    std::vector<std::uint32_t> objects;
    std::vector<TetInfo> infos;
    std::vector<TetPlanes> planes;
    const std::uint8_t self = 1;
    const std::uint32_t checked = object_bit(0);
    const Aabb everywhere_box{{-1e9f, -1e9f, -1e9f}, {1e9f, 1e9f, 1e9f}};
    std::uint32_t min_size = float_to_ordered(INFINITY), max_size = float_to_ordered(0.0f);
    std::uint32_t min_upper = float_to_ordered(INFINITY), max_lower = float_to_ordered(0.0f);
    std::vector<std::uint32_t> spacing = std::vector<std::uint32_t>(float_octaves, 0u);
    std::uint32_t count;
    SceneView scene;

    SizedTets(std::vector<vec3> corners, int threads)
        : positions(std::move(corners)), count(static_cast<std::uint32_t>(positions.size() / 4)) {
        for (std::uint32_t t = 0; t < count; ++t) tets.push_back(TetIndices{{4 * t, 4 * t + 1, 4 * t + 2, 4 * t + 3}});
        objects.assign(count, 0u);
        infos.resize(count);
        planes.resize(count);
        scene = SceneView{positions.data(), tets.data(), objects.data(), infos.data(), planes.data(), nullptr, &self,
                          &checked, &everywhere_box, count, 1, nullptr, nullptr};
        DetectorOptions options;
        options.threads = threads;
        const CpuExec exec(options);
        exec.for_each(count, TetBoundsKernel{scene});
        exec.for_each(count, TetSizeKernel{scene, &min_size, &max_size, &min_upper, &max_lower, spacing.data()});
    }
    SizedTets(const SizedTets&) = delete;
};

TEST(GridPlan, PutsEveryTetOnItsSpheresLayerThoughSizingLeavesMostSpheresUncomputed) {
    // Tets of sizes over six octaves, some flat or needles, sized on two threads as the pipeline does.
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const std::uint32_t count = 20000;
    std::vector<vec3> positions;
    for (std::uint32_t t = 0; t < count; ++t) {
        const float size = std::exp2(6.0f * unit(rng));
        const vec3 at{100.0f * unit(rng), 100.0f * unit(rng), 100.0f * unit(rng)};
        for (int k = 0; k < 4; ++k) {
            vec3 q{unit(rng), unit(rng), unit(rng)};
            if (t % 7 == 1) q.z *= 0.01f;
            if (t % 7 == 2) q.x *= 0.01f, q.y *= 0.01f;
            positions.push_back(at + q * size);
        }
    }
    SizedTets sized(std::move(positions), 2);
    const SceneView& scene = sized.scene;
    const std::vector<TetInfo>& infos = sized.infos;
    const std::uint32_t min_size = sized.min_size, max_size = sized.max_size;
    EXPECT_EQ(std::accumulate(sized.spacing.begin(), sized.spacing.end(), 0u), count / spacing_sample); // tets 1, 9, 17, ...
    std::uint32_t left = 0;
    float dmin = INFINITY, dmax = 0.0f;
    for (std::uint32_t t = 0; t < count; ++t) {
        left += infos[t].diameter < 0.0f ? 1u : 0u;
        vec3 v[4];
        load_tet(scene, t, v);
        const float d = enclosing_sphere_diameter(v);
        dmin = std::min(dmin, d);
        dmax = std::max(dmax, d);
    }
    EXPECT_GT(left, count / 2) << "most spheres are left to the plan";
    EXPECT_EQ(ordered_to_float(min_size), dmin); // the grid's geometry comes from the exact extremes
    EXPECT_EQ(ordered_to_float(max_size), dmax);
    const OrderedBox region{{float_to_ordered(0.0f), float_to_ordered(0.0f), float_to_ordered(0.0f)},
                            {float_to_ordered(200.0f), float_to_ordered(200.0f), float_to_ordered(200.0f)}};
    GridParams params{};
    // No spacing counted: c0 is the smallest size (these tets lie far apart; see the spacing test).
    const std::vector<std::uint32_t> no_spacing(float_octaves, 0u);
    GridParamsKernel{&min_size, &max_size, no_spacing.data(), &region, &params, CpuTuning::grid_cell_spacings}(0);
    EXPECT_EQ(params.cell_size0, dmin);
    unsigned long long entries[max_grid_layers] = {}, cells[max_grid_layers] = {};
    std::uint32_t mask = 0;
    const std::uint32_t chunk = 64;
    DetectorOptions two_threads;
    two_threads.threads = 2;
    const CpuExec exec(two_threads);
    exec.for_each((count + chunk - 1) / chunk, GridPlanKernel{scene, &params, chunk, entries, cells, &mask});
    for (std::uint32_t t = 0; t < count; ++t) {
        vec3 v[4];
        load_tet(scene, t, v);
        ASSERT_EQ(infos[t].layer, layer_of(params, enclosing_sphere_diameter(v))) << "tet " << t;
    }
}

/// The grid's c0 for regular tets of edge `edge` on a row along x, one every `pitch`, as the
/// pipeline's sizing kernels choose it with cells of at least `cell_spacings` spacings.
float cell_size0_of_row(float edge, float pitch, std::uint32_t count, float cell_spacings) {
    std::vector<vec3> positions;
    for (std::uint32_t t = 0; t < count; ++t) {
        const vec3 at{pitch * static_cast<float>(t), 0.0f, 0.0f};
        for (const vec3& corner : {vec3{0, 0, 0}, vec3{1, 0, 0}, vec3{0.5f, 0.866f, 0}, vec3{0.5f, 0.289f, 0.816f}})
            positions.push_back(at + corner * edge);
    }
    const SizedTets sized(std::move(positions), 1);
    const OrderedBox region{{float_to_ordered(0.0f), float_to_ordered(0.0f), float_to_ordered(0.0f)},
                            {float_to_ordered(pitch * static_cast<float>(count)), float_to_ordered(4 * edge), float_to_ordered(4 * edge)}};
    GridParams params{};
    GridParamsKernel{&sized.min_size, &sized.max_size, sized.spacing.data(), &region, &params, cell_spacings}(0);
    return params.cell_size0;
}

TEST(ObjectCulling, AnObjectMeetsTheOthersItIsCheckedAgainstWhereTheirBoxesOverlapIt) {
    // B and C overlap A near x = 10; D overlaps A near x = 0 but is not checked against it; E is apart;
    // F overlaps A but holds no tets. A's meeting box holds the two overlaps with B and C only.
    const std::vector<Aabb> boxes = {{{0, 0, 0}, {10, 10, 10}}, {{9, 0, 0}, {12, 2, 2}}, {{8, 1, 1}, {9.5f, 3, 2}},
                                     {{-1, 4, 4}, {1, 6, 6}},   {{20, 0, 0}, {21, 1, 1}}, {{0, 0, 0}, {10, 10, 10}}};
    const std::uint32_t n = 6;
    const std::vector<std::uint32_t> tet_begin = {0, 5, 6, 7, 8, 9, 9};
    std::vector<std::uint8_t> enabled(n * n, 1), active(n * n);
    enabled[0 * n + 3] = enabled[3 * n + 0] = 0;
    std::vector<std::uint32_t> checked(n);
    std::vector<Aabb> meeting(n);
    OrderedBox region{};
    unsigned long long involved = 0;
    const CpuExec exec(DetectorOptions{});
    exec.for_each(n, ObjectCullingKernel{enabled.data(), active.data(), checked.data(), boxes.data(), meeting.data(),
                                         tet_begin.data(), n, &region, &involved});
    const auto same = [](const Aabb& a, const Aabb& b) {
        return a.lo.x == b.lo.x && a.lo.y == b.lo.y && a.lo.z == b.lo.z && a.hi.x == b.hi.x && a.hi.y == b.hi.y &&
               a.hi.z == b.hi.z;
    };
    EXPECT_TRUE(same(meeting[0], Aabb{{8, 0, 0}, {10, 3, 2}}));
    EXPECT_TRUE(same(meeting[1], Aabb{{9, 0, 0}, {10, 2, 2}})); // A and C
    EXPECT_FALSE(boxes_overlap(Aabb{{0, 4.5f, 4.5f}, {0.5f, 5, 5}}, meeting[0])) << "where only D reaches";
    EXPECT_FALSE(boxes_overlap(meeting[4], meeting[4])) << "E meets nothing: its meeting box is empty";
    EXPECT_FALSE(boxes_overlap(meeting[5], meeting[5])) << "F holds no tets";
    EXPECT_EQ(active[0 * n + 3], 0);
    EXPECT_EQ(active[0 * n + 5], 0);
    EXPECT_EQ(active[0 * n + 1], 1);
}

TEST(GridParams, CellsSpanAFewOfTheTetsSpacings) {
    static_assert(CpuTuning::grid_cell_spacings == 4.0f, "the sizes below are four spacings");
    const float four = CpuTuning::grid_cell_spacings;
    // Tets far apart: c0 is four times their spacing rounded up to a power of two, and every tet
    // shares layer 0.
    EXPECT_EQ(cell_size0_of_row(0.01f, 3.0f, 1000, four), 16.0f);
    EXPECT_EQ(cell_size0_of_row(0.01f, 0.3f, 1000, four), 2.0f);
    // Tets overlapping their neighbours (as a mesh's tets touch theirs): a spacing of 0.001 counts as
    // at most 0.00195, and four of those stay below the tets' sphere (0.0122), which is c0.
    const float regular_sphere = 0.01f * std::sqrt(1.5f);
    EXPECT_NEAR(cell_size0_of_row(0.01f, 0.001f, 1000, four), regular_sphere, 1e-4f);
    // A spacing of 0.004 counts as up to 0.0078, four of which exceed the sphere: layer 0's cells grow
    // to them.
    EXPECT_EQ(cell_size0_of_row(0.01f, 0.004f, 1000, four), 0.03125f);
    // Too few tets to sample a spacing: the smallest sphere.
    EXPECT_NEAR(cell_size0_of_row(0.01f, 3.0f, 1, four), regular_sphere, 1e-4f);
}

TEST(GridParams, CellsOfOneSpacingAreTheSpacingOrTheSmallestSphere) {
    // The GPU's cells (CudaTuning::grid_cell_spacings) span one spacing: the spacing rounded up to a
    // power of two where the tets lie apart, the smallest sphere where the spacing is below it.
    static_assert(CudaTuning::grid_cell_spacings == 1.0f, "the sizes below are one spacing");
    const float one = CudaTuning::grid_cell_spacings;
    EXPECT_EQ(cell_size0_of_row(0.01f, 3.0f, 1000, one), 4.0f);
    EXPECT_EQ(cell_size0_of_row(0.01f, 0.3f, 1000, one), 0.5f);
    const float regular_sphere = 0.01f * std::sqrt(1.5f);
    EXPECT_NEAR(cell_size0_of_row(0.01f, 0.004f, 1000, one), regular_sphere, 1e-4f);
}

TEST(GridParams, MedianSpacingIsTheMiddleSamplesBinsUpperEnd) {
    std::vector<std::uint32_t> octaves(float_octaves, 0u);
    EXPECT_EQ(median_spacing(octaves.data()), 0.0f);
    octaves[float_octave(0.3f)] = 2; // [0.25, 0.5)
    octaves[float_octave(3.0f)] = 3; // [2, 4)
    EXPECT_EQ(median_spacing(octaves.data()), 4.0f);
    octaves[float_octave(0.3f)] = 3;
    EXPECT_EQ(median_spacing(octaves.data()), 0.5f);
    // Infinite or overflowing spacings never make the median.
    std::vector<std::uint32_t> unbounded(float_octaves, 0u);
    unbounded[float_octave(INFINITY)] = 5;
    EXPECT_EQ(median_spacing(unbounded.data()), 0.0f);
}

TEST(BucketTable, ConcurrentInsertsChainOverflowBucketsAndLoseNothing) {
    TestTable table(64, 4, 4096, 32, HashFunction::fnv1a);
    DetectorOptions two_threads;
    two_threads.threads = 2;
    const CpuExec exec(two_threads);
    const std::uint32_t ids = 5000, cells = 7;
    exec.for_each(ids, [&](std::uint64_t i) {
        grid_insert(table.view, CellCoord{static_cast<std::uint32_t>(i % cells), 1, 2, 0}, static_cast<std::uint32_t>(i), 0u);
    });
    ASSERT_EQ(table.failure, 0u);
    EXPECT_EQ(table.claimed, cells);
    std::set<std::uint32_t> main_buckets;
    for (std::uint32_t c = 0; c < cells; ++c) main_buckets.insert(grid_find(table.view, CellCoord{c, 1, 2, 0}));
    EXPECT_EQ(std::set<std::uint32_t>(table.claimed_slots.begin(), table.claimed_slots.begin() + cells), main_buckets);
    EXPECT_GT(table.overflow_used, 1000u);
    for (std::uint32_t c = 0; c < cells; ++c) {
        std::multiset<std::uint32_t> expected;
        for (std::uint32_t i = c; i < ids; i += cells) expected.insert(i);
        EXPECT_EQ(table.contents(CellCoord{c, 1, 2, 0}), expected) << "cell " << c;
    }
    EXPECT_TRUE(table.contents(CellCoord{99, 1, 2, 0}).empty());
}

TEST(BucketTable, RecordsTheCellsInTheOrderTheyWereClaimed) {
    TestTable table(64, 4, 16, 32, HashFunction::djb2);
    const CellCoord cells[] = {{5, 1, 0, 0}, {2, 7, 1, 0}, {5, 1, 0, 0}, {0, 0, 3, 1}, {2, 7, 1, 0}};
    std::uint32_t id = 0;
    for (const CellCoord& cell : cells) ASSERT_NE(grid_insert(table.view, cell, id++, 0u), no_bucket);
    ASSERT_EQ(table.claimed, 3u);
    EXPECT_EQ(table.claimed_slots[0], grid_find(table.view, cells[0]));
    EXPECT_EQ(table.claimed_slots[1], grid_find(table.view, cells[1]));
    EXPECT_EQ(table.claimed_slots[2], grid_find(table.view, cells[3]));
    table.next_frame(); // a new frame claims anew, in its own order
    ASSERT_NE(grid_insert(table.view, cells[3], 0u, 0u), no_bucket);
    ASSERT_EQ(table.claimed, 1u);
    EXPECT_EQ(table.claimed_slots[0], grid_find(table.view, cells[3]));
}

TEST(BucketTable, ReportsAFullTableAndAnExhaustedPool) {
    TestTable full(4, 8, 16, 4, HashFunction::djb2);
    for (std::uint32_t c = 0; c < 16; ++c) grid_insert(full.view, CellCoord{c, 0, 0, 0}, c, 0u);
    EXPECT_TRUE(full.failure & grid_table_full);

    TestTable pool(16, 2, 1, 8, HashFunction::djb2);
    for (std::uint32_t i = 0; i < 10; ++i) grid_insert(pool.view, CellCoord{3, 3, 3, 0}, i, 0u);
    EXPECT_TRUE(pool.failure & grid_overflow_pool_full);
}

TEST(BucketTable, ANewStampEmptiesTheTableWithoutClearing) {
    TestTable table(32, 4, 8, 8, HashFunction::morton);
    grid_insert(table.view, CellCoord{1, 2, 3, 0}, 42, 0u);
    EXPECT_EQ(table.contents(CellCoord{1, 2, 3, 0}).count(42), 1u);
    table.next_frame();
    EXPECT_TRUE(table.contents(CellCoord{1, 2, 3, 0}).empty());
    grid_insert(table.view, CellCoord{1, 2, 3, 0}, 7, 0u);
    EXPECT_EQ(table.contents(CellCoord{1, 2, 3, 0}), std::multiset<std::uint32_t>{7});
}

TEST(BucketTable, CompactionThatDoesNotFitSaysSoAndLeavesEmptyCells) {
    TestTable table(64, 4, 64, 32, HashFunction::djb2);
    for (std::uint32_t i = 0; i < 30; ++i) grid_insert(table.view, CellCoord{i % 3, 0, 0, 0}, i, 0u);
    const auto exact = table.compacted(30);
    EXPECT_EQ(exact.failure, 0u);
    EXPECT_EQ(exact.used, 30u);
    const auto short_of_room = table.compacted(25);
    EXPECT_EQ(short_of_room.failure, static_cast<std::uint32_t>(grid_entries_full));
    EveryEntry readable;
    for (std::uint32_t x = 0; x < 3; ++x) grid_for_each_in_cell(short_of_room.view, CellCoord{x, 0, 0, 0}, 0u, any_object, everywhere, 0u, readable);
    EXPECT_EQ(readable.found.size(), 20u); // two cells of ten fit; the third reads as empty
    for (std::uint32_t id : readable.found) EXPECT_LT(id, 30u);
}

TEST(BucketTable, CompactedCellsListTheirIdsInOrderAndSkipTheSmallerOnes) {
    // Ids inserted out of order across a chain of several buckets, as concurrent threads would.
    TestTable table(64, 4, 64, 32, HashFunction::fnv1a);
    std::vector<std::uint32_t> ids(37);
    for (std::uint32_t i = 0; i < ids.size(); ++i) ids[i] = 3 * i + 1;
    std::shuffle(ids.begin(), ids.end(), std::mt19937(11));
    const CellCoord cell{2, 0, 5, 1};
    for (std::uint32_t id : ids) ASSERT_NE(grid_insert(table.view, cell, id, 0u), no_bucket);
    const auto c = table.compacted(ids.size());
    ASSERT_EQ(c.failure, 0u);
    struct InOrder {
        std::vector<std::uint32_t> seen;
        void operator()(const GridEntry& e) { seen.push_back(e.id()); }
    };
    std::sort(ids.begin(), ids.end());
    for (std::uint32_t first_id : {0u, 1u, 2u, 50u, 52u, 109u, 110u, 1000u}) {
        InOrder visit;
        grid_for_each_in_cell(c.view, cell, first_id, any_object, everywhere, 0u, visit);
        const std::vector<std::uint32_t> expected(std::lower_bound(ids.begin(), ids.end(), first_id), ids.end());
        EXPECT_EQ(visit.seen, expected) << "first_id " << first_id;
    }
}

TEST(BucketTable, QueriesVisitExactlyTheEntriesWhoseBoxesOverlapTheirsAndBlocksBoundTheirEntries) {
    // Two cells whose lists interleave in memory with blocks; entry i's box spans x in [i, i + 0.5].
    TestTable table(64, 4, 64, 32, HashFunction::djb2);
    const CellCoord row{1, 1, 1, 0}, other{9, 9, 9, 0};
    for (std::uint32_t i = 0; i < 60; ++i) ASSERT_NE(grid_insert(table.view, row, i, 0u), no_bucket);
    for (std::uint32_t i = 100; i < 105; ++i) ASSERT_NE(grid_insert(table.view, other, i, 0u), no_bucket);
    const auto c = table.compacted(65, [](std::uint32_t id) {
        const float x = static_cast<float>(id);
        return GridEntry{Aabb{{x, 0.0f, 0.0f}, {x + 0.5f, 1.0f, 1.0f}}, id, id};
    });
    ASSERT_EQ(c.failure, 0u);
    // Each block's bound is the union of its entries' boxes (what lets a query skip it unread).
    for (std::uint32_t block = 0; block < c.blocks; ++block) {
        Aabb expected{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
        for (std::uint32_t k = block * entry_block; k < std::min(c.used, (block + 1) * entry_block); ++k) {
            const GridEntry e = load_entry(c.view, k);
            expected.lo = min_v(expected.lo, e.box.lo);
            expected.hi = max_v(expected.hi, e.box.hi);
        }
        const Aabb bound = block_bound(c.view, block);
        EXPECT_EQ(bound.lo.x, expected.lo.x) << block;
        EXPECT_EQ(bound.hi.x, expected.hi.x) << block;
        EXPECT_EQ(bound.hi.y, expected.hi.y) << block;
    }
    for (std::uint32_t first_id : {0u, 11u, 30u}) {
        const Aabb query{{10.2f, 0.5f, 0.5f}, {21.7f, 0.6f, 0.6f}};
        SeenIds seen;
        grid_for_each_in_cell(c.view, row, first_id, any_object, query, 0u, seen);
        std::vector<std::uint32_t> expected;
        for (std::uint32_t i = std::max(first_id, 10u); i <= 21; ++i) expected.push_back(i);
        EXPECT_EQ(seen.ids, expected) << first_id;
    }
    // Boxes that only touch the query's count (closed boxes), in every lane of a block.
    for (std::uint32_t i = 0; i < 60; ++i) {
        const float x = static_cast<float>(i);
        const Aabb touching{{x + 0.5f, 1.0f, 1.0f}, {x + 0.75f, 2.0f, 2.0f}};
        SeenIds seen;
        grid_for_each_in_cell(c.view, row, 0u, any_object, touching, 0u, seen);
        EXPECT_EQ(seen.ids, std::vector<std::uint32_t>{i}) << i;
    }
    SeenIds everything;
    grid_for_each_in_cell(c.view, row, 0u, any_object, everywhere, 0u, everything);
    EXPECT_EQ(everything.ids.size(), 60u);
}

/// One cell's list of n entries, entry k id k with its box x in [k, k + 0.5] (y and z in [0, 1]).
TestTable::Compacted list_along_x(TestTable& table, std::uint32_t n) {
    for (std::uint32_t i = 0; i < n; ++i) EXPECT_NE(grid_insert(table.view, CellCoord{2, 3, 4, 0}, i, 0u), no_bucket);
    return table.compacted(n, [](std::uint32_t id) {
        const float x = static_cast<float>(id);
        return GridEntry{Aabb{{x, 0.0f, 0.0f}, {x + 0.5f, 1.0f, 1.0f}}, id, id};
    });
}

TEST(BucketTable, AScanVisitsExactlyTheMatchingEntriesOfItsRangeWhereverTheRangeStartsAndEnds) {
    // One list of 150 entries (19 blocks, three groups of block bounds), list_along_x. Ranges starting
    // and ending inside a block, a group or at either edge.
    constexpr std::uint32_t n = 150;
    TestTable table(64, 4, 64, 32, HashFunction::djb2);
    const auto c = list_along_x(table, n);
    ASSERT_EQ(c.failure, 0u);
    ASSERT_EQ(c.used, n);
    const float windows[][2] = {{-1.0f, 200.0f}, {10.2f, 21.7f}, {60.0f, 75.0f}, {130.6f, 140.4f}, {63.6f, 63.9f}};
    for (const auto& window : windows)
        for (std::uint32_t begin = 0; begin < n; begin += 3)
            for (std::uint32_t end = begin + 1; end <= n; end += 5) {
                const Aabb query{{window[0], 0.5f, 0.5f}, {window[1], 0.6f, 0.6f}};
                SeenIds seen;
                grid_for_each_in_entries(c.view, begin, end, query, any_object, 0u, seen);
                std::vector<std::uint32_t> expected;
                for (std::uint32_t k = begin; k < end; ++k)
                    if (static_cast<float>(k) + 0.5f >= window[0] && static_cast<float>(k) <= window[1]) expected.push_back(k);
                ASSERT_EQ(seen.ids, expected) << "window " << window[0] << " entries " << begin << "-" << end;
            }
}

TEST(BucketTable, AScanSharedByPartsReadsEachBlockInExactlyOnePart) {
    // One list of 150 entries (19 blocks, three groups), list_along_x; the scans of a range by 1, 2, 4
    // and 8 parts (group_blocks_of_part) together visit what the whole scan visits, each entry once, and
    // part p only entries of the blocks i of a group with i % parts == p.
    EXPECT_EQ(group_blocks_of_part(0, 1), all_group_blocks);
    EXPECT_EQ(group_blocks_of_part(1, 4), 0x22u);
    constexpr std::uint32_t n = 150;
    TestTable table(64, 4, 64, 32, HashFunction::djb2);
    const auto c = list_along_x(table, n);
    ASSERT_EQ(c.failure, 0u);
    const Aabb query{{10.2f, 0.5f, 0.5f}, {141.7f, 0.6f, 0.6f}};
    for (const auto& [begin, end] : {std::pair{0u, n}, std::pair{5u, 71u}, std::pair{63u, 66u}, std::pair{17u, 140u}}) {
        SeenIds whole;
        grid_for_each_in_entries(c.view, begin, end, query, any_object, 0u, whole);
        for (std::uint32_t parts : {1u, 2u, 4u, 8u}) {
            std::vector<std::uint32_t> together;
            for (std::uint32_t part = 0; part < parts; ++part) {
                SeenIds seen;
                grid_for_each_in_entries(c.view, begin, end, query, any_object, 0u, seen, group_blocks_of_part(part, parts));
                for (std::uint32_t id : seen.ids) EXPECT_EQ(id / entry_block % parts, part) << id;
                together.insert(together.end(), seen.ids.begin(), seen.ids.end());
            }
            std::sort(together.begin(), together.end());
            EXPECT_EQ(together, whole.ids) << parts << " parts, entries " << begin << "-" << end;
        }
    }
}

TEST(BucketTable, QueriesPassOnlyTheEntriesWhoseBoxesStartAlongTheRequiredAxes) {
    // 70 ids across a chain of buckets, id i starting along the axes i % 8; every subset asked for.
    TestTable table(64, 4, 64, 32, HashFunction::morton);
    const CellCoord cell{3, 1, 4, 0};
    for (std::uint32_t i = 0; i < 70; ++i) ASSERT_NE(grid_insert(table.view, cell, 5 * i, i % 8u), no_bucket);
    const auto c = table.compacted(70);
    ASSERT_EQ(c.failure, 0u);
    for (std::uint32_t required = 0; required < 8; ++required)
        for (std::uint32_t first_id : {0u, 7u, 100u}) {
            SeenIds seen;
            grid_for_each_in_cell(c.view, cell, first_id, any_object, everywhere, required, seen);
            std::vector<std::uint32_t> expected;
            for (std::uint32_t i = 0; i < 70; ++i)
                if (5 * i >= first_id && ((i % 8u) & required) == required) expected.push_back(5 * i);
            EXPECT_EQ(seen.ids, expected) << "required " << required << ", first_id " << first_id;
        }
}

TEST(BucketTable, InsertsStartAtTheChainsLastBucketAndLeaveTheFullOnesAlone) {
    // 50 ids into one cell of buckets of 4: 13 buckets, each filled to exactly its capacity (an insert
    // that added to every full bucket's count on its way would leave the main bucket counting 50).
    TestTable table(64, 4, 64, 32, HashFunction::simple);
    const CellCoord cell{6, 6, 6, 2};
    std::uint32_t main = no_bucket;
    for (std::uint32_t i = 0; i < 50; ++i) {
        main = grid_insert(table.view, cell, i, 0u);
        ASSERT_NE(main, no_bucket);
    }
    std::vector<std::uint32_t> counts;
    for (std::uint32_t b = main; b != no_bucket; b = table.headers[b].next) counts.push_back(table.headers[b].count);
    std::vector<std::uint32_t> expected(12, 4u);
    expected.push_back(2u);
    EXPECT_EQ(counts, expected);
    EXPECT_EQ(table.headers[main].tail, table.view.slot_count + 11u); // the 12th pool bucket is the last
    std::multiset<std::uint32_t> all;
    for (std::uint32_t i = 0; i < 50; ++i) all.insert(i);
    EXPECT_EQ(table.contents(cell), all);
}

TEST(BucketTable, OwnCellRowsStartWhereTheLookupAndBinarySearchAfterTheTetDo) {
    // 40 tets whose ranges of 2 x 2 x 1 cells overlap their neighbours', inserted in a shuffled order as
    // populating inserts them (start bits included); each records its main buckets in its row, and
    // compacting records where its entries lie.
    TestTable table(256, 4, 256, 32, HashFunction::djb2);
    std::vector<OwnCells> rows(40);
    table.view.own_cells = rows.data();
    const auto range_of = [](std::uint32_t id) { return CellRange{{id / 3, id % 2, 5}, {id / 3 + 1, id % 2 + 1, 5}}; };
    std::vector<std::uint32_t> order(40);
    std::iota(order.begin(), order.end(), 0u);
    std::shuffle(order.begin(), order.end(), std::mt19937(5));
    for (std::uint32_t id : order) {
        const CellRange r = range_of(id);
        ASSERT_TRUE(has_own_cells(r));
        for (std::uint32_t y = r.lo[1]; y <= r.hi[1]; ++y)
            for (std::uint32_t x = r.lo[0]; x <= r.hi[0]; ++x) {
                const std::uint32_t bucket = grid_insert(table.view, make_cell(x, y, 5, 0), id, first_cell_axes(r, x, y, 5));
                ASSERT_NE(bucket, no_bucket);
                rows[id].bucket[own_cell_index(r, x, y, 5)] = bucket;
            }
    }
    const auto c = table.compacted(160);
    ASSERT_EQ(c.failure, 0u);
    std::size_t visited = 0;
    for (std::uint32_t id = 0; id < 40; ++id) {
        const CellRange r = range_of(id);
        for (std::uint32_t y = r.lo[1]; y <= r.hi[1]; ++y)
            for (std::uint32_t x = r.lo[0]; x <= r.hi[0]; ++x)
                for (std::uint32_t required : {0u, 1u, 3u, 7u}) {
                    SeenIds by_row, by_lookup;
                    grid_for_each_after_own_entry(c.view, id, own_cell_index(r, x, y, 5), any_object, everywhere, required, by_row);
                    grid_for_each_in_cell(c.view, make_cell(x, y, 5, 0), id + 1, any_object, everywhere, required, by_lookup);
                    EXPECT_EQ(by_row.ids, by_lookup.ids) << "tet " << id << " cell " << x << " " << y << " required " << required;
                    visited += by_row.ids.size();
                }
    }
    EXPECT_GT(visited, 200u);
    // Under a later frame's stamp every header of this frame is stale, though it still holds its list:
    // the rows (as a frame whose grid failed before populating would find them) read nothing.
    GridView later = c.view;
    ++later.stamp;
    for (std::uint32_t id = 0; id < 40; ++id)
        for (std::uint32_t index = 0; index < 4; ++index) {
            SeenIds stale;
            grid_for_each_after_own_entry(later, id, index, any_object, everywhere, 0u, stale);
            EXPECT_TRUE(stale.ids.empty()) << id << " " << index;
        }
}

TEST(BucketTable, CompactedEntriesKeepTheirStartBitsAndSortByIdAlone) {
    TestTable table(64, 4, 64, 32, HashFunction::djb2);
    const CellCoord cell{4, 5, 6, 2};
    std::vector<std::uint32_t> ids(40);
    for (std::uint32_t i = 0; i < ids.size(); ++i) ids[i] = grid_id_mask - 2 * i; // the largest ids there are
    std::shuffle(ids.begin(), ids.end(), std::mt19937(3));
    for (std::uint32_t id : ids) ASSERT_NE(grid_insert(table.view, cell, id, id % 8u), no_bucket);
    const auto c = table.compacted(ids.size());
    ASSERT_EQ(c.failure, 0u);
    struct InOrder {
        std::vector<std::uint32_t> seen;
        void operator()(const GridEntry& e) {
            EXPECT_EQ(e.starts(), e.id() % 8u) << e.id();
            EXPECT_EQ(e.object, e.id());
            seen.push_back(e.id());
        }
    };
    InOrder visit;
    grid_for_each_in_cell(c.view, cell, grid_id_mask - 20, any_object, everywhere, 0u, visit);
    std::sort(ids.begin(), ids.end());
    EXPECT_EQ(visit.seen, std::vector<std::uint32_t>(std::lower_bound(ids.begin(), ids.end(), grid_id_mask - 20), ids.end()));
}

TEST(BucketTable, ACellHoldingNoneOfTheObjectsAskedForIsSkippedUnread) {
    // Cell `mixed` holds tets of objects 3 and 5, cell `alone` only of object 3; object_bit wraps at
    // 32, so object 35 shares object 3's bit and reads the cell for nothing (the visitor's object check
    // rejects such entries), which is allowed; a cell that may hold a wanted object is never skipped.
    TestTable table(64, 4, 64, 32, HashFunction::djb2);
    const CellCoord mixed{2, 3, 4, 1}, alone{7, 3, 4, 1};
    for (std::uint32_t i = 0; i < 12; ++i) ASSERT_NE(grid_insert(table.view, mixed, i, 0u), no_bucket);
    for (std::uint32_t i = 20; i < 26; ++i) ASSERT_NE(grid_insert(table.view, alone, i, 0u), no_bucket);
    const auto c = table.compacted(18, [](std::uint32_t id) { return GridEntry{Aabb{}, id, id < 6 ? 5u : 3u}; });
    ASSERT_EQ(c.failure, 0u);
    struct Count {
        std::uint32_t n = 0;
        void operator()(const GridEntry&) { ++n; }
    };
    const auto visited = [&](CellCoord cell, std::uint32_t objects) {
        Count count;
        grid_for_each_in_cell(c.view, cell, 0u, objects, everywhere, 0u, count);
        return count.n;
    };
    // The lists lie in claim order: mixed's ids 0-11 in entries 0-11, so its first block (ids 0-7) holds
    // both objects and its second (ids 8-11, then alone's) only object 3, which a query for object 5
    // skips (AScanSkipsTheBlocksHoldingNoneOfTheObjectsAskedFor).
    EXPECT_EQ(visited(mixed, object_bit(5)), 8u);
    EXPECT_EQ(visited(mixed, object_bit(3)), 12u);
    EXPECT_EQ(visited(mixed, object_bit(7)), 0u);
    EXPECT_EQ(visited(alone, object_bit(5)), 0u);
    EXPECT_EQ(visited(alone, object_bit(5) | object_bit(3)), 6u);
    EXPECT_EQ(visited(alone, object_bit(35)), 6u);
    EXPECT_EQ(visited(alone, any_object), 6u);
}

TEST(BucketTable, AScanSkipsTheBlocksHoldingNoneOfTheObjectsAskedFor) {
    // One list of 150 entries (list_along_x's boxes) whose objects come in runs of random length, as a
    // list of several objects' tets does (an object's tets are consecutive ids), with a few strays,
    // objects up to 40 so that bits wrap (object_bit). Every entry of the range whose box overlaps the
    // query is visited exactly when its block holds an entry of a wanted object; so every overlapping
    // entry of a wanted object is.
    constexpr std::uint32_t n = 150;
    std::mt19937 rng(29);
    const auto pick = [&rng](std::uint32_t below) { return static_cast<std::uint32_t>(rng() % below); };
    std::vector<std::uint32_t> object_of(n);
    for (std::uint32_t k = 0, object = 0; k < n; ++k) {
        if (pick(9) == 0) object = pick(41);
        object_of[k] = pick(23) == 0 ? pick(41) : object;
    }
    TestTable table(64, 4, 64, 32, HashFunction::djb2);
    for (std::uint32_t i = 0; i < n; ++i) ASSERT_NE(grid_insert(table.view, CellCoord{2, 3, 4, 0}, i, 0u), no_bucket);
    const auto c = table.compacted(n, [&](std::uint32_t id) {
        const float x = static_cast<float>(id);
        return GridEntry{Aabb{{x, 0.0f, 0.0f}, {x + 0.5f, 1.0f, 1.0f}}, id, object_of[id]};
    });
    ASSERT_EQ(c.failure, 0u);
    const auto block_holds = [&](std::uint32_t block, std::uint32_t objects) {
        for (std::uint32_t k = block * entry_block; k < std::min(n, (block + 1) * entry_block); ++k)
            if (object_bit(object_of[k]) & objects) return true;
        return false;
    };
    for (int trial = 0; trial < 300; ++trial) {
        const std::uint32_t begin = pick(n), end = begin + 1 + pick(n - begin);
        const float from = static_cast<float>(pick(160)) - 5.0f, to = from + static_cast<float>(pick(60));
        const std::uint32_t objects = trial % 10 == 0 ? any_object : object_bit(pick(41)) | (trial % 3 ? 0u : object_bit(pick(41)));
        const Aabb query{{from, 0.5f, 0.5f}, {to, 0.6f, 0.6f}};
        SeenIds seen;
        grid_for_each_in_entries(c.view, begin, end, query, objects, 0u, seen);
        std::vector<std::uint32_t> expected;
        for (std::uint32_t k = begin; k < end; ++k)
            if (static_cast<float>(k) + 0.5f >= from && static_cast<float>(k) <= to && block_holds(k / entry_block, objects))
                expected.push_back(k);
        ASSERT_EQ(seen.ids, expected) << "trial " << trial;
    }
}

TEST(BucketCapacity, AutomaticIsFourTimesTheMeanIdsPerCellRoundedUpToAPowerOfTwoFrom4To32) {
    EXPECT_EQ(automatic_bucket_capacity(0.0, 0.0), 4u);
    EXPECT_EQ(automatic_bucket_capacity(1000.0, 1000.0), 4u);
    EXPECT_EQ(automatic_bucket_capacity(1001.0, 1000.0), 8u);
    EXPECT_EQ(automatic_bucket_capacity(1300.0, 1000.0), 8u);   // a sparse soup: 1.3 ids per cell
    EXPECT_EQ(automatic_bucket_capacity(3500.0, 1000.0), 16u);  // armadillo at resolution 4: 3.5
    EXPECT_EQ(automatic_bucket_capacity(4001.0, 1000.0), 32u);
    EXPECT_EQ(automatic_bucket_capacity(500000.0, 1000.0), 32u); // dense cells keep the thesis's size
}

TEST(CellKey, DistinguishesLayersAndCoordinates) {
    std::set<std::uint64_t> keys;
    for (int layer = 0; layer < 3; ++layer)
        for (std::uint32_t x = 0; x < 4; ++x)
            for (std::uint32_t y = 0; y < 4; ++y)
                for (std::uint32_t z = 0; z < 4; ++z) keys.insert(cell_key(make_cell(x, y, z, layer)));
    EXPECT_EQ(keys.size(), 3u * 64u);
    EXPECT_EQ(keys.count(0), 0u);
}

} // namespace
} // namespace kdet
