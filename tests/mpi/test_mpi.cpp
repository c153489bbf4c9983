// Tests of kdet::mpi::Detector, run by ctest under mpirun with 1 to 4 ranks: every scene is split
// over the ranks, and the pairs all ranks report together must be exactly the single Detector's.

#include "../test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/mpi.hpp>
#include <kdet/scenes.hpp>

#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

namespace kdet::test {
namespace {

int world_rank() {
    int r = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
}
int world_size() {
    int s = 0;
    MPI_Comm_size(MPI_COMM_WORLD, &s);
    return s;
}

DetectorOptions one_thread() {
    DetectorOptions options;
    options.threads = 1; // every rank shares the cores with the others
    return options;
}

/// A scene as every rank of the test sees it in full: meshes, switches and per-frame positions.
struct Scenario {
    std::vector<TetMesh> meshes;
    std::vector<bool> self;                               ///< per object
    std::vector<std::pair<ObjectId, ObjectId>> pairs_off;
    std::vector<std::vector<std::vector<double>>> frames; ///< [frame][object] x y z; the rest shape first
};

Scenario scenario(std::vector<TetMesh> meshes) {
    Scenario s;
    s.self.assign(meshes.size(), false);
    s.frames.emplace_back();
    for (const TetMesh& m : meshes) s.frames.back().push_back(m.positions);
    s.meshes = std::move(meshes);
    return s;
}

std::vector<double> held_positions(const mpi::MeshPart& part, const std::vector<double>& all) {
    std::vector<double> out;
    for (std::uint32_t v : part.vertex_ids)
        for (int k = 0; k < 3; ++k) out.push_back(all[3 * v + k]);
    return out;
}

/// A part's tets and vertices in descending id order, as a simulation's own numbering may give them.
mpi::MeshPart reversed(const mpi::MeshPart& part) {
    mpi::MeshPart out = part;
    const std::size_t nv = part.vertex_ids.size(), nt = part.tet_ids.size();
    for (std::size_t v = 0; v < nv; ++v) {
        out.vertex_ids[v] = part.vertex_ids[nv - 1 - v];
        for (int c = 0; c < 3; ++c) out.positions[3 * v + c] = part.positions[3 * (nv - 1 - v) + c];
    }
    for (std::size_t t = 0; t < nt; ++t) {
        out.tet_ids[t] = part.tet_ids[nt - 1 - t];
        for (int c = 0; c < 4; ++c) out.tets[4 * t + c] = part.tets[4 * (nt - 1 - t) + c];
    }
    return out;
}

enum class PartOrder { ascending, descending };

/// Runs @p s split as @p owners on every rank and on one CPU Detector, frame by frame, and compares;
/// @p rebuilt, when given, gets per frame whether any rank's local detector changed its set of tets.
void expect_same_as_single(const Scenario& s, const std::vector<std::vector<int>>& owners,
                           const DetectorOptions& options = one_thread(), std::vector<int>* rebuilt = nullptr,
                           PartOrder order = PartOrder::ascending) {
    const int rank = world_rank();
    mpi::Detector distributed(MPI_COMM_WORLD, options);
    DetectorOptions reference = options; // one process on the CPU: the answer every backend must give
    reference.backend = Backend::cpu;
    Detector single(reference);
    std::vector<mpi::MeshPart> parts;
    for (std::size_t o = 0; o < s.meshes.size(); ++o) {
        const mpi::MeshPart part = mpi::local_part(s.meshes[o], owners[o], rank);
        parts.push_back(order == PartOrder::ascending ? part : reversed(part));
        distributed.add_object(parts.back());
        single.add_object(s.meshes[o]);
        distributed.set_self_collision(static_cast<ObjectId>(o), s.self[o]);
        single.set_self_collision(static_cast<ObjectId>(o), s.self[o]);
    }
    for (const auto& p : s.pairs_off) {
        distributed.set_pair_collision(p.first, p.second, false);
        single.set_pair_collision(p.first, p.second, false);
    }
    for (std::size_t f = 0; f < s.frames.size(); ++f) {
        for (std::size_t o = 0; o < s.meshes.size(); ++o) {
            const std::vector<double> held = held_positions(parts[o], s.frames[f][o]);
            distributed.set_positions(static_cast<ObjectId>(o), held.data(), held.size() / 3);
            single.set_positions(static_cast<ObjectId>(o), s.frames[f][o].data(), s.meshes[o].num_vertices());
        }
        const mpi::FrameResult& mine = distributed.detect();
        const FrameResult& expected = single.detect();
        const std::set<TetPair> all(expected.pairs.begin(), expected.pairs.end());
        for (std::size_t k = 0; k < mine.pairs.size(); ++k) {
            const TetPair& p = mine.pairs[k];
            EXPECT_EQ(owners[p.object_a][p.tet_a], rank) << "frame " << f << ": a pair reported off its lower tet's rank";
            EXPECT_TRUE(all.count(p)) << "frame " << f << ": (" << p.object_a << ", " << p.tet_a << ") x (" << p.object_b
                                      << ", " << p.tet_b << ") is not a pair of the single detector";
            if (options.contacts && all.count(p)) {
                const std::size_t at = static_cast<std::size_t>(std::lower_bound(expected.pairs.begin(), expected.pairs.end(), p) -
                                                                expected.pairs.begin());
                EXPECT_EQ(mine.contacts[k].depth, expected.contacts[at].depth);
                for (int c = 0; c < 3; ++c) EXPECT_EQ(mine.contacts[k].direction[c], expected.contacts[at].direction[c]);
            }
        }
        for (std::size_t o = 0; o < s.meshes.size(); ++o)
            for (std::size_t k = 0; k < parts[o].tet_ids.size(); ++k)
                EXPECT_EQ(mine.colliding[o][k], expected.colliding[o][parts[o].tet_ids[k]])
                    << "frame " << f << ": flag of object " << o << " tet " << parts[o].tet_ids[k];
        const std::vector<TetPair> gathered = distributed.gather_pairs(0);
        if (rank == 0) {
            EXPECT_EQ(gathered.size(), expected.pairs.size()) << "frame " << f;
            EXPECT_TRUE(gathered == expected.pairs) << "frame " << f << ": the ranks' pairs differ from the single detector's";
        }
        EXPECT_EQ(mine.exchange.local_tets, mine.exchange.owned_tets + mine.exchange.tets_received);
        if (rebuilt) {
            int here = mine.exchange.rebuilt ? 1 : 0, any = 0;
            MPI_Allreduce(&here, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
            rebuilt->push_back(any);
        }
    }
}

void expect_same_with_both_partitions(const Scenario& s) {
    std::vector<const TetMesh*> meshes;
    for (const TetMesh& m : s.meshes) meshes.push_back(&m);
    for (mpi::Partition kind : {mpi::Partition::slabs, mpi::Partition::random}) {
        SCOPED_TRACE(kind == mpi::Partition::slabs ? "slabs" : "random");
        expect_same_as_single(s, mpi::partition_tets(meshes, world_size(), kind, 7));
    }
}

std::vector<int> all_to(const TetMesh& mesh, int rank) { return std::vector<int>(mesh.num_tets(), rank); }

/// The message every rank got from @p action, checked to be the same on all ranks.
std::string same_error_everywhere(const std::function<void()>& action) {
    const std::string message = error_message(action);
    unsigned long length = message.size(), longest = 0;
    MPI_Allreduce(&length, &longest, 1, MPI_UNSIGNED_LONG, MPI_MAX, MPI_COMM_WORLD);
    std::string padded = message;
    padded.resize(longest, '\0');
    std::string first = padded;
    MPI_Bcast(first.data(), static_cast<int>(longest), MPI_CHAR, 0, MPI_COMM_WORLD);
    EXPECT_EQ(padded, first) << "ranks disagree on the error";
    return message;
}

TEST(Mpi, RandomSoupsOverFrames) {
    Scenario s = scenario({random_soup(1500, 1.0, 1.5, 11), random_soup(1500, 1.0, 1.5, 12)});
    s.self[0] = true;
    for (double dx : {0.03, 0.2}) { // the soups slide past each other: the tets exchanged change
        s.frames.push_back(s.frames[0]);
        for (std::size_t i = 0; i < s.frames.back()[1].size(); i += 3) s.frames.back()[1][i] += dx;
    }
    expect_same_with_both_partitions(s);
}

TEST(Mpi, TwoThreadsPerRankAsOne) {
    // The layer's per-tet functors share a rank's tets among its threads (above 512 tets): the records
    // must come out as with one thread.
    Scenario s = scenario({random_soup(1500, 1.0, 1.5, 71), random_soup(1500, 1.0, 1.5, 72)});
    s.self[1] = true;
    s.frames.push_back(s.frames[0]);
    for (std::size_t i = 0; i < s.frames.back()[0].size(); i += 3) s.frames.back()[0][i] += 0.1;
    DetectorOptions options;
    options.threads = 2;
    std::vector<const TetMesh*> meshes{&s.meshes[0], &s.meshes[1]};
    for (mpi::Partition kind : {mpi::Partition::slabs, mpi::Partition::random})
        expect_same_as_single(s, mpi::partition_tets(meshes, world_size(), kind, 17), options);
}

TEST(Mpi, RealMeshes) {
    const TetMesh bunny = load_model("bunny.mesh");
    const TetMesh octopus = load_model("octopus-low.mesh");
    const double e = extent_of(bunny);
    Scenario s = scenario({bunny, moved(bunny, 0.4, 0.8 * e, 0.1 * e, 0.0), octopus});
    s.self[2] = true;
    s.pairs_off.push_back({0, 2});
    expect_same_with_both_partitions(s);
}

TEST(Mpi, FoldedBarSelfCollides) {
    const TetMesh bar = make_box_mesh(40, 3, 3, 0.1);
    TetMesh folded = bar;
    fold_bar(bar, 2.0 * 3.14159265358979 * 1.15, folded.positions);
    Scenario s = scenario({folded});
    s.self[0] = true;
    s.frames.emplace_back();
    s.frames.back().emplace_back();
    fold_bar(bar, 2.0 * 3.14159265358979 * 1.3, s.frames.back()[0]);
    expect_same_with_both_partitions(s);
}

TEST(Mpi, ThesisScenesAtResolutionOne) {
    use_default_data_dir();
    for (const char* name : {"armadillos", "buddha_and_armadillo", "bunny_and_planck"}) {
        SCOPED_TRACE(name);
        std::unique_ptr<Scene> scene;
        try {
            scene = open_scene(name, SceneRequest{});
        } catch (const Error& e) {
            GTEST_SKIP() << "thesis scenes not prepared ('kdet prepare -r 1'): " << e.what();
        }
        std::vector<TetMesh> meshes;
        for (std::size_t o = 0; o < scene->num_objects(); ++o) meshes.push_back(scene->rest_mesh(o));
        Scenario s = scenario(meshes);
        s.frames.clear();
        for (std::size_t o = 0; o < scene->num_objects(); ++o) {
            s.self[o] = scene->checks_self(o);
            for (std::size_t p = o + 1; p < scene->num_objects(); ++p)
                if (!scene->checks_pair(o, p)) s.pairs_off.push_back({static_cast<ObjectId>(o), static_cast<ObjectId>(p)});
        }
        const int frames = scene->num_frames();
        for (int f : {frames / 2, (2 * frames) / 3}) {
            s.frames.emplace_back(scene->num_objects());
            for (std::size_t o = 0; o < scene->num_objects(); ++o) scene->positions(o, f, s.frames.back()[o]);
        }
        expect_same_with_both_partitions(s);
    }
}

TEST(Mpi, RankWithoutTetsObjectOnSomeRanksAllOnOneRank) {
    const int size = world_size();
    Scenario s = scenario({random_soup(800, 1.0, 1.0, 21), random_soup(800, 1.0, 1.0, 22)});
    s.self[1] = true;
    std::vector<int> spread(s.meshes[0].num_tets());
    for (std::size_t t = 0; t < spread.size(); ++t) spread[t] = static_cast<int>(t % static_cast<std::size_t>(std::max(size - 1, 1)));
    {
        SCOPED_TRACE("the last rank owns no tet");
        expect_same_as_single(s, {spread, spread});
    }
    {
        SCOPED_TRACE("object 1 on the last rank only");
        expect_same_as_single(s, {spread, all_to(s.meshes[1], size - 1)});
    }
    {
        SCOPED_TRACE("every tet on the last rank");
        expect_same_as_single(s, {all_to(s.meshes[0], size - 1), all_to(s.meshes[1], size - 1)});
    }
}

TEST(Mpi, ContactsAsTheSingleDetectors) {
    const TetMesh bunny = load_model("bunny.mesh");
    const Scenario s = scenario({bunny, moved(bunny, 0.3, 0.8 * extent_of(bunny), 0.0, 0.0)});
    DetectorOptions options = one_thread();
    options.contacts = true;
    options.narrow_phase = NarrowPhase::sat;
    std::vector<const TetMesh*> meshes{&s.meshes[0], &s.meshes[1]};
    expect_same_as_single(s, mpi::partition_tets(meshes, world_size(), mpi::Partition::random, 3), options);
}

TEST(Mpi, ContactsAsTheSingleDetectorsWhateverOrderARankGivesItsTets) {
    // A pair's contact is computed with its lower tet first: a rank's local detector must meet two owned
    // tets in that order too, or depth and direction differ in their last bits (seen on these soups).
    Scenario s = scenario({random_soup(1500, 1.0, 1.5, 11), random_soup(1500, 1.0, 1.5, 12)});
    s.self[0] = true;
    DetectorOptions options = one_thread();
    options.contacts = true;
    std::vector<const TetMesh*> meshes{&s.meshes[0], &s.meshes[1]};
    const std::vector<std::vector<int>> owners = mpi::partition_tets(meshes, world_size(), mpi::Partition::random, 3);
    for (PartOrder order : {PartOrder::ascending, PartOrder::descending}) {
        SCOPED_TRACE(order == PartOrder::ascending ? "ascending ids" : "descending ids");
        expect_same_as_single(s, owners, options, nullptr, order);
    }
}

TEST(Mpi, PairsWithinAMarginAsTheSingleDetectors) {
    // Two soups apart by more than their tets' size: only the margin brings pairs, and the exchange
    // must send the tets that are near another rank's part by the margin, not only those overlapping it.
    Scenario s = scenario({random_soup(800, 1.0, 1.0, 21), random_soup(800, 1.0, 1.0, 22)});
    for (std::size_t i = 0; i < s.frames[0][1].size(); i += 3) s.frames[0][1][i] += 1.04;
    s.self[0] = true;
    DetectorOptions options = one_thread();
    options.margin = 0.08f;
    std::vector<const TetMesh*> meshes{&s.meshes[0], &s.meshes[1]};
    for (mpi::Partition kind : {mpi::Partition::slabs, mpi::Partition::random})
        expect_same_as_single(s, mpi::partition_tets(meshes, world_size(), kind, 5), options);
}

TEST(Mpi, GhostsKeptOrChangedAsTheSingleDetectors) {
    // Scaling every coordinate by a power of two (per axis) scales every box and cell bound exactly:
    // the tets exchanged stay the same while the positions change, so the local detectors keep their
    // tets and only take the new positions (contacts, which scale, show stale ones). A slide of one
    // object changes the tets exchanged.
    Scenario s = scenario({random_soup(1200, 1.0, 1.5, 61), random_soup(1200, 1.0, 1.5, 62)});
    s.self[0] = true;
    const auto scaled = [](std::vector<std::vector<double>> frame) {
        for (auto& xyz : frame)
            for (std::size_t i = 0; i < xyz.size(); i += 3) {
                xyz[i] *= 2.0;
                xyz[i + 1] *= 4.0;
            }
        return frame;
    };
    std::vector<std::vector<double>> slid = s.frames[0];
    for (std::size_t i = 0; i < slid[1].size(); i += 3) slid[1][i] += 0.3;
    s.frames = {s.frames[0], s.frames[0], scaled(s.frames[0]), slid, scaled(slid)};
    DetectorOptions options = one_thread();
    options.contacts = true;
    options.narrow_phase = NarrowPhase::sat;
    std::vector<const TetMesh*> meshes{&s.meshes[0], &s.meshes[1]};
    for (mpi::Partition kind : {mpi::Partition::slabs, mpi::Partition::random}) {
        SCOPED_TRACE(kind == mpi::Partition::slabs ? "slabs" : "random");
        std::vector<int> rebuilt;
        expect_same_as_single(s, mpi::partition_tets(meshes, world_size(), kind, 13), options, &rebuilt);
        ASSERT_EQ(rebuilt.size(), 5u);
        EXPECT_EQ(rebuilt[0], 1) << "the first frame builds the local detectors";
        EXPECT_EQ(rebuilt[1], 0) << "nothing moved";
        EXPECT_EQ(rebuilt[2], 0) << "scaled: the same tets exchanged";
        if (world_size() > 1 && kind == mpi::Partition::slabs) {
            EXPECT_EQ(rebuilt[3], 1) << "slid: other tets exchanged";
        }
        EXPECT_EQ(rebuilt[4], 0) << "scaled after the slide: the same tets exchanged";
    }
}

TEST(Mpi, CudaBackendOnEveryRankAsTheCpu) {
    std::string reason;
    if (!cuda_available(&reason)) GTEST_SKIP() << "CUDA backend not tested: " << reason;
    Scenario s = scenario({random_soup(1500, 1.0, 1.5, 51), random_soup(1500, 1.0, 1.5, 52)});
    s.self[1] = true;
    s.frames.push_back(s.frames[0]);
    for (std::size_t i = 0; i < s.frames.back()[0].size(); i += 3) s.frames.back()[0][i] += 0.05;
    DetectorOptions cuda = one_thread();
    cuda.backend = Backend::cuda; // every rank on the one GPU here; one GPU per rank in production
    std::vector<const TetMesh*> meshes{&s.meshes[0], &s.meshes[1]};
    expect_same_as_single(s, mpi::partition_tets(meshes, world_size(), mpi::Partition::slabs, 9), cuda);
}

TEST(Mpi, NoObjectsNoPairs) {
    mpi::Detector detector(MPI_COMM_WORLD, one_thread());
    EXPECT_TRUE(detector.detect().pairs.empty());
    EXPECT_TRUE(detector.gather_pairs(0).empty());
}

TEST(Mpi, SharedVertexMovedOnOneRankFailsOnEveryRank) {
    const int size = world_size(), rank = world_rank();
    if (size < 2) GTEST_SKIP() << "needs two ranks";
    const TetMesh box = make_box_mesh(8, 2, 2, 1.0);
    const std::vector<int> owners = mpi::partition_tets({&box}, size, mpi::Partition::slabs)[0];
    // A vertex that tets of rank 0 and of rank 1 both use: each of them holds a copy.
    std::vector<int> users(box.num_vertices(), 0);
    for (std::size_t t = 0; t < box.num_tets(); ++t)
        for (int c = 0; c < 4; ++c)
            if (owners[t] <= 1) users[box.tets[4 * t + c]] |= 1 << owners[t];
    const auto shared = static_cast<std::uint32_t>(std::find(users.begin(), users.end(), 3) - users.begin());
    ASSERT_LT(shared, box.num_vertices());
    const mpi::MeshPart part = mpi::local_part(box, owners, rank);
    mpi::Detector detector(MPI_COMM_WORLD, one_thread());
    const ObjectId id = detector.add_object(part);
    detector.set_self_collision(id, true);
    // Moved on a fresh detector (the ghosts numbered anew), then by one float step after a good frame
    // (the same ghosts as before, only their positions refreshed): the same error either way.
    for (const bool after_a_frame : {false, true}) {
        SCOPED_TRACE(after_a_frame ? "after a frame" : "first frame");
        std::vector<double> positions = part.positions;
        if (after_a_frame) {
            detector.set_positions(id, positions.data(), positions.size() / 3);
            detector.detect();
        }
        if (rank == 1) {
            const std::size_t k = static_cast<std::size_t>(
                std::lower_bound(part.vertex_ids.begin(), part.vertex_ids.end(), shared) - part.vertex_ids.begin());
            positions[3 * k] = after_a_frame ? std::nextafter(static_cast<float>(positions[3 * k]), 1e30f) : positions[3 * k] + 0.25;
        }
        detector.set_positions(id, positions.data(), positions.size() / 3);
        const std::string message = same_error_everywhere([&] { detector.detect(); });
        EXPECT_NE(message.find("object 0: vertex " + std::to_string(shared) + " has different positions here and on the rank owning tet"),
                  std::string::npos)
            << message;
    }
}

TEST(Mpi, ScatterMeshGivesEachRankItsPart) {
    const TetMesh soup = random_soup(300, 1.0, 1.0, 31);
    const std::vector<std::vector<int>> owners =
        mpi::partition_tets({&soup}, world_size(), mpi::Partition::random, 5);
    const bool root = world_rank() == 0;
    const mpi::MeshPart got = mpi::scatter_mesh(MPI_COMM_WORLD, root ? &soup : nullptr, root ? &owners[0] : nullptr);
    const mpi::MeshPart expected = mpi::local_part(soup, owners[0], world_rank());
    EXPECT_EQ(got.global_tet_count, soup.num_tets());
    EXPECT_EQ(got.global_vertex_count, soup.num_vertices());
    EXPECT_EQ(got.tet_ids, expected.tet_ids);
    EXPECT_EQ(got.tets, expected.tets);
    EXPECT_EQ(got.vertex_ids, expected.vertex_ids);
    EXPECT_EQ(got.positions, expected.positions);
}

TEST(Mpi, SlabsAreContiguousAlongTheLongestAxis) {
    const TetMesh bar = make_box_mesh(40, 2, 2, 0.1); // longest along x
    const std::vector<std::vector<int>> owners = mpi::partition_tets({&bar}, 3, mpi::Partition::slabs);
    double last_x[3] = {-1e300, -1e300, -1e300}, first_x[3] = {1e300, 1e300, 1e300};
    std::size_t count[3] = {0, 0, 0};
    for (std::size_t t = 0; t < bar.num_tets(); ++t) {
        double x = 0;
        for (int c = 0; c < 4; ++c) x += bar.positions[3 * bar.tets[4 * t + c]] / 4;
        const int r = owners[0][t];
        last_x[r] = std::max(last_x[r], x);
        first_x[r] = std::min(first_x[r], x);
        ++count[r];
    }
    EXPECT_LE(last_x[0], first_x[1]);
    EXPECT_LE(last_x[1], first_x[2]);
    EXPECT_EQ(count[0], count[1]);
    EXPECT_EQ(count[1], count[2]);
}

TEST(Mpi, BadInputOnOneRankFailsOnEveryRank) {
    const int rank = world_rank(), size = world_size(), last = size - 1;
    const TetMesh soup = random_soup(200, 1.0, 1.0, 41);
    std::vector<int> owners(soup.num_tets());
    for (std::size_t t = 0; t < owners.size(); ++t) owners[t] = static_cast<int>(t % static_cast<std::size_t>(size));
    const mpi::MeshPart good = mpi::local_part(soup, owners, rank);
    mpi::Detector detector(MPI_COMM_WORLD, one_thread());

    mpi::MeshPart bad = good;
    if (rank == last) bad.tet_ids[0] = static_cast<std::uint32_t>(soup.num_tets());
    EXPECT_EQ(same_error_everywhere([&] { detector.add_object(bad); }),
              "rank " + std::to_string(last) + ": object 0: tet id 200 out of range (200 tets)");

    bad = good;
    if (rank == last) bad.tets[1] = 100000;
    EXPECT_EQ(same_error_everywhere([&] { detector.add_object(bad); }),
              "rank " + std::to_string(last) + ": object 0: tet " + std::to_string(last) +
                  " uses vertex 100000, out of range (800 vertices)");

    if (size > 1) {
        bad = good;
        if (rank == last) bad.global_tet_count = 201;
        EXPECT_EQ(same_error_everywhere([&] { detector.add_object(bad); }),
                  "object 0: ranks give different global tet counts (200 and 201)");

        // One more vertex, held by every rank at a position of its own.
        mpi::MeshPart shared = good;
        shared.global_vertex_count = 801;
        shared.vertex_ids.push_back(800);
        shared.positions.insert(shared.positions.end(), {5.0, 5.0, 5.0 + rank});
        EXPECT_EQ(same_error_everywhere([&] { detector.add_object(shared); }),
                  "rank " + std::to_string(size - 1) + ": object 0: vertex 800 has different positions on ranks 0 and 1");

        mpi::MeshPart twice = good;
        twice.tet_ids[0] = 0; // rank 0 owns tet 0 already
        EXPECT_EQ(same_error_everywhere([&] { detector.add_object(twice); }),
                  "rank 0: object 0: tet 0 is owned by ranks 0 and 1");
    }
    // The last rank leaves out the last tet it owns: no rank owns it.
    mpi::MeshPart short_part = good;
    std::uint32_t left_out = 0;
    for (std::size_t t = 0; t < owners.size(); ++t)
        if (owners[t] == last) left_out = static_cast<std::uint32_t>(t);
    if (rank == last) {
        short_part.tet_ids.pop_back();
        short_part.tets.resize(4 * short_part.tet_ids.size());
    }
    const int directory = static_cast<int>(std::uint64_t{left_out} * static_cast<std::uint64_t>(size) / soup.num_tets());
    EXPECT_EQ(same_error_everywhere([&] { detector.add_object(short_part); }),
              "rank " + std::to_string(directory) + ": object 0: tet " + std::to_string(left_out) +
                  " is owned by no rank (each of the 200 tets must be owned by one)");
    EXPECT_EQ(detector.object_count(), 0u);

    // A NaN on the last rank: detect() fails everywhere, and the detector keeps the previous positions.
    const ObjectId id = detector.add_object(good);
    detector.set_self_collision(id, true);
    detector.detect();
    const std::vector<TetPair> before = detector.gather_pairs(0);
    std::vector<double> nan_positions = good.positions;
    if (rank == last && !nan_positions.empty()) nan_positions[1] = std::numeric_limits<double>::quiet_NaN();
    detector.set_positions(id, nan_positions.data(), nan_positions.size() / 3);
    if (rank == last && !good.positions.empty()) {
        EXPECT_EQ(same_error_everywhere([&] { detector.detect(); }),
                  "rank " + std::to_string(last) + ": object 0: vertex " + std::to_string(good.vertex_ids[0]) +
                      " has a non-finite coordinate (or one beyond float range)");
    } else {
        same_error_everywhere([&] { detector.detect(); });
    }
    detector.detect();
    EXPECT_TRUE(detector.gather_pairs(0) == before);

    // Switches set differently on one rank.
    if (rank == last) detector.set_self_collision(id, false);
    if (size > 1) {
        EXPECT_EQ(same_error_everywhere([&] { detector.detect(); }),
                  "self-collision or pair switches differ between ranks (set them alike on every rank)");
    }
    if (rank == last) detector.set_self_collision(id, true);
    EXPECT_EQ(same_error_everywhere([&] { (void)detector.gather_pairs(size); }),
              "gather_pairs: root " + std::to_string(size) + " is not a rank of the communicator (0 to " +
                  std::to_string(last) + ")");
}

TEST(Mpi, RanksOutOfStepFailOnEveryRankInsteadOfWaiting) {
    const int rank = world_rank(), size = world_size();
    if (size < 2) GTEST_SKIP() << "needs two ranks";
    const TetMesh soup = random_soup(200, 1.0, 1.0, 43);
    std::vector<int> owners(soup.num_tets());
    for (std::size_t t = 0; t < owners.size(); ++t) owners[t] = static_cast<int>(t % static_cast<std::size_t>(size));
    const mpi::MeshPart part = mpi::local_part(soup, owners, rank);
    mpi::Detector detector(MPI_COMM_WORLD, one_thread());
    // Rank 0 detects while the others add an object.
    const std::string message = same_error_everywhere([&] {
        if (rank == 0) detector.detect();
        else detector.add_object(part);
    });
    EXPECT_EQ(message, "collective calls out of step: a rank called add_object() where another called detect() (every rank "
                       "makes the same collective calls in the same order)");
    EXPECT_EQ(detector.object_count(), 0u);
    // Each rank names itself the root.
    EXPECT_EQ(same_error_everywhere([&] { (void)detector.gather_pairs(rank); }),
              "gather_pairs(): the ranks give different roots (0 and " + std::to_string(size - 1) + "); give every rank the same");
    // In step again, it works.
    detector.add_object(part);
    detector.detect();
    EXPECT_EQ(detector.object_count(), 1u);
}

TEST(Mpi, OptionsOneRankRefusesOrThatDecideTheAnswerDifferFailOnEveryRank) {
    const int rank = world_rank(), size = world_size(), last = size - 1;
    DetectorOptions options = one_thread();
    if (rank == last) options.results_to_host = false;
    EXPECT_EQ(same_error_everywhere([&] { mpi::Detector refused(MPI_COMM_WORLD, options); }),
              "rank " + std::to_string(last) + ": kdet::mpi::Detector needs results_to_host: it filters the local pairs on the host");
    options = one_thread();
    options.distances = true;
    EXPECT_EQ(same_error_everywhere([&] { mpi::Detector refused(MPI_COMM_WORLD, options); }),
              "rank 0: kdet::mpi::Detector returns no distances: its FrameResult has pairs, flags and contacts");
    if (size > 1) {
        options = one_thread();
        if (rank == last) options.margin = 0.02f;
        EXPECT_EQ(same_error_everywhere([&] { mpi::Detector refused(MPI_COMM_WORLD, options); }),
                  "the method, test, margin or contacts of kdet::mpi::Detector differ between ranks (give every rank the same)");
    }
    options = one_thread();
    if (rank == last) options.threads = 2; // threads may differ: no error
    EXPECT_NO_THROW(mpi::Detector(MPI_COMM_WORLD, options));
}

} // namespace
} // namespace kdet::test

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    ::testing::InitGoogleTest(&argc, argv);
    if (kdet::test::world_rank() != 0) {
        // One report: rank 0 prints; the others print only their failures.
        auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
        delete listeners.Release(listeners.default_result_printer());
    }
    int failed = RUN_ALL_TESTS() != 0, any = 0;
    MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    MPI_Finalize();
    return any;
}
