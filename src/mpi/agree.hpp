#pragma once
/// @file agree.hpp
/// @brief Agreeing on errors across ranks, so that a collective call either completes on every rank or
/// throws the same kdet::Error on every rank, and no rank is left waiting in a collective.

#include <kdet/error.hpp>

#include <mpi.h>

#include <string>

namespace kdet::mpi::detail {

/// @brief Collective: the message of the lowest rank whose @p local_error is not empty ("" when none).
/// @p first_bad is that rank when the caller already knows it from a collective of its own (else -1):
/// then only the message travels.
inline std::string agree(MPI_Comm comm, const std::string& local_error, int first_bad = -1) {
    int rank = 0, size = 0;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &size);
    if (first_bad < 0) {
        int mine = local_error.empty() ? size : rank;
        MPI_Allreduce(&mine, &first_bad, 1, MPI_INT, MPI_MIN, comm);
        if (first_bad == size) return {};
    }
    std::string message = rank == first_bad ? "rank " + std::to_string(rank) + ": " + local_error : std::string();
    unsigned long length = message.size();
    MPI_Bcast(&length, 1, MPI_UNSIGNED_LONG, first_bad, comm);
    message.resize(length);
    MPI_Bcast(message.data(), static_cast<int>(length), MPI_CHAR, first_bad, comm);
    return message;
}

/// @brief Collective: throws on every rank the error of the lowest rank that has one.
inline void agree_or_throw(MPI_Comm comm, const std::string& local_error) {
    const std::string message = agree(comm, local_error);
    if (!message.empty()) throw Error(message);
}

} // namespace kdet::mpi::detail
