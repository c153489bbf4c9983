/// @file partition.cpp
/// @brief Splitting meshes read on one rank over all ranks: partition_tets() and scatter_mesh().

#include "agree.hpp"

#include <kdet/error.hpp>
#include <kdet/mpi.hpp>

#include <algorithm>
#include <limits>
#include <random>
#include <string>

namespace kdet::mpi {

std::vector<std::vector<int>> partition_tets(const std::vector<const TetMesh*>& objects, int ranks, Partition kind,
                                             std::uint64_t seed) {
    if (ranks < 1) throw Error("partition_tets: " + std::to_string(ranks) + " ranks, need at least 1");
    std::vector<std::vector<int>> owners(objects.size());
    if (kind == Partition::random) {
        std::mt19937_64 rng(seed);
        for (std::size_t o = 0; o < objects.size(); ++o) {
            owners[o].resize(objects[o]->num_tets());
            for (int& owner : owners[o]) owner = static_cast<int>(rng() % static_cast<std::uint64_t>(ranks));
        }
        return owners;
    }
    // Slabs: the tets of all objects by their centroids along the scene's longest axis, cut into
    // runs of equal length (ties broken by object and tet, so the cut is deterministic).
    const double inf = std::numeric_limits<double>::infinity();
    double lo[3] = {inf, inf, inf}, hi[3] = {-inf, -inf, -inf};
    for (const TetMesh* mesh : objects)
        for (std::size_t i = 0; i < mesh->positions.size(); ++i) {
            lo[i % 3] = std::min(lo[i % 3], mesh->positions[i]);
            hi[i % 3] = std::max(hi[i % 3], mesh->positions[i]);
        }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
        if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
    struct Key {
        double centroid;
        std::uint32_t object, tet;
    };
    std::vector<Key> keys;
    for (std::size_t o = 0; o < objects.size(); ++o) {
        const TetMesh& mesh = *objects[o];
        owners[o].resize(mesh.num_tets());
        for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
            double c = 0;
            for (int i = 0; i < 4; ++i) c += mesh.positions[3 * std::size_t{mesh.tets[4 * t + static_cast<std::size_t>(i)]} + static_cast<std::size_t>(axis)];
            keys.push_back(Key{c, static_cast<std::uint32_t>(o), static_cast<std::uint32_t>(t)});
        }
    }
    std::sort(keys.begin(), keys.end(), [](const Key& x, const Key& y) {
        if (x.centroid != y.centroid) return x.centroid < y.centroid;
        if (x.object != y.object) return x.object < y.object;
        return x.tet < y.tet;
    });
    for (std::size_t k = 0; k < keys.size(); ++k)
        owners[keys[k].object][keys[k].tet] = static_cast<int>(k * static_cast<std::size_t>(ranks) / keys.size());
    return owners;
}

MeshPart local_part(const TetMesh& mesh, const std::vector<int>& owners, int rank) {
    MeshPart part;
    part.global_vertex_count = mesh.num_vertices();
    part.global_tet_count = mesh.num_tets();
    for (std::size_t t = 0; t < mesh.num_tets() && t < owners.size(); ++t) {
        if (owners[t] != rank) continue;
        part.tet_ids.push_back(static_cast<std::uint32_t>(t));
        part.tets.insert(part.tets.end(), mesh.tets.begin() + 4 * static_cast<std::ptrdiff_t>(t),
                         mesh.tets.begin() + 4 * static_cast<std::ptrdiff_t>(t) + 4);
    }
    part.vertex_ids = part.tets;
    std::sort(part.vertex_ids.begin(), part.vertex_ids.end());
    part.vertex_ids.erase(std::unique(part.vertex_ids.begin(), part.vertex_ids.end()), part.vertex_ids.end());
    for (std::uint32_t v : part.vertex_ids)
        part.positions.insert(part.positions.end(), mesh.positions.begin() + 3 * static_cast<std::ptrdiff_t>(v),
                              mesh.positions.begin() + 3 * static_cast<std::ptrdiff_t>(v) + 3);
    return part;
}

void agree_on_error(MPI_Comm comm, const std::string& local_error) { detail::agree_or_throw(comm, local_error); }

MeshPart scatter_mesh(MPI_Comm comm, const TetMesh* mesh, const std::vector<int>* owners, int root) {
    int rank = 0, size = 1;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &size);
    std::string bad;
    // Root builds every rank's part.
    std::vector<MeshPart> parts;
    unsigned long long counts[2] = {0, 0}; // global vertices and tets
    if (rank == root) {
        if (!mesh || !owners) bad = "scatter_mesh: no mesh or owners on the root rank";
        else if (owners->size() != mesh->num_tets())
            bad = "scatter_mesh: " + std::to_string(owners->size()) + " owners for " + std::to_string(mesh->num_tets()) + " tets";
        for (std::size_t t = 0; bad.empty() && t < mesh->num_tets(); ++t)
            if ((*owners)[t] < 0 || (*owners)[t] >= size)
                bad = "scatter_mesh: tet " + std::to_string(t) + " goes to rank " + std::to_string((*owners)[t]) +
                      ", not one of " + std::to_string(size);
        for (std::size_t i = 0; bad.empty() && i < mesh->tets.size(); ++i)
            if (mesh->tets[i] >= mesh->num_vertices())
                bad = "scatter_mesh: tet " + std::to_string(i / 4) + " uses vertex " + std::to_string(mesh->tets[i]) +
                      ", out of range";
        if (bad.empty()) {
            counts[0] = mesh->num_vertices();
            counts[1] = mesh->num_tets();
            for (int r = 0; r < size; ++r) parts.push_back(local_part(*mesh, *owners, r));
        }
    }
    detail::agree_or_throw(comm, bad);
    MPI_Bcast(counts, 2, MPI_UNSIGNED_LONG_LONG, root, comm);
    MeshPart part;
    part.global_vertex_count = counts[0];
    part.global_tet_count = counts[1];
    // One Scatterv per array, each rank's length from a Scatter of the sizes.
    const auto scatter = [&](const auto& per_rank, auto& out, MPI_Datatype type) {
        std::vector<int> sizes(per_rank.size()), at(per_rank.size());
        using T = typename std::decay_t<decltype(out)>::value_type;
        std::vector<T> flat;
        for (std::size_t r = 0; r < per_rank.size(); ++r) {
            at[r] = static_cast<int>(flat.size());
            sizes[r] = static_cast<int>(per_rank[r].size());
            flat.insert(flat.end(), per_rank[r].begin(), per_rank[r].end());
        }
        int mine = 0;
        MPI_Scatter(sizes.data(), 1, MPI_INT, &mine, 1, MPI_INT, root, comm);
        out.resize(static_cast<std::size_t>(mine));
        MPI_Scatterv(flat.data(), sizes.data(), at.data(), type, out.data(), mine, type, root, comm);
    };
    const auto field = [&](auto member) {
        std::vector<std::decay_t<decltype(MeshPart{}.*member)>> per_rank;
        for (MeshPart& p : parts) per_rank.push_back(std::move(p.*member));
        return per_rank;
    };
    scatter(field(&MeshPart::tet_ids), part.tet_ids, MPI_UINT32_T);
    scatter(field(&MeshPart::tets), part.tets, MPI_UINT32_T);
    scatter(field(&MeshPart::vertex_ids), part.vertex_ids, MPI_UINT32_T);
    scatter(field(&MeshPart::positions), part.positions, MPI_DOUBLE);
    return part;
}

} // namespace kdet::mpi
