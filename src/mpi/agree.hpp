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

/// @brief The collective calls of kdet::mpi::Detector after its construction.
enum class Call : long long { add_object = 1, detect = 2, gather_pairs = 3 };

inline const char* name_of(Call call) {
    switch (call) {
    case Call::add_object: return "add_object()";
    case Call::detect: return "detect()";
    default: return "gather_pairs()";
    }
}

/// @brief Collective, the first step of every collective call: one small reduction of the same shape
/// in all of them, so that ranks out of step (one in add_object(), another in detect(), or
/// gather_pairs() with two roots) all throw instead of waiting in mismatched collectives.
/// @p argument (named @p argument_name) must be alike on every rank too.
inline void agree_on_call(MPI_Comm comm, Call call, long long argument = 0, const char* argument_name = "") {
    const long long mine[4] = {static_cast<long long>(call), -static_cast<long long>(call), argument, -argument};
    long long all[4];
    MPI_Allreduce(mine, all, 4, MPI_LONG_LONG, MPI_MAX, comm);
    if (all[0] != -all[1])
        throw Error(std::string("collective calls out of step: a rank called ") + name_of(static_cast<Call>(-all[1])) +
                    " where another called " + name_of(static_cast<Call>(all[0])) +
                    " (every rank makes the same collective calls in the same order)");
    if (all[2] != -all[3])
        throw Error(std::string(name_of(call)) + ": the ranks give different " + argument_name + "s (" +
                    std::to_string(-all[3]) + " and " + std::to_string(all[2]) + "); give every rank the same");
}

/// @brief Collective: throws on every rank the error of the lowest rank that has one.
inline void agree_or_throw(MPI_Comm comm, const std::string& local_error) {
    const std::string message = agree(comm, local_error);
    if (!message.empty()) throw Error(message);
}

} // namespace kdet::mpi::detail
