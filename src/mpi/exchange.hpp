#pragma once
/// @file exchange.hpp
/// @brief Sending each rank its own list of plain records: one MPI_Alltoall of counts, one
/// MPI_Alltoallv of the records.

#include <mpi.h>

#include <cstddef>
#include <type_traits>
#include <vector>

namespace kdet::mpi::detail {

/// @brief Collective: sends @p out[r] to rank r; returns what every rank sent to this one, in rank
/// order. Records travel as raw bytes, counted in records so that counts stay within int.
template <class T>
std::vector<T> all_to_all(MPI_Comm comm, const std::vector<std::vector<T>>& out) {
    static_assert(std::is_trivially_copyable_v<T>, "records travel as raw bytes");
    const std::size_t n = out.size();
    std::vector<int> send_counts(n), recv_counts(n), send_at(n), recv_at(n);
    std::vector<T> send;
    for (std::size_t r = 0; r < n; ++r) {
        send_at[r] = static_cast<int>(send.size());
        send_counts[r] = static_cast<int>(out[r].size());
        send.insert(send.end(), out[r].begin(), out[r].end());
    }
    MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm);
    std::size_t total = 0;
    for (std::size_t r = 0; r < n; ++r) {
        recv_at[r] = static_cast<int>(total);
        total += static_cast<std::size_t>(recv_counts[r]);
    }
    std::vector<T> received(total);
    MPI_Datatype type;
    MPI_Type_contiguous(static_cast<int>(sizeof(T)), MPI_BYTE, &type);
    MPI_Type_commit(&type);
    MPI_Alltoallv(send.data(), send_counts.data(), send_at.data(), type, received.data(), recv_counts.data(),
                  recv_at.data(), type, comm);
    MPI_Type_free(&type);
    return received;
}

} // namespace kdet::mpi::detail
