#pragma once
/// @file mpi.hpp
/// @brief Distributed detection over MPI (the kdet::mpi target): each rank holds its own part of every
/// object, and the ranks together find the pairs a single Detector holding everything would find.
///
/// Numbering is global, as in the simulation: an object's tets and vertices have global ids (0 up to
/// the object's global counts); each tet is owned by exactly one rank, which gives it as 4 global
/// vertex ids, and each rank holds the positions of every vertex its tets use (a vertex several ranks
/// hold must have the same position on each). Tets of one object that share a global vertex are
/// adjacent, also across ranks, and never reported; switches apply per object as on kdet::Detector.
///
/// Each frame the ranks exchange their parts' bounds and, within them, which cells of a coarse grid
/// their tets occupy; every rank then sends each of its tets to the ranks whose part it may touch
/// (one MPI_Alltoall of counts and one MPI_Alltoallv of tets) and runs a kdet::Detector (CPU or CUDA
/// backend) on its own tets plus those it received. A pair is reported once, on the rank that owns its
/// lower tet, (object, global tet id) ordered as TetPair. See docs/distributed.md.

#include <kdet/detector.hpp>
#include <kdet/mesh.hpp>
#include <kdet/options.hpp>
#include <kdet/results.hpp>

#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace kdet::mpi {

/// @brief One rank's part of an object, in global ids (the arrays stay the caller's).
struct ObjectPart {
    std::size_t global_vertex_count = 0; ///< vertices of the whole object: the same on every rank
    std::size_t global_tet_count = 0;    ///< tets of the whole object: the same on every rank
    const std::uint32_t* vertex_ids = nullptr; ///< global ids of the vertices this rank holds
    PositionsView positions;             ///< their positions, in the order of vertex_ids
    const std::uint32_t* tet_ids = nullptr; ///< global ids of the tets this rank owns
    const std::uint32_t* tets = nullptr; ///< 4 global vertex ids per owned tet
    std::size_t tet_count = 0;
};

/// @brief A part held in vectors, as scatter_mesh() returns it.
struct MeshPart {
    std::size_t global_vertex_count = 0;
    std::size_t global_tet_count = 0;
    std::vector<std::uint32_t> vertex_ids;
    std::vector<double> positions;       ///< x y z per vertex of vertex_ids
    std::vector<std::uint32_t> tet_ids;
    std::vector<std::uint32_t> tets;     ///< 4 global vertex ids per tet of tet_ids

    ObjectPart view() const;
};

/// @brief What one rank exchanged and how long it took, in one detect().
struct ExchangeStats {
    std::uint64_t owned_tets = 0;     ///< tets this rank owns, all objects
    std::uint64_t local_tets = 0;     ///< owned plus received: what its local detector ran on
    std::uint64_t tets_sent = 0;      ///< tet copies sent (a tet sent to two ranks counts twice)
    std::uint64_t tets_received = 0;
    std::uint64_t bytes_sent = 0;     ///< of the tets, plus the bounds and cells every rank gathers
    std::uint64_t bytes_received = 0;
    std::uint32_t ranks_sent_to = 0;  ///< other ranks that got at least one tet from this one
    bool rebuilt = false;             ///< the local detector's set of tets changed (updated with set_tets)
    double exchange_ms = 0;           ///< gathering bounds and cells, choosing and exchanging tets
    double local_ms = 0;              ///< the local detector: building it when needed, detect()
    double total_ms = 0;              ///< the whole detect(), the agreement on errors included
};

/// @brief One rank's result of a distributed detection.
struct FrameResult {
    /// The pairs whose lower tet this rank owns, in global ids, sorted ascending and unique; over all
    /// ranks together, every colliding pair exactly once.
    std::vector<TetPair> pairs;
    std::vector<Contact> contacts;    ///< parallel to pairs when DetectorOptions::contacts is on
    /// [object][k]: 1 when the k-th tet this rank owns (ObjectPart order) collides with any tet.
    std::vector<std::vector<std::uint8_t>> colliding;
    FrameCounts counts;               ///< the local detector's, ghosts' candidates included
    StageTimes times;                 ///< the local detector's
    std::size_t memory_bytes = 0;     ///< the local detector's buffers
    ExchangeStats exchange;
};

/// @brief Finds every colliding pair among the tets of all ranks of a communicator. The constructor,
/// add_object(), detect() and gather_pairs() are collective: every rank calls them in the same order.
/// Ranks out of step in the last three (one in add_object(), another in detect()) throw on every rank
/// instead of waiting; so does gather_pairs() given two roots.
/// Bad input on one rank makes the collective call throw the same one-line kdet::Error on every rank
/// (prefixed "rank R: " with the lowest rank at fault), and leaves every rank's detector as it was.
class Detector {
public:
    /// @brief Works on a duplicate of @p comm; collective. Throws on every rank where a rank turns
    /// DetectorOptions::results_to_host off or distances on (mpi::FrameResult has none), or where the
    /// ranks' method, test, margin or contacts differ.
    explicit Detector(MPI_Comm comm, const DetectorOptions& options = {});
    ~Detector();
    Detector(Detector&&) noexcept;
    Detector& operator=(Detector&&) noexcept;
    Detector(const Detector&) = delete;
    Detector& operator=(const Detector&) = delete;

    /// @brief Collective: adds one object, each rank giving its part (possibly empty), its tets in any
    /// order. Checks ids against the global counts (which every rank must give alike), that each tet's
    /// vertices are held by the rank, that every tet is owned by exactly one rank, that a vertex held
    /// by several ranks has one position and that positions are finite.
    ObjectId add_object(const ObjectPart& part);
    ObjectId add_object(const MeshPart& part) { return add_object(part.view()); }

    /// @brief Local: new positions of this rank's vertices of @p object (vertex_ids' order). A bad
    /// call (wrong count, a non-finite coordinate) keeps the previous positions, and the next detect()
    /// throws its error on every rank; so a rank never leaves the others waiting.
    void set_positions(ObjectId object, const PositionsView& positions);
    void set_positions(ObjectId object, const double* positions, std::size_t vertex_count);
    void set_positions(ObjectId object, const float* positions, std::size_t vertex_count);

    /// @brief Local switches, which every rank must set alike (detect() checks it).
    void set_self_collision(ObjectId object, bool enabled);
    void set_pair_collision(ObjectId a, ObjectId b, bool enabled);

    /// @brief Collective: one detection. The result stays valid until the next call.
    const FrameResult& detect();

    /// @brief Collective: the last detection's pairs of all ranks on @p root, sorted (empty elsewhere).
    /// Throws kdet::Error for a root that is not a rank of the communicator.
    std::vector<TetPair> gather_pairs(int root = 0) const;

    std::size_t object_count() const;
    MPI_Comm communicator() const;
    int rank() const;
    int size() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// @brief Collective: throws on every rank a kdet::Error with the message of the lowest rank whose
/// @p local_error is not empty, prefixed "rank R: "; returns on every rank when none has one. For a
/// caller's own steps on some ranks (reading a file on one) before collective calls.
void agree_on_error(MPI_Comm comm, const std::string& local_error);

/// @brief How partition_tets() splits a scene over ranks.
enum class Partition {
    slabs,  ///< contiguous slabs along the scene's longest axis, equal tet counts (by tet centroid)
    random, ///< every tet to a random rank: the adversarial case for the exchange
};

/// @brief The owning rank of every tet of every object ([object][tet]), all objects split together so
/// that a slab holds the parts of every object that lie in it. Deterministic for a given @p seed.
std::vector<std::vector<int>> partition_tets(const std::vector<const TetMesh*>& objects, int ranks, Partition kind,
                                             std::uint64_t seed = 1);

/// @brief The part of @p mesh that @p owners (one rank per tet) gives @p rank: its tets in increasing
/// id order and the vertices they use, by increasing id. For a caller holding the whole mesh on every
/// rank (tests, benchmarks); scatter_mesh() sends each rank this part from one rank.
MeshPart local_part(const TetMesh& mesh, const std::vector<int>& owners, int rank);

/// @brief Collective: sends each rank its part of @p mesh (read on @p root only), the tets @p owners
/// (also read on root only, one rank per tet) gives it, with the vertices those tets use. Global ids
/// are the mesh's indices.
MeshPart scatter_mesh(MPI_Comm comm, const TetMesh* mesh, const std::vector<int>* owners, int root = 0);

} // namespace kdet::mpi
