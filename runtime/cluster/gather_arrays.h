#pragma once
// Every rank's array at rank 0 (MPI_Gather of the lengths, then MPI_Gatherv), for the frame records of
// a batch and the pieces of one frame.
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "cluster/mpi_session.h"

namespace rivulet::cluster {

// Rank 0 gets every rank's `mine` in rank order, the others an empty list. MPI's counts are ints:
// `what` names the data in the error when one rank's array, or all of them together, hold more.
template <class T>
std::vector<std::vector<T>> gather_arrays(const MpiSession& session, const std::vector<T>& mine,
                                          MPI_Datatype type, const char* what) {
    constexpr auto kMaxCount = static_cast<long long>(std::numeric_limits<int>::max());
    if (static_cast<long long>(mine.size()) > kMaxCount)
        throw std::length_error(std::string(what) + ": more than 2^31 values on one rank");
    const int count = static_cast<int>(mine.size());
    const bool root = session.rank() == 0;
    std::vector<int> counts(root ? std::size_t(session.size()) : 0), offsets(counts.size());
    MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, session.comm());
    std::vector<T> all;
    if (root) {
        const long long total = std::accumulate(counts.begin(), counts.end(), 0LL);
        if (total > kMaxCount)
            throw std::length_error(std::string(what) + ": more than 2^31 values from all ranks");
        std::exclusive_scan(counts.begin(), counts.end(), offsets.begin(), 0);
        all.resize(static_cast<std::size_t>(total));
    }
    MPI_Gatherv(mine.data(), count, type, all.data(), counts.data(), offsets.data(), type, 0, session.comm());
    std::vector<std::vector<T>> out(counts.size());
    for (std::size_t r = 0; r < counts.size(); ++r)
        out[r].assign(all.begin() + offsets[r], all.begin() + offsets[r] + counts[r]);
    return out;
}

}  // namespace rivulet::cluster
