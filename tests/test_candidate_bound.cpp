// The lower bound on a frame's candidate pairs (candidate_bound.hpp), which refuses a first frame the
// memory cannot hold before its search counts the pairs: it never exceeds the frame's exact count (here
// brute force's colliding pairs, which are no more than the candidates), on scenes with filters,
// switched-off pairs, adjacency and exclusions, and meets it where every pair holds one point.

#include "exec/cpu_exec.hpp"
#include "pipeline/baselines.hpp"
#include "pipeline/pipeline.hpp"
#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace kdet {
namespace {

using test::identical_tets;
using test::random_soup;

/// The kdet pipeline on the CPU, which records the bound over its grid after each candidate stage.
class BoundRecorder : public Pipeline<CpuExec> {
public:
    using Pipeline<CpuExec>::Pipeline;
    std::uint64_t bound = 0;

protected:
    std::optional<FrameCounters> candidate_stage() override {
        std::optional<FrameCounters> found = Pipeline<CpuExec>::candidate_stage();
        const FrameCounters c = read_counters_now();
        bound = candidate_lower_bound(exec_, scene_view(), grid_, c.cells_claimed, static_cast<std::uint32_t>(tets_.size()),
                                      positions_.size());
        return found;
    }
};

/// A scene: its objects, which pairs of objects are checked (row-major, the diagonal self-collision)
/// and the exclusions (stored ids, ExclusionLists) of a scene of one object.
struct Scene {
    using Excluded = std::vector<std::pair<std::uint32_t, std::uint32_t>>;
    Scene(std::vector<TetMesh> meshes_, std::vector<std::uint8_t> enabled_, int rings_ = 0, Excluded excluded_ = {})
        : meshes(std::move(meshes_)), enabled(std::move(enabled_)), rings(rings_), excluded(std::move(excluded_)) {}
    std::vector<TetMesh> meshes;
    std::vector<std::uint8_t> enabled;
    int rings;
    Excluded excluded;
};

struct Found {
    std::uint64_t bound, candidates;
    FrameResult kdet, brute_force;
};

/// One frame of `pipeline` over `scene`, its tets and vertices stored as Detector stores them.
FrameResult run_frame(PipelineBase& pipeline, const Scene& scene) {
    std::vector<vec3> positions;
    for (const TetMesh& mesh : scene.meshes)
        for (std::size_t v = 0; v < mesh.num_vertices(); ++v)
            positions.push_back(vec3{static_cast<float>(mesh.positions[3 * v]), static_cast<float>(mesh.positions[3 * v + 1]),
                                     static_cast<float>(mesh.positions[3 * v + 2])});
    SceneTopology topology;
    for (std::size_t o = 0, first_vertex = 0; o < scene.meshes.size(); first_vertex += scene.meshes[o].num_vertices(), ++o)
        topology.add_object(positions.data() + first_vertex, static_cast<std::uint32_t>(scene.meshes[o].num_vertices()),
                            scene.meshes[o].tets.data(), scene.meshes[o].num_tets());
    pipeline.set_topology(topology);
    const auto tets = static_cast<std::uint32_t>(topology.tets.size());
    if (scene.rings)
        pipeline.set_exclusions(pipeline.ring_exclusions(topology.tets.data(), tets, 0, topology.vertex_count, scene.rings, 0));
    if (!scene.excluded.empty()) {
        ExclusionLists lists;
        lists.begin.assign(tets + 1, 0);
        for (std::uint32_t t = 0; t < tets; ++t) {
            lists.begin[t] = static_cast<std::uint32_t>(lists.partners.size());
            for (const auto& [a, b] : scene.excluded)
                if (a == t) lists.partners.push_back(b);
        }
        lists.begin[tets] = static_cast<std::uint32_t>(lists.partners.size());
        pipeline.set_exclusions(lists);
    }
    std::vector<vec3> stored(positions.size());
    topology.to_stored_order(0, topology.vertex_count, positions.data(), stored.data());
    pipeline.start({PositionUpload{0, stored.data(), topology.vertex_count}}, {}, scene.enabled);
    FrameResult result;
    EXPECT_EQ(pipeline.finish(result), no_vertex);
    return result;
}

/// The scene's frame with kdet (recording the bound) and with brute force, the oracle.
Found run_scene(const Scene& scene) {
    DetectorOptions options;
    options.initial_candidate_capacity = 1u << 22; // no overflow: the bound is recorded, nothing refused
    BoundRecorder kdet(options);
    const FrameResult found = run_frame(kdet, scene);
    options.method = Method::brute_force_pairs;
    BaselinePipeline<CpuExec> brute_force(options);
    return Found{kdet.bound, found.counts.narrow_phase_candidates, found, run_frame(brute_force, scene)};
}

std::vector<std::uint8_t> all_checked(std::size_t objects, bool self) {
    std::vector<std::uint8_t> enabled(objects * objects, 1);
    for (std::size_t o = 0; o < objects; ++o) enabled[o * objects + o] = self ? 1 : 0;
    return enabled;
}

/// `count` identical tets in which tets 2m and 2m + 1 share their first vertex (one index).
TetMesh identical_pairs_sharing_a_vertex(std::uint32_t count) {
    TetMesh mesh = identical_tets(count);
    for (std::uint32_t t = 1; t < count; t += 2) mesh.tets[4 * t] = mesh.tets[4 * (t - 1)];
    return mesh;
}

TEST(CandidateBound, NeverExceedsTheExactCountAndMeetsItWhereEveryPairHoldsOnePoint) {
    const TetMesh mesh = test::load_model("octopus-low.mesh");
    const double e = test::extent_of(mesh);
    TetMesh folded = mesh; // one object over itself: self-collision past its rings
    const TetMesh copy = test::moved(mesh, 0.2, 0.05 * e, 0.0, 0.0);
    for (std::uint32_t t : copy.tets) folded.tets.push_back(t + static_cast<std::uint32_t>(mesh.num_vertices()));
    folded.positions.insert(folded.positions.end(), copy.positions.begin(), copy.positions.end());
    const TetMesh pile = identical_tets(120), soup = random_soup(1000, 1.0, 0.5, 11), dense = random_soup(500, 0.3, 0.2, 12);
    // Three piles: the first two not checked against each other, only the last with itself.
    std::vector<std::uint8_t> switched(9, 1);
    switched[0 * 3 + 1] = switched[1 * 3 + 0] = switched[0] = switched[4] = 0;
    const std::int64_t n = 120;
    struct Case {
        const char* name;
        Scene scene;
        /// What the bound and the count must be where every pair holds one point; else -1.
        std::int64_t exact_bound;
    };
    const std::vector<Case> cases{
        {"identical tets", {{pile}, all_checked(1, true)}, n * (n - 1) / 2},
        {"identical tets without self-collision", {{pile}, all_checked(1, false)}, 0},
        {"two piles", {{pile, pile}, all_checked(2, false)}, n * n},
        {"three piles, two not checked", {{pile, pile, pile}, switched}, 2 * n * n + n * (n - 1) / 2},
        {"pairs sharing a vertex", {{identical_pairs_sharing_a_vertex(120)}, all_checked(1, true)}, n * (n - 1) / 2 - n / 2},
        {"excluded pairs", {{pile}, all_checked(1, true), 0, {{0, 1}, {0, 5}, {3, 100}, {7, 8}}}, n * (n - 1) / 2 - 4},
        {"random soup", {{soup}, all_checked(1, true)}, -1},
        {"dense soups", {{dense, dense, soup}, all_checked(3, true)}, -1},
        {"a mesh folded over itself, rings", {{folded}, all_checked(1, true), 2}, -1},
        {"a mesh against its copy", {{mesh, copy}, all_checked(2, true)}, -1},
    };
    for (const Case& c : cases) {
        const Found found = run_scene(c.scene);
        const std::uint64_t pairs = found.brute_force.pairs.size();
        EXPECT_EQ(found.kdet.pairs, found.brute_force.pairs) << c.name;
        EXPECT_LE(found.bound, pairs) << c.name;
        EXPECT_LE(pairs, found.candidates) << c.name;
        if (c.exact_bound >= 0) {
            EXPECT_EQ(pairs, static_cast<std::uint64_t>(c.exact_bound)) << c.name;
            EXPECT_EQ(found.bound, static_cast<std::uint64_t>(c.exact_bound)) << c.name;
        } else {
            EXPECT_GT(pairs, 0u) << c.name;
        }
    }
}

TEST(CandidateBound, RefusesAFirstFrameBeforeTheCountAndTheDetectorAnswersTheNext) {
    const std::uint32_t n = 400;
    const std::uint64_t pairs = std::uint64_t{n} * (n - 1) / 2;
    DetectorOptions options;
    options.initial_candidate_capacity = 16;
    // The pile's candidates with their window take 24 bytes each (more than this), a candidate buffer of
    // the guess and the rest far less.
    options.memory_limit = 24 * pairs - 1;
    Detector detector(options);
    const ObjectId pile = detector.add_object(identical_tets(n));
    detector.add_object(random_soup(50, 1.0, 0.3, 9));
    detector.set_self_collision(pile, true);
    const std::string message = test::error_message([&] { detector.detect(); });
    EXPECT_EQ(message.rfind("the frame has at least " + std::to_string(pairs) + " candidate pairs", 0), 0u) << message;
    EXPECT_NE(message.find(std::to_string(24 * pairs) + " bytes ("), std::string::npos) << message;
    detector.set_self_collision(pile, false);
    DetectorOptions unlimited = options;
    unlimited.memory_limit = 0;
    Detector fresh(unlimited);
    fresh.add_object(identical_tets(n));
    fresh.add_object(random_soup(50, 1.0, 0.3, 9));
    EXPECT_EQ(detector.detect().pairs, fresh.detect().pairs);
}

TEST(CandidateBound, AFrameThatFitsIsNotRefused) {
    // The same pile under a limit that holds its need: the bound equals the count here, and the frame
    // runs as without a limit.
    const std::uint32_t n = 400;
    DetectorOptions options;
    options.initial_candidate_capacity = 16;
    Detector unlimited(options);
    const ObjectId a = unlimited.add_object(identical_tets(n));
    unlimited.set_self_collision(a, true);
    const FrameResult expected = unlimited.detect();
    options.memory_limit = unlimited.memory_bytes();
    Detector limited(options);
    const ObjectId b = limited.add_object(identical_tets(n));
    limited.set_self_collision(b, true);
    EXPECT_EQ(limited.detect().pairs, expected.pairs);
}

} // namespace
} // namespace kdet
