// Every method must return exactly the pair set of brute force; the flags of kdet_no_pairs must equal
// the tets that appear in brute force's pairs.

#include "exec/cpu_exec.hpp"
#include "exec/tuning.hpp"
#include "near_touching.hpp"
#include "pipeline/pipeline.hpp"
#include "device_like_exec.hpp"
#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <type_traits>

namespace kdet {
namespace {

using test::error_message;
using test::load_model;
using test::moved;
using test::random_soup;

struct Outcome {
    std::vector<TetPair> pairs;
    std::vector<std::vector<std::uint8_t>> colliding;
    FrameCounts counts;
    std::size_t grid_bytes;
};

Outcome run(const std::vector<TetMesh>& meshes, bool self, DetectorOptions options) {
    Detector detector(options);
    for (const TetMesh& m : meshes) detector.set_self_collision(detector.add_object(m), self);
    const FrameResult& r = detector.detect();
    return Outcome{r.pairs, r.colliding, r.counts, r.grid_bytes};
}

DetectorOptions with_method(Method method) {
    DetectorOptions o;
    o.method = method;
    return o;
}

/// Flags implied by a pair list.
std::vector<std::vector<std::uint8_t>> flags_of(const std::vector<TetPair>& pairs,
                                                const std::vector<std::vector<std::uint8_t>>& shape) {
    auto flags = shape;
    for (auto& f : flags) std::fill(f.begin(), f.end(), 0);
    for (const TetPair& p : pairs) flags[p.object_a][p.tet_a] = flags[p.object_b][p.tet_b] = 1;
    return flags;
}

void expect_same_as_brute_force(const std::vector<TetMesh>& meshes, bool self, std::size_t min_pairs) {
    const Outcome oracle = run(meshes, self, with_method(Method::brute_force_loop));
    ASSERT_GE(oracle.pairs.size(), min_pairs);
    ASSERT_TRUE(std::is_sorted(oracle.pairs.begin(), oracle.pairs.end()));
    ASSERT_EQ(std::adjacent_find(oracle.pairs.begin(), oracle.pairs.end()), oracle.pairs.end());
    for (const TetPair& p : oracle.pairs) {
        ASSERT_TRUE(p.object_a < p.object_b || (p.object_a == p.object_b && p.tet_a < p.tet_b));
        ASSERT_TRUE(self || p.object_a != p.object_b);
    }
    for (HashFunction hash : {HashFunction::djb2, HashFunction::fnv1a, HashFunction::simple, HashFunction::morton}) {
        DetectorOptions o = with_method(Method::kdet);
        o.hash = hash;
        const Outcome found = run(meshes, self, o);
        // Candidates are not deduplicated (each pair is reported from one shared cell only), so a pair
        // written twice would show up twice here.
        EXPECT_EQ(found.pairs, oracle.pairs) << "kdet with hash " << to_string(hash);
    }
    DetectorOptions thesis_buckets = with_method(Method::kdet);
    thesis_buckets.bucket_capacity = 32;
    EXPECT_EQ(run(meshes, self, thesis_buckets).pairs, oracle.pairs) << "kdet with buckets of 32";
    const Outcome no_pairs = run(meshes, self, with_method(Method::kdet_no_pairs));
    EXPECT_TRUE(no_pairs.pairs.empty());
    EXPECT_EQ(no_pairs.colliding, flags_of(oracle.pairs, oracle.colliding));
    EXPECT_EQ(oracle.colliding, flags_of(oracle.pairs, oracle.colliding));
}

TEST(Pipeline, RandomSoupsSpanningThreeDecadesMatchBruteForce) {
    for (unsigned seed : {1u, 2u, 3u}) {
        const TetMesh a = random_soup(1500, 10.0, 3.0, seed);
        const TetMesh b = random_soup(1500, 10.0, 3.0, seed + 100);
        expect_same_as_brute_force({a, b}, false, 20);
        EXPECT_EQ(run({a, b}, false, with_method(Method::brute_force_pairs)).pairs,
                  run({a, b}, false, with_method(Method::brute_force_loop)).pairs);
    }
}

TEST(Pipeline, RandomSoupSelfCollisionMatchesBruteForce) {
    const TetMesh soup = random_soup(3000, 10.0, 3.0, 7);
    expect_same_as_brute_force({soup}, true, 20);
    EXPECT_EQ(run({soup}, true, with_method(Method::brute_force_pairs)).pairs,
              run({soup}, true, with_method(Method::brute_force_loop)).pairs);
}

TEST(Pipeline, ThreeObjectsWithSelfCollisionMatchBruteForce) {
    expect_same_as_brute_force({random_soup(800, 5.0, 2.0, 11), random_soup(900, 5.0, 2.0, 12),
                                random_soup(700, 5.0, 2.0, 13)},
                               true, 20);
}

class RealMesh : public ::testing::TestWithParam<const char*> {};

TEST_P(RealMesh, OverlappingCopyMatchesBruteForce) {
    const TetMesh mesh = load_model(GetParam());
    const double e = test::extent_of(mesh);
    expect_same_as_brute_force({mesh, moved(mesh, 0.3, 0.1 * e, 0.05 * e, 0.02 * e)}, false, 100);
}

TEST_P(RealMesh, UndeformedMeshHasNoSelfCollision) {
    const TetMesh mesh = load_model(GetParam());
    for (Method m : {Method::kdet, Method::brute_force_loop}) {
        const Outcome r = run({mesh}, true, with_method(m));
        EXPECT_TRUE(r.pairs.empty()) << to_string(m) << " found " << r.pairs.size() << " pairs";
        EXPECT_EQ(r.counts.colliding_tets, 0u);
    }
    const FrameCounts counts = run({mesh}, true, with_method(Method::kdet)).counts;
    EXPECT_GT(counts.candidates, 0u); // the grid did find neighbours
    // ... and the face-plane pre-test proved most of them separated before they were written.
    EXPECT_LT(counts.narrow_phase_candidates, counts.candidates / 2);
}

// Named after the model (Models/RealMesh.Test/bunny), so test filters can pick models by name.
INSTANTIATE_TEST_SUITE_P(Models, RealMesh, ::testing::Values("bunny.mesh", "hand.mesh", "octopus-low.mesh"),
                         [](const ::testing::TestParamInfo<const char*>& model) {
                             std::string name = model.param;
                             name = name.substr(0, name.find('.'));
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

TEST(Pipeline, FoldedBarSelfCollidesLikeBruteForce) {
    const TetMesh bar = make_box_mesh(60, 4, 4, 0.1);
    TetMesh folded = bar;
    fold_bar(bar, 2.0 * 3.14159265358979 * 1.15, folded.positions);
    expect_same_as_brute_force({folded}, true, 50);
    TetMesh gently = bar;
    fold_bar(bar, 3.14159265358979, gently.positions);
    EXPECT_TRUE(run({gently}, true, with_method(Method::kdet)).pairs.empty());
}

TEST(Pipeline, NearTouchingPairsGetEachTestsOwnAnswer) {
    // The grid methods run the face-plane pre-test before the test, brute force runs the test alone:
    // on pairs around the pre-test's margin and the tests' tolerance, the pair sets must not differ.
    const test::NearTouchingPairs pairs = test::near_touching_pairs(216, 5);
    const std::size_t count = pairs.first.tets.size() / 4;
    for (NarrowPhase narrow : test::every_narrow_phase_test()) {
        DetectorOptions brute = with_method(Method::brute_force_loop), grid = with_method(Method::kdet);
        brute.narrow_phase = grid.narrow_phase = narrow;
        const Outcome oracle = run({pairs.first, pairs.second}, false, brute);
        const Outcome found = run({pairs.first, pairs.second}, false, grid);
        EXPECT_EQ(found.pairs, oracle.pairs) << to_string(narrow);
        EXPECT_GT(oracle.pairs.size(), count / 4) << to_string(narrow);
        // Not vacuous: the pre-test proved a good part of the pairs separated.
        EXPECT_GT(found.counts.candidates - found.counts.narrow_phase_candidates, count / 10) << to_string(narrow);
        grid.method = Method::kdet_no_pairs;
        EXPECT_EQ(run({pairs.first, pairs.second}, false, grid).colliding, flags_of(oracle.pairs, oracle.colliding))
            << to_string(narrow);
    }
}

TEST(Pipeline, PairsThatOnlyAnEdgeAxisSeparatesGetEachTestsOwnAnswer) {
    // Two wedges whose nearest edges cross at a gap along their common normal, which no face axis
    // shows: sat_no_edges reports every such pair, the other tests none. The normal is turned onto each
    // slab direction (slabs.hpp), with a few spins about it, so that the slabs separate what the boxes
    // cannot: the grid methods must reject the pairs with them for every test but sat_no_edges.
    const double directions[8][3] = {{1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}, {1, 1, 0}, {1, -1, 0}, {1, 0, 1}, {1, 0, -1}};
    TetMesh first, second;
    std::size_t count = 0;
    for (const auto& direction : directions) {
        // A frame (u, w, n) with n along the direction.
        const double length = std::sqrt(direction[0] * direction[0] + direction[1] * direction[1] + direction[2] * direction[2]);
        const double n[3] = {direction[0] / length, direction[1] / length, direction[2] / length};
        const double helper[3] = {std::fabs(n[0]) < 0.9 ? 1.0 : 0.0, std::fabs(n[0]) < 0.9 ? 0.0 : 1.0, 0.0};
        double u[3] = {helper[1] * n[2] - helper[2] * n[1], helper[2] * n[0] - helper[0] * n[2], helper[0] * n[1] - helper[1] * n[0]};
        const double u_length = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        for (double& c : u) c /= u_length;
        const double w[3] = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]};
        for (int spin = 0; spin < 4; ++spin)
            for (double gap : {0.05, 0.2, 0.5, 0.9}) {
                // The wedges turned by `spin` about n.
                const double angle = 0.4 * spin, cs = std::cos(angle), sn = std::sin(angle);
                const double centre[3] = {10.0 * static_cast<double>(count % 16), 10.0 * static_cast<double>(count / 16), 0.0};
                auto place = [&](TetMesh& mesh, std::initializer_list<std::array<double, 3>> corners) {
                    for (const auto& p : corners) {
                        const double a = cs * p[0] - sn * p[1], b = sn * p[0] + cs * p[1];
                        for (int c = 0; c < 3; ++c) mesh.positions.push_back(centre[c] + a * u[c] + b * w[c] + p[2] * n[c]);
                    }
                    for (std::uint32_t k = 0; k < 4; ++k) mesh.tets.push_back(static_cast<std::uint32_t>(4 * count) + k);
                };
                place(first, {{-1, 0, 0}, {1, 0, 0}, {0, -1, -1}, {0, 1, -1}});
                place(second, {{0, -1, gap}, {0, 1, gap}, {-1, 0, 1 + gap}, {1, 0, 1 + gap}});
                ++count;
            }
    }
    for (NarrowPhase narrow : test::every_narrow_phase_test()) {
        DetectorOptions brute = with_method(Method::brute_force_loop), grid = with_method(Method::kdet);
        brute.narrow_phase = grid.narrow_phase = narrow;
        const Outcome oracle = run({first, second}, false, brute);
        const Outcome found = run({first, second}, false, grid);
        EXPECT_EQ(found.pairs, oracle.pairs) << to_string(narrow);
        const bool reports_them = narrow == NarrowPhase::sat_no_edges;
        EXPECT_EQ(oracle.pairs.size(), reports_them ? count : 0u) << to_string(narrow);
        EXPECT_EQ(found.counts.candidates, count) << to_string(narrow);
        EXPECT_EQ(found.counts.narrow_phase_candidates, reports_them ? count : 0u) << to_string(narrow);
        grid.method = Method::kdet_no_pairs;
        EXPECT_EQ(run({first, second}, false, grid).colliding, flags_of(oracle.pairs, oracle.colliding))
            << to_string(narrow);
    }
}

TEST(Pipeline, TinyBuffersGrowAndGiveTheSamePairs) {
    const TetMesh a = random_soup(2000, 4.0, 2.0, 21), b = random_soup(2000, 4.0, 2.0, 22);
    const Outcome reference = run({a, b}, true, with_method(Method::kdet));
    ASSERT_GT(reference.pairs.size(), 50u);
    DetectorOptions tiny = with_method(Method::kdet);
    tiny.initial_candidate_capacity = 1;
    tiny.bucket_capacity = 1; // every cell with two tets chains overflow buckets
    const Outcome small = run({a, b}, true, tiny);
    EXPECT_EQ(small.pairs, reference.pairs);
    EXPECT_GT(small.counts.buffer_regrows, 0u);
    // The tets that did not fit resume where they stopped: no candidate is written twice or lost,
    // and no rejection is counted twice. Dense soups give tets several batches of candidates, so
    // some stop after storing a batch.
    EXPECT_EQ(small.counts.narrow_phase_candidates, reference.counts.narrow_phase_candidates);
    EXPECT_EQ(small.counts.candidates, reference.counts.candidates);
    const TetMesh c = random_soup(3000, 1.0, 0.05, 41), d = random_soup(3000, 1.0, 0.05, 42);
    const Outcome dense = run({c, d}, true, with_method(Method::kdet));
    ASSERT_GT(dense.counts.narrow_phase_candidates, 8u * 6000u); // 16 keys to a batch
    for (const auto& [meshes, whole] : {std::pair{std::vector<TetMesh>{a, b}, reference}, std::pair{std::vector<TetMesh>{c, d}, dense}})
        for (std::size_t capacity : {std::size_t{17}, whole.counts.narrow_phase_candidates / 3, whole.counts.narrow_phase_candidates - 1}) {
            DetectorOptions part = with_method(Method::kdet);
            part.initial_candidate_capacity = capacity;
            const Outcome grown = run(meshes, true, part);
            EXPECT_EQ(grown.pairs, whole.pairs) << capacity;
            EXPECT_EQ(grown.counts.narrow_phase_candidates, whole.counts.narrow_phase_candidates) << capacity;
            EXPECT_EQ(grown.counts.candidates, whole.counts.candidates) << capacity;
            EXPECT_GT(grown.counts.buffer_regrows, 0u) << capacity;
        }
    DetectorOptions tiny_brute = with_method(Method::brute_force_pairs);
    tiny_brute.initial_candidate_capacity = 1;
    EXPECT_EQ(run({a, b}, true, tiny_brute).pairs, reference.pairs);
}

/// The CPU backend with the pipeline's work divided as `Tuning` says (exec/tuning.hpp): with
/// CudaTuning, as on the GPU.
template <class Tuning>
struct TunedCpuExec : CpuExec {
    using CpuExec::CpuExec;
    using tuning = Tuning;
};

/// CpuTuning with the candidate search split as the GPU splits it, into LayerParts x BlockParts parts
/// by layers and by blocks of each list (SearchPart), a tet per search item (or TetsPerItem), and the
/// grid's plan in chunks of PlanChunk tets.
template <std::uint32_t LayerParts, std::uint32_t BlockParts, std::uint32_t PlanChunk, std::uint32_t TetsPerItem = 1>
struct SplitTuning : CpuTuning {
    static constexpr std::uint32_t search_layer_parts(bool /*self_collision*/, std::size_t /*tets*/) { return LayerParts; }
    static constexpr std::uint32_t search_block_parts(bool /*self_collision*/, std::size_t /*tets*/) { return BlockParts; }
    static constexpr std::uint32_t search_tets_per_item = TetsPerItem;
    static constexpr std::uint32_t plan_chunk = PlanChunk;
};

/// CudaTuning with the split of its search that it picks for the other kind of scene (with
/// self-collision where the scene has none, and the other way round), so that both of its splits
/// search every scene.
struct CudaTuningOtherSplit : CudaTuning {
    static constexpr std::uint32_t search_layer_parts(bool self_collision, std::size_t tets) {
        return CudaTuning::search_layer_parts(!self_collision, tets);
    }
    static constexpr std::uint32_t search_block_parts(bool self_collision, std::size_t tets) {
        return CudaTuning::search_block_parts(!self_collision, tets);
    }
};

/// CpuTuning with the face planes in the narrow phase (as CudaTuning has them).
struct PlanesAfterSearchTuning : CpuTuning {
    static constexpr bool face_planes_in_search = false;
};

/// Frames of `pipeline`, each over the meshes of one element of `frames` (the same tets, other
/// positions), every object against the others and, with `self`, itself; the tets and vertices stored
/// in spatial order as Detector stores them (SceneTopology::add_object). Returns the last frame's result.
FrameResult run_frames(PipelineBase& pipeline, const std::vector<std::vector<TetMesh>>& frames, bool self) {
    const auto float_positions = [](const std::vector<TetMesh>& meshes) {
        std::vector<vec3> positions;
        for (const TetMesh& mesh : meshes)
            for (std::size_t v = 0; v < mesh.num_vertices(); ++v)
                positions.push_back(vec3{static_cast<float>(mesh.positions[3 * v]), static_cast<float>(mesh.positions[3 * v + 1]),
                                         static_cast<float>(mesh.positions[3 * v + 2])});
        return positions;
    };
    const std::vector<TetMesh>& meshes = frames.front();
    const std::vector<vec3> first_positions = float_positions(meshes);
    SceneTopology topology;
    for (std::size_t o = 0, first_vertex = 0; o < meshes.size(); first_vertex += meshes[o].num_vertices(), ++o)
        topology.add_object(first_positions.data() + first_vertex, static_cast<std::uint32_t>(meshes[o].num_vertices()),
                            meshes[o].tets.data(), meshes[o].num_tets());
    pipeline.set_topology(topology);
    std::vector<std::uint8_t> pair_enabled(meshes.size() * meshes.size(), 1);
    for (std::size_t o = 0; o < meshes.size(); ++o) pair_enabled[o * meshes.size() + o] = self ? 1 : 0;
    FrameResult result;
    for (const std::vector<TetMesh>& frame : frames) {
        const std::vector<vec3> positions = float_positions(frame);
        std::vector<vec3> stored(positions.size());
        topology.to_stored_order(0, topology.vertex_count, positions.data(), stored.data());
        pipeline.start({PositionUpload{0, stored.data(), topology.vertex_count}}, {}, pair_enabled);
        EXPECT_EQ(pipeline.finish(result), no_vertex);
    }
    return result;
}

/// One frame of `pipeline` over `meshes` (run_frames).
FrameResult run_pipeline(PipelineBase& pipeline, const std::vector<TetMesh>& meshes, bool self) {
    return run_frames(pipeline, {meshes}, self);
}

TEST(Pipeline, WorkDividedAsOnTheGpuFindsEveryCandidateOnce) {
    const TetMesh a = random_soup(3000, 4.0, 3.0, 61), b = random_soup(3000, 4.0, 3.0, 62);
    const TetMesh folded = load_model("bunny.mesh");
    for (std::size_t capacity : {std::size_t{0}, std::size_t{1}, std::size_t{200}}) {
        DetectorOptions options;
        options.initial_candidate_capacity = capacity; // small ones make the split items stop and resume
        const std::vector<TetMesh> folded_and_moved{folded, moved(folded, 0.4, 0.02, 0.01, 0.0)};
        for (const auto& [meshes, self] : {std::pair{std::vector<TetMesh>{a, b}, true}, std::pair{folded_and_moved, true},
                                           std::pair{folded_and_moved, false}}) {
            Pipeline<CpuExec> whole(options);
            Pipeline<TunedCpuExec<SplitTuning<3, 1, 1>>> by_layers(options);
            Pipeline<TunedCpuExec<SplitTuning<1, 8, 256>>> by_blocks(options);
            // The GPU's: cells one spacing wide, the face planes in the narrow phase
            Pipeline<TunedCpuExec<CudaTuning>> like_cuda(options);
            // The GPU's with the split it picks for the other kind of scene
            Pipeline<TunedCpuExec<CudaTuningOtherSplit>> like_cuda_other_split(options);
            // Runs of 7 tets, split by layers: runs end inside objects and the last one is short.
            Pipeline<TunedCpuExec<SplitTuning<3, 1, 256, 7>>> odd_runs(options);
            // The face planes in the narrow phase, the CPU's search otherwise.
            Pipeline<TunedCpuExec<PlanesAfterSearchTuning>> planes_after_search(options);
            const FrameResult expected = run_pipeline(whole, meshes, self); // runs of CpuTuning::search_tets_per_item
            ASSERT_GT(expected.pairs.size(), 20u);
            // Whether the shape writes the same candidates as the CPU's search, so that its buffer grows
            // as often.
            const std::pair<PipelineBase*, bool> shapes[] = {{&by_layers, true},  {&by_blocks, true},
                                                             {&like_cuda, false}, {&like_cuda_other_split, false},
                                                             {&odd_runs, true},   {&planes_after_search, false}};
            for (const auto& [split, same_candidates_written] : shapes) {
                const FrameResult got = run_pipeline(*split, meshes, self);
                EXPECT_EQ(got.pairs, expected.pairs) << "capacity " << capacity;
                EXPECT_EQ(got.colliding, expected.colliding);
                EXPECT_EQ(got.counts.candidates, expected.counts.candidates);
                EXPECT_EQ(got.counts.narrow_phase_candidates, expected.counts.narrow_phase_candidates);
                // A plan in smaller chunks bounds the cells more loosely, never too tightly.
                if (capacity == 0 && same_candidates_written) {
                    EXPECT_EQ(got.counts.buffer_regrows, expected.counts.buffer_regrows);
                }
            }
        }
    }
}

/// How many elements a buffer of CappedExec can hold, by their type: more fails as an allocation would.
std::size_t key_buffer_cap = 0, contact_buffer_cap = 0;

/// A host buffer whose 64-bit keys (the candidates' buffer and the pairs' window) and contacts
/// cannot grow past their caps, as device memory near its limit: a failed allocation leaves it empty.
template <class T>
struct CappedBuffer : HostBuffer<T> {
    static std::size_t cap() {
        if constexpr (std::is_same_v<T, std::uint64_t>) return key_buffer_cap;
        if constexpr (std::is_same_v<T, Contact>) return contact_buffer_cap;
        return std::numeric_limits<std::size_t>::max();
    }
    bool try_resize_discard(std::size_t n) noexcept {
        if (n > cap()) {
            HostBuffer<T> released;
            this->swap(released);
            return false;
        }
        return HostBuffer<T>::try_resize_discard(n);
    }
    void resize_discard(std::size_t n) {
        if (!try_resize_discard(n)) throw std::bad_alloc();
    }
};

struct CappedExec : CpuExec {
    using CpuExec::CpuExec;
    template <class T>
    using buffer = CappedBuffer<T>;
};

TEST(Pipeline, NearTheMemoryLimitBuffersGrowToWhatFitsAndNoPairIsLost) {
    // Two soups apart, then overlapping (without self-collision, so that the first frame sizes small
    // buffers): the second frame outgrows the candidates' buffer and the pairs' window, and doubling
    // them would pass a cap where the need does not.
    const TetMesh a = random_soup(3000, 1.0, 0.05, 71), b = random_soup(3000, 1.0, 0.05, 72);
    const std::vector<std::vector<TetMesh>> frames{{a, moved(b, 0.0, 5.0, 0.0, 0.0)}, {a, b}};
    DetectorOptions options;
    options.contacts = true;
    Pipeline<CpuExec> unlimited(options);
    const FrameResult expected = run_frames(unlimited, frames, false);
    const std::size_t candidates = expected.counts.narrow_phase_candidates, pairs = expected.pairs.size();
    ASSERT_GT(candidates, 4u * 4096u); // past the first frame's sizing
    ASSERT_GT(pairs, 1000u);
    constexpr std::size_t unlimited_room = std::numeric_limits<std::size_t>::max();
    // Caps a tenth over the need, under the quarter over it that growing asks for: the candidates'
    // buffer (the pairs' window, of fewer keys, fits), then the contacts beside the pairs' window.
    for (const auto& [keys, contacts] : {std::pair{candidates + candidates / 10, unlimited_room},
                                         std::pair{unlimited_room, pairs + pairs / 10}}) {
        key_buffer_cap = keys;
        contact_buffer_cap = contacts;
        Pipeline<CappedExec> capped(options);
        const FrameResult got = run_frames(capped, frames, false);
        EXPECT_EQ(got.pairs, expected.pairs);
        EXPECT_EQ(got.contacts.size(), pairs);
        EXPECT_EQ(got.counts.narrow_phase_candidates, candidates);
        EXPECT_GT(got.counts.buffer_regrows, 0u);
    }
    // A first frame whose guess (16 keys a tet) the memory does not hold starts from less and grows
    // as its search goes, within the cap.
    key_buffer_cap = unlimited_room;
    contact_buffer_cap = unlimited_room;
    Pipeline<CpuExec> first_unlimited(options);
    const FrameResult first_expected = run_frames(first_unlimited, {frames.back()}, true);
    const std::size_t first_candidates = first_expected.counts.narrow_phase_candidates;
    ASSERT_LT(first_candidates + first_candidates / 10, 16u * 6000u);
    key_buffer_cap = first_candidates + first_candidates / 10;
    Pipeline<CappedExec> first_capped(options);
    const FrameResult first_got = run_frames(first_capped, {frames.back()}, true);
    EXPECT_EQ(first_got.pairs, first_expected.pairs);
    EXPECT_EQ(first_got.counts.narrow_phase_candidates, first_candidates);
    EXPECT_GT(first_got.counts.buffer_regrows, 0u);
    // Below the need itself the frame cannot run: kdet::Error naming the pairs it counted and their
    // bytes, not a partial answer.
    for (const auto& [keys, contacts, need] : {std::tuple{candidates / 2, unlimited_room, " candidate pairs"},
                                               std::tuple{unlimited_room, pairs / 2, " colliding pairs"}}) {
        key_buffer_cap = keys;
        contact_buffer_cap = contacts;
        Pipeline<CappedExec> too_small(options);
        const std::string message = test::error_message([&] { run_frames(too_small, frames, false); });
        EXPECT_NE(message.find(need), std::string::npos) << message;
        EXPECT_NE(message.find(" bytes ("), std::string::npos) << message;
    }
}

TEST(Pipeline, OrdinaryInputGrowsNoBuffer) {
    // The grid's table and overflow pool are sized from the cells the relevant tets need, and the
    // candidate buffer from the relevant tets, so a first frame (a one-off query) fills each in one pass.
    const TetMesh hand = load_model("hand.mesh");
    const double e = test::extent_of(hand);
    const TetMesh a = random_soup(20000, 10.0, 3.0, 5), b = random_soup(20000, 10.0, 3.0, 6);
    for (const auto& [meshes, self] : {std::pair{std::vector<TetMesh>{a, b}, false}, std::pair{std::vector<TetMesh>{a}, true},
                                       std::pair{std::vector<TetMesh>{hand}, true},
                                       std::pair{std::vector<TetMesh>{hand, moved(hand, 0.3, 0.1 * e, 0.0, 0.0)}, false}}) {
        const Outcome outcome = run(meshes, self, with_method(Method::kdet));
        EXPECT_GT(outcome.counts.narrow_phase_candidates, 0u);
        EXPECT_EQ(outcome.counts.buffer_regrows, 0u) << meshes.size() << " objects, self " << self;
    }
}

TEST(Pipeline, SparseScenesGetSmallBucketsAndTheSameAnswer) {
    // A dense cloud of small tets, which sets the tets' spacing and so the cells of layer 0 (each
    // holds dozens of them), beside fewer large tets far apart, each alone in the cells it overlaps
    // on its higher layer: most occupied cells hold one id, so the automatic bucket capacity (8 here)
    // shrinks the table's id storage, and the answer is the one of any fixed capacity.
    const auto cloud = [](std::size_t count, double extent, double size, unsigned seed) {
        TetMesh mesh = random_soup(count, 1.0, 0.0, seed); // tets of size 0.2 in a unit cube
        for (double& x : mesh.positions) x *= extent;
        for (std::size_t t = 0; t < count; ++t) {
            double* corner = &mesh.positions[12 * t];
            for (int k = 1; k < 4; ++k)
                for (int a = 0; a < 3; ++a) corner[3 * k + a] = corner[a] + (corner[3 * k + a] - corner[a]) * size / (0.2 * extent);
        }
        return mesh;
    };
    const TetMesh dust = cloud(12000, 1.0, 0.02, 51), boulders = cloud(10000, 400.0, 2.0, 52);
    DetectorOptions automatic = with_method(Method::kdet), fixed = automatic;
    fixed.bucket_capacity = 32;
    const Outcome small = run({dust, boulders}, true, automatic), large = run({dust, boulders}, true, fixed);
    ASSERT_GT(small.pairs.size(), 100u);
    EXPECT_EQ(small.pairs, large.pairs);
    EXPECT_EQ(small.counts.buffer_regrows, 0u);
    EXPECT_EQ(small.counts.grid_bucket_capacity, 8u);
    EXPECT_EQ(large.counts.grid_bucket_capacity, 32u);
    EXPECT_LT(10 * small.grid_bytes, 9 * large.grid_bytes); // at least 10 % less
}

TEST(Pipeline, ThreadCountDoesNotChangeTheAnswer) {
    // 6000 tets: several runs of populating per thread (CpuExec::for_each_in_runs), odd counts included.
    const TetMesh a = random_soup(3000, 6.0, 2.0, 31), b = random_soup(3000, 6.0, 2.0, 32);
    DetectorOptions one = with_method(Method::kdet);
    one.threads = 1;
    const Outcome r1 = run({a, b}, true, one);
    for (const int threads : {2, 3, 4}) {
        DetectorOptions more = one;
        more.threads = threads;
        const Outcome r = run({a, b}, true, more);
        EXPECT_EQ(r1.pairs, r.pairs) << threads;
        EXPECT_EQ(r1.counts.narrow_phase_candidates, r.counts.narrow_phase_candidates) << threads;
    }
}

TEST(Pipeline, PairsAndFlagsAreHandedOutByObjectOnAnyNumberOfThreads) {
    // 3 objects (counted without a branch) and 40 (a binary search), 100k keys and about 100k tets
    // (shared by threads), objects of every size, empty ones included, against a search over the
    // objects one by one.
    std::mt19937 rng(90);
    for (const std::size_t objects : {std::size_t{3}, std::size_t{40}}) {
        std::vector<std::uint32_t> begin{0};
        const std::uint32_t largest = objects == 3 ? 70000u : 5000u;
        for (std::size_t o = 0; o < objects; ++o)
            begin.push_back(begin.back() + (o % 7 == 3 ? 0u : static_cast<std::uint32_t>(rng() % largest)));
        std::uniform_int_distribution<std::uint32_t> tet(0, begin.back() - 1);
        std::vector<std::uint64_t> keys(100000);
        for (std::uint64_t& key : keys) key = (std::uint64_t{tet(rng)} << 32) | tet(rng);
        const auto object_of = [&](std::uint32_t global) {
            std::uint32_t o = 0;
            while (begin[o + 1] <= global) ++o;
            return o;
        };
        for (const int threads : {1, 2}) {
            std::vector<TetPair> pairs(keys.size());
            pairs_from_keys(begin, keys.data(), keys.size(), pairs.data(), threads);
            for (std::size_t k = 0; k < keys.size(); ++k) {
                const std::uint32_t a = key_first(keys[k]), b = key_second(keys[k]);
                const TetPair expected{object_of(a), a - begin[object_of(a)], object_of(b), b - begin[object_of(b)]};
                ASSERT_EQ(pairs[k], expected) << objects << " objects, " << threads << " threads, key " << k;
            }
            std::vector<std::uint32_t> flags(begin.back());
            for (std::uint32_t& flag : flags) flag = rng() % 3u == 0 ? 1u + rng() % 4u : 0u;
            std::vector<std::vector<std::uint8_t>> colliding(1, std::vector<std::uint8_t>(3, 7));
            flags_by_object(begin, flags.data(), colliding, threads);
            ASSERT_EQ(colliding.size(), objects);
            for (std::uint32_t o = 0; o < objects; ++o) {
                ASSERT_EQ(colliding[o].size(), begin[o + 1] - begin[o]) << "object " << o;
                for (std::uint32_t t = begin[o]; t < begin[o + 1]; ++t)
                    ASSERT_EQ(colliding[o][t - begin[o]], flags[t] ? 1 : 0) << "object " << o << ", global tet " << t;
            }
        }
    }
}

TEST(Detector, FrameByFrameMatchesOneOffQueries) {
    ProceduralSceneOptions scene_options;
    scene_options.total_tets = 4000;
    scene_options.frames = 9;
    const ProceduralScene scene(scene_options);
    Detector detector;
    for (std::size_t o = 0; o < 2; ++o) detector.add_object(scene.rest_mesh(o));
    std::size_t frames_with_pairs = 0;
    for (int f = 0; f < scene.num_frames(); ++f) {
        std::vector<TetMesh> posed(2);
        std::vector<float> xyz;
        for (std::size_t o = 0; o < 2; ++o) {
            scene.positions(o, f, xyz);
            detector.set_positions(static_cast<ObjectId>(o), xyz.data(), xyz.size() / 3);
            posed[o].tets = scene.rest_mesh(o).tets;
            posed[o].positions.assign(xyz.begin(), xyz.end());
        }
        const std::vector<TetPair> pairs = detector.detect().pairs;
        EXPECT_EQ(pairs, run(posed, false, with_method(Method::brute_force_loop)).pairs) << "frame " << f;
        frames_with_pairs += pairs.empty() ? 0 : 1;
    }
    EXPECT_GE(frames_with_pairs, 3u);
}

TEST(Detector, PairAndSelfTogglesAreHonoured) {
    const TetMesh a = random_soup(600, 3.0, 1.0, 41), b = random_soup(600, 3.0, 1.0, 42),
                  c = random_soup(600, 3.0, 1.0, 43);
    Detector detector;
    const ObjectId ia = detector.add_object(a), ib = detector.add_object(b), ic = detector.add_object(c);
    detector.set_pair_collision(ia, ib, false);
    detector.set_self_collision(ic, true);
    std::set<std::pair<std::uint32_t, std::uint32_t>> kinds;
    for (const TetPair& p : detector.detect().pairs) kinds.insert({p.object_a, p.object_b});
    EXPECT_EQ(kinds.count({ia, ib}), 0u);
    EXPECT_EQ(kinds.count({ia, ia}), 0u);
    EXPECT_EQ(kinds.count({ib, ib}), 0u);
    EXPECT_EQ(kinds.count({ia, ic}), 1u);
    EXPECT_EQ(kinds.count({ib, ic}), 1u);
    EXPECT_EQ(kinds.count({ic, ic}), 1u);
}

TEST(Detector, ManyObjectsWithMixedTogglesMatchBruteForce) {
    // More objects than the grid's cells have object bits (32): objects 32 apart share a bit, so a
    // cell may be read for an object that is not there, and never skipped for one that is.
    constexpr std::uint32_t objects = 40;
    std::vector<TetMesh> meshes;
    for (std::uint32_t o = 0; o < objects; ++o) meshes.push_back(random_soup(60, 2.0, 1.0, 500 + o));
    const auto run_with = [&](Method method) {
        Detector detector(with_method(method));
        for (const TetMesh& m : meshes) detector.add_object(m);
        for (std::uint32_t o = 0; o < objects; ++o) {
            detector.set_self_collision(o, o % 3 == 0);
            if (o + 32 < objects) detector.set_pair_collision(o, o + 32, false);
            if (o % 2 == 0) detector.set_pair_collision(o, o + 1, false);
        }
        return detector.detect().pairs;
    };
    const std::vector<TetPair> oracle = run_with(Method::brute_force_loop);
    ASSERT_GE(oracle.size(), 100u);
    EXPECT_EQ(run_with(Method::kdet), oracle);
}

TEST(Detector, SeparatedObjectsGridNothingAndFindNothing) {
    const TetMesh a = random_soup(500, 1.0, 1.0, 51);
    Detector detector;
    detector.add_object(a);
    detector.add_object(moved(a, 0.0, 5.0, 0.0, 0.0));
    const FrameResult& r = detector.detect();
    EXPECT_TRUE(r.pairs.empty());
    EXPECT_EQ(r.counts.candidates, 0u);
    EXPECT_EQ(r.counts.grid_cells, 0u); // no tet was relevant, so nothing was gridded
    EXPECT_EQ(r.counts.colliding_tets, 0u);
}

TEST(Detector, CountsTheTimesTheHostWaitsForTheBackend) {
    const TetMesh a = random_soup(2000, 3.0, 1.0, 57);
    for (Method method : {Method::kdet, Method::kdet_no_pairs, Method::brute_force_loop, Method::brute_force_pairs})
        for (bool to_host : {true, false}) {
            const std::string what = std::string(to_string(method)) + (to_host ? ", results to host" : ", on device");
            DetectorOptions o = with_method(method);
            o.results_to_host = to_host;
            Detector detector(o);
            detector.set_self_collision(detector.add_object(a), true);
            const ObjectId b = detector.add_object(moved(a, 0.3, 0.2, 0.0, 0.0));
            const FrameResult& first = detector.detect();
            ASSERT_GT(first.counts.colliding_tets, 0u) << what;
            // A first frame reads its grid plan and its candidate count to size its buffers, then
            // everything once at the end; a frame that grows a buffer reruns and reads again.
            EXPECT_LE(first.counts.host_waits, 3u + 2u * first.counts.buffer_regrows) << what;
            // brute_force_pairs lays its work out on the host from the pairs of objects checked: one read more.
            const std::uint32_t per_frame = method == Method::brute_force_pairs ? 2u : 1u;
            const FrameResult& second = detector.detect();
            EXPECT_EQ(second.counts.buffer_regrows, 0u) << what;
            EXPECT_EQ(second.counts.host_waits, per_frame) << what;
            const std::size_t grown_bytes = detector.memory_bytes();
            EXPECT_EQ(detector.detect().counts.host_waits, per_frame) << what;
            EXPECT_EQ(detector.memory_bytes(), grown_bytes) << what; // nothing allocated once grown
            // Objects apart, self-collision off: still the one read at the end.
            const TetMesh far = moved(a, 0.0, 50.0, 0.0, 0.0);
            detector.set_self_collision(0, false);
            detector.set_positions(b, far.positions.data(), far.num_vertices());
            const FrameResult& apart = detector.detect();
            EXPECT_EQ(apart.counts.colliding_tets, 0u) << what;
            EXPECT_EQ(apart.counts.host_waits, per_frame) << what;
        }
}

TEST(Detector, DetectAsyncWaitsForNothingAndFinishWaitsOnce) {
    const TetMesh a = random_soup(2000, 3.0, 1.0, 58);
    const TetMesh near = moved(a, 0.3, 0.2, 0.0, 0.0), nearer = moved(a, 0.3, 0.1, 0.0, 0.0);
    for (bool to_host : {true, false}) {
        DetectorOptions o;
        o.results_to_host = to_host;
        Detector detector(o), reference;
        for (Detector* d : {&detector, &reference}) {
            d->set_self_collision(d->add_object(a), true);
            d->add_object(near);
        }
        detector.detect(); // the first frame sizes the buffers
        detector.set_positions(1, nearer.positions.data(), nearer.num_vertices());
        reference.set_positions(1, nearer.positions.data(), nearer.num_vertices());
        const FrameResult expected = reference.detect();
        detector.detect_async();
        // The frame is not complete until finish(): its results cannot be read before.
        EXPECT_THROW(detector.device_results(), Error);
        const FrameResult& r = detector.finish();
        // One wait in all, and finish() waits at least once: detect_async() waited for nothing.
        EXPECT_EQ(r.counts.host_waits, 1u);
        EXPECT_EQ(r.counts.colliding_pairs, expected.counts.colliding_pairs);
        EXPECT_EQ(r.counts.colliding_tets, expected.counts.colliding_tets);
        if (to_host) {
            EXPECT_EQ(r.pairs, expected.pairs);
        }
        {
            const DeviceResults device = detector.device_results();
            const device_like::BackendMemoryReadable readable;
            ASSERT_EQ(device.pair_count, expected.pairs.size());
            for (std::size_t k = 0; k < device.pair_count; ++k) {
                const TetPair& p = expected.pairs[k];
                EXPECT_EQ(device.pair_keys[k], (std::uint64_t{detector.first_tet(p.object_a) + p.tet_a} << 32) |
                                                   (detector.first_tet(p.object_b) + p.tet_b));
            }
        }
        // A second detect_async() finishes the first before it starts: no frame goes unchecked.
        detector.detect_async();
        detector.detect_async();
        EXPECT_EQ(detector.finish().counts.colliding_pairs, expected.counts.colliding_pairs);
        EXPECT_EQ(detector.finish().counts.colliding_pairs, expected.counts.colliding_pairs); // nothing pending: the last result
    }
}

TEST(Detector, ALaterFrameThatNeedsMoreRoomRunsAgainAndLosesNothing) {
    // The first frame sizes the buffers for a graze; the next one overlaps deeply and needs far more
    // candidates and colliding pairs: it finds out at its end, grows and runs again.
    const TetMesh a = random_soup(3000, 3.0, 1.0, 59);
    const TetMesh graze = moved(a, 0.0, 2.9, 0.0, 0.0), deep = moved(a, 0.3, 0.1, 0.0, 0.0);
    for (Method method : {Method::kdet, Method::brute_force_loop}) {
        Detector detector(with_method(method));
        detector.add_object(a);
        const ObjectId b = detector.add_object(graze);
        const FrameResult& first = detector.detect();
        ASSERT_LT(first.counts.colliding_pairs, 100u) << to_string(method);
        detector.set_positions(b, deep.positions.data(), deep.num_vertices());
        const FrameResult& r = detector.detect();
        EXPECT_GT(r.counts.buffer_regrows, 0u) << to_string(method);
        EXPECT_EQ(r.counts.host_waits, 1u + r.counts.buffer_regrows) << to_string(method);
        std::vector<TetPair> expected;
        for (const auto& [i, j] : collide(a, deep)) expected.push_back(TetPair{0, i, 1, j});
        EXPECT_EQ(r.pairs, expected) << to_string(method);
        EXPECT_EQ(detector.detect().counts.buffer_regrows, 0u) << to_string(method); // grown for good
    }
}

TEST(Detector, ALaterFrameWhosePairsOutgrowOnlyTheirWindowRunsItsNarrowPhaseAgainAndLosesNothing) {
    // A deep overlap sizes every buffer, a graze then shrinks the colliding pairs' window (the GPU sorts
    // all of it), and the deep overlap again outgrows only that window: the candidates found are kept
    // and the narrow phase runs again. Pairs, flags, contacts and counts are those of a fresh detector
    // (with contacts on, the first attempt must not read the window's unwritten slots).
    const TetMesh a = random_soup(12000, 6.0, 1.0, 67);
    const TetMesh graze = moved(a, 0.0, 5.9, 0.0, 0.0), deep = moved(a, 0.3, 0.1, 0.0, 0.0);
    for (Method method : {Method::kdet, Method::brute_force_loop}) {
        DetectorOptions options = with_method(method);
        options.contacts = true;
        options.narrow_phase = NarrowPhase::exact;
        Detector detector(options), fresh(options);
        detector.add_object(a);
        const ObjectId b = detector.add_object(deep);
        const std::size_t deep_pairs = detector.detect().pairs.size();
        ASSERT_GT(deep_pairs, 4096u) << to_string(method);
        detector.set_positions(b, graze.positions.data(), graze.num_vertices());
        ASSERT_LT(detector.detect().counts.colliding_pairs, deep_pairs / 4) << to_string(method);
        detector.set_positions(b, deep.positions.data(), deep.num_vertices());
        const FrameResult grown = detector.detect();
        EXPECT_EQ(grown.counts.buffer_regrows, 1u) << to_string(method);
        EXPECT_EQ(grown.counts.host_waits, 2u) << to_string(method);
        fresh.add_object(a);
        fresh.add_object(deep);
        const FrameResult& expected = fresh.detect();
        EXPECT_EQ(grown.pairs, expected.pairs) << to_string(method);
        EXPECT_EQ(grown.colliding, expected.colliding) << to_string(method);
        EXPECT_EQ(grown.counts.colliding_tets, expected.counts.colliding_tets) << to_string(method);
        EXPECT_EQ(grown.counts.candidates, expected.counts.candidates) << to_string(method);
        EXPECT_EQ(grown.counts.exact_stage_pairs, expected.counts.exact_stage_pairs) << to_string(method);
        ASSERT_EQ(grown.contacts.size(), expected.contacts.size()) << to_string(method);
        for (std::size_t k = 0; k < grown.contacts.size(); ++k) {
            EXPECT_EQ(grown.contacts[k].depth, expected.contacts[k].depth) << k;
            EXPECT_EQ(grown.contacts[k].direction[0], expected.contacts[k].direction[0]) << k;
        }
    }
}

TEST(Detector, AFrameWhoseObjectsMeetRunsAgainFromEachStageThatLackedRoomAndLosesNothing) {
    // Apart, the objects grid nothing and the buffers stay at their smallest; when they overlap, the
    // frame outgrows the grid (it runs again from populating), then, with the grid in place, the
    // candidate buffer (again from the candidate stage) and the pairs' window. Everything equals a
    // fresh detector's.
    const TetMesh a = random_soup(6000, 4.0, 1.0, 71);
    const TetMesh apart = moved(a, 0.0, 10.0, 0.0, 0.0), deep = moved(a, 0.3, 0.1, 0.0, 0.0);
    for (Method method : {Method::kdet, Method::brute_force_loop}) {
        const DetectorOptions options = with_method(method);
        Detector detector(options), fresh(options);
        detector.add_object(a);
        const ObjectId b = detector.add_object(apart);
        ASSERT_EQ(detector.detect().counts.colliding_pairs, 0u) << to_string(method);
        detector.set_positions(b, deep.positions.data(), deep.num_vertices());
        const FrameResult grown = detector.detect();
        EXPECT_GE(grown.counts.buffer_regrows, method == Method::kdet ? 2u : 1u) << to_string(method);
        EXPECT_EQ(grown.counts.host_waits, 1u + grown.counts.buffer_regrows) << to_string(method);
        fresh.add_object(a);
        fresh.add_object(deep);
        const FrameResult& expected = fresh.detect();
        ASSERT_GT(expected.pairs.size(), 4096u) << to_string(method);
        EXPECT_EQ(grown.pairs, expected.pairs) << to_string(method);
        EXPECT_EQ(grown.colliding, expected.colliding) << to_string(method);
        EXPECT_EQ(grown.counts.candidates, expected.counts.candidates) << to_string(method);
        EXPECT_EQ(grown.counts.narrow_phase_candidates, expected.counts.narrow_phase_candidates) << to_string(method);
        EXPECT_EQ(grown.counts.colliding_tets, expected.counts.colliding_tets) << to_string(method);
        EXPECT_EQ(grown.counts.exact_stage_pairs, expected.counts.exact_stage_pairs) << to_string(method);
        EXPECT_EQ(grown.counts.grid_cells, expected.counts.grid_cells) << to_string(method);
    }
}

TEST(Detector, BucketsGrowWhenObjectsThatStartedApartMeet) {
    // Apart, nothing is gridded and the automatic bucket capacity starts at its smallest; once the
    // objects overlap, the buckets grow to what a detector that saw the overlap first chose, so both
    // end with the same grid (a later frame keeping buckets of 4 chained most of its cells).
    const TetMesh a = random_soup(3000, 3.0, 1.0, 61);
    const TetMesh apart = moved(a, 0.0, 10.0, 0.0, 0.0), deep = moved(a, 0.3, 0.1, 0.0, 0.0);
    Detector late(with_method(Method::kdet)), early(with_method(Method::kdet));
    late.add_object(a);
    const ObjectId b = late.add_object(apart);
    ASSERT_EQ(late.detect().counts.colliding_pairs, 0u);
    late.set_positions(b, deep.positions.data(), deep.num_vertices());
    late.detect();
    early.add_object(a);
    early.add_object(deep);
    early.detect();
    const FrameResult& seen_late = late.detect();
    const std::size_t late_grid_bytes = seen_late.grid_bytes;
    const std::uint32_t late_capacity = seen_late.counts.grid_bucket_capacity;
    const std::vector<TetPair> late_pairs = seen_late.pairs;
    const FrameResult& seen_early = early.detect();
    EXPECT_GT(late_capacity, 4u);
    EXPECT_EQ(late_capacity, seen_early.counts.grid_bucket_capacity);
    EXPECT_EQ(late_grid_bytes, seen_early.grid_bytes);
    EXPECT_EQ(late_pairs, seen_early.pairs);
    EXPECT_GT(late_pairs.size(), 100u);
}

TEST(Detector, FlagsClearWhenObjectsSeparateAfterColliding) {
    const TetMesh a = random_soup(500, 1.0, 1.0, 53);
    const TetMesh near = moved(a, 0.3, 0.05, 0.0, 0.0), far = moved(a, 0.3, 5.0, 0.0, 0.0);
    for (Method method : {Method::kdet, Method::kdet_no_pairs, Method::brute_force_loop}) {
        Detector detector(with_method(method));
        detector.add_object(a);
        const ObjectId b = detector.add_object(near);
        ASSERT_GT(detector.detect().counts.colliding_tets, 0u) << to_string(method);
        detector.set_positions(b, far.positions.data(), far.num_vertices());
        const FrameResult& r = detector.detect();
        EXPECT_EQ(r.counts.colliding_tets, 0u);
        for (const auto& flags : r.colliding) EXPECT_EQ(std::count(flags.begin(), flags.end(), 1), 0);
        const DeviceResults device = detector.device_results();
        const device_like::BackendMemoryReadable readable;
        EXPECT_EQ(std::count_if(device.colliding, device.colliding + device.tet_count,
                                [](std::uint32_t f) { return f != 0; }),
                  0);
    }
}

/// Unit tets with their lowest corner at the given (x, y) points, z = 0.
TetMesh corner_tets(std::initializer_list<std::pair<double, double>> corners) {
    TetMesh mesh;
    for (const auto& [x, y] : corners) {
        const double p[4][3] = {{x, y, 0}, {x + 1, y, 0}, {x, y + 1, 0}, {x, y, 1}};
        const auto v = static_cast<std::uint32_t>(mesh.num_vertices());
        for (const auto& q : p) mesh.positions.insert(mesh.positions.end(), q, q + 3);
        for (std::uint32_t k = 0; k < 4; ++k) mesh.tets.push_back(v + k);
    }
    return mesh;
}

TEST(Detector, OverlappingObjectBoxesWithNoTetInTheOverlapSkipTheGrid) {
    // Each object's box overlaps the other's, yet none of its tets reaches into the other's box.
    const TetMesh a = corner_tets({{0, 10}, {10, 0}}), b = corner_tets({{-10, 5}, {5, -10}});
    for (Method method : {Method::kdet, Method::kdet_no_pairs}) {
        Detector detector(with_method(method));
        detector.add_object(a);
        detector.add_object(b);
        const FrameResult& r = detector.detect();
        EXPECT_TRUE(r.pairs.empty());
        EXPECT_EQ(r.counts.colliding_tets, 0u);
        EXPECT_EQ(r.counts.candidates, 0u);
        EXPECT_EQ(r.counts.grid_cells, 0u); // nothing was gridded
    }
    // Moving b onto a makes its tets relevant again, and the grid finds the pairs.
    Detector detector;
    detector.add_object(a);
    detector.add_object(corner_tets({{0.5, 10.5}, {5, -10}}));
    EXPECT_EQ(detector.detect().pairs, (std::vector<TetPair>{{0, 0, 1, 0}}));
}

TEST(Detector, OneOffFunctionsReturnFileOrderIndices) {
    const TetMesh a = random_soup(400, 2.0, 1.0, 61), b = random_soup(400, 2.0, 1.0, 62);
    const auto pairs = collide(a, b);
    const Outcome reference = run({a, b}, false, with_method(Method::brute_force_loop));
    ASSERT_EQ(pairs.size(), reference.pairs.size());
    for (std::size_t k = 0; k < pairs.size(); ++k) {
        EXPECT_EQ(pairs[k].first, reference.pairs[k].tet_a);
        EXPECT_EQ(pairs[k].second, reference.pairs[k].tet_b);
    }
    const auto self_pairs = collide_self(a);
    for (const auto& p : self_pairs) EXPECT_LT(p.first, p.second);
    EXPECT_EQ(self_pairs.size(), run({a}, true, with_method(Method::brute_force_loop)).pairs.size());
}

TEST(Detector, OneOffFunctionsRefuseWhatTheyCannotReturn) {
    const TetMesh a = random_soup(50, 2.0, 1.0, 63);
    const DetectorOptions no_pairs = with_method(Method::kdet_no_pairs);
    EXPECT_EQ(error_message([&] { collide(a, a, no_pairs); }),
              "collide: method 'kdet_no_pairs' only flags colliding tets and builds no pairs; a Detector's detect() gives the flags");
    EXPECT_EQ(error_message([&] { collide_self(a, no_pairs); }),
              "collide_self: method 'kdet_no_pairs' only flags colliding tets and builds no pairs; a Detector's detect() gives the flags");
    DetectorOptions on_device;
    on_device.results_to_host = false;
    EXPECT_EQ(error_message([&] { collide(a, a, on_device); }),
              "collide: results_to_host=false keeps the pairs on the device, and collide returns them on the host; a Detector "
              "gives device results");
    for (const bool contacts : {true, false}) {
        DetectorOptions extra;
        (contacts ? extra.contacts : extra.distances) = true;
        EXPECT_EQ(error_message([&] { collide_self(a, extra); }),
                  std::string("collide_self: ") + (contacts ? "contacts" : "distances") +
                      " would be computed and dropped, as collide_self returns the pairs alone; a Detector's detect() "
                      "results hold them");
    }
    LocateOptions counts_only;
    counts_only.results_to_host = false;
    const std::vector<double> point = {0.0, 0.0, 0.0};
    EXPECT_EQ(error_message([&] { locate(a, point, counts_only); }),
              "locate: results_to_host=false would leave a one-off point location only its counts (its device arrays "
              "end with its detector); a Detector's locate() keeps device results");
}

TEST(Detector, RejectsBadInputWithClearErrors) {
    Detector detector;
    const std::vector<float> xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const std::vector<std::uint32_t> bad = {0, 1, 2, 4};
    EXPECT_THROW(detector.add_object(xyz.data(), 4, bad.data(), 1), Error);
    std::vector<float> nan_xyz = xyz;
    nan_xyz[4] = std::nanf("");
    const std::vector<std::uint32_t> tet = {0, 1, 2, 3};
    EXPECT_THROW(detector.add_object(nan_xyz.data(), 4, tet.data(), 1), Error);
    const ObjectId id = detector.add_object(xyz.data(), 4, tet.data(), 1);
    EXPECT_THROW(detector.set_positions(id, xyz.data(), 3), Error);
    EXPECT_THROW(detector.set_positions(id + 1, xyz.data(), 4), Error);
    EXPECT_THROW(detector.set_pair_collision(id, id, true), Error);
    EXPECT_EQ(error_message([&] { detector.add_object(xyz.data(), 4, nullptr, 1); }),
              "object 1: the tets' pointer is null, with 1 tets");
    EXPECT_EQ(error_message([&] { detector.set_tets(id, nullptr, 2); }), "object 0: the tets' pointer is null, with 2 tets");
    // A TetMesh with a partial vertex or tet, which num_vertices() and num_tets() would drop.
    TetMesh partial{std::vector<double>(xyz.begin(), xyz.end()), tet};
    partial.positions.pop_back();
    EXPECT_EQ(error_message([&] { detector.add_object(partial); }),
              "add_object: the mesh's positions hold 11 values, not a multiple of 3");
    partial.positions.push_back(1.0);
    partial.tets.pop_back();
    EXPECT_EQ(error_message([&] { detector.set_tets(id, partial); }),
              "object 0: set_tets: the mesh's tets hold 3 indices, not a multiple of 4");
    EXPECT_EQ(error_message([&] { collide_self(partial); }), "add_object: the mesh's tets hold 3 indices, not a multiple of 4");
    EXPECT_EQ(detector.object_count(), 1u);
}

TEST(Detector, ReportsMemoryAndStageTimes) {
    const TetMesh a = random_soup(2000, 3.0, 1.0, 71), b = random_soup(2000, 3.0, 1.0, 72);
    Detector detector;
    detector.add_object(a);
    detector.add_object(b);
    const FrameResult& r = detector.detect();
    EXPECT_GT(r.memory_bytes, 4000u * sizeof(float) * 12);
    EXPECT_EQ(r.memory_bytes, detector.memory_bytes());
    EXPECT_GT(r.times.total, 0.0);
    EXPECT_GE(r.times.total, r.times.populate_grid + r.times.find_candidates);
    EXPECT_GT(r.counts.candidates, 0u);
    EXPECT_GE(r.counts.candidates, r.counts.narrow_phase_candidates);
    EXPECT_GE(r.counts.narrow_phase_candidates, r.counts.colliding_pairs);
    EXPECT_GT(r.counts.grid_cells, 0u);
    EXPECT_LE(r.counts.grid_cells, r.counts.grid_slots);
    EXPECT_GT(r.grid_bytes, 0u);
    EXPECT_GT(r.candidate_bytes, 0u);
    EXPECT_LT(r.grid_bytes + r.candidate_bytes, r.memory_bytes);
}

} // namespace
} // namespace kdet
