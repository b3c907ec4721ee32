#include "cluster/piece_gather.h"

#include <bit>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace rivulet::cluster {
namespace {

// Rank 0 receives every rank's `mine` (counts fit an int: MPI's counts are ints).
template <class T>
std::vector<std::vector<T>> gather_arrays(const MpiSession& session, const std::vector<T>& mine,
                                          MPI_Datatype type) {
    if (mine.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
        throw std::length_error("a mesh piece holds more than 2^31 values: use more ranks");
    const int count = static_cast<int>(mine.size());
    const bool root = session.rank() == 0;
    std::vector<int> counts(root ? std::size_t(session.size()) : 0), offsets(counts.size());
    MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, session.comm());
    std::vector<T> all;
    if (root) {
        const long long total = std::accumulate(counts.begin(), counts.end(), 0LL);
        if (total > std::numeric_limits<int>::max())
            throw std::length_error("the mesh pieces together hold more than 2^31 values");
        std::exclusive_scan(counts.begin(), counts.end(), offsets.begin(), 0);
        all.resize(static_cast<std::size_t>(total));
    }
    MPI_Gatherv(mine.data(), count, type, all.data(), counts.data(), offsets.data(), type, 0, session.comm());
    std::vector<std::vector<T>> out(counts.size());
    for (std::size_t r = 0; r < counts.size(); ++r)
        out[r].assign(all.begin() + offsets[r], all.begin() + offsets[r] + counts[r]);
    return out;
}

}  // namespace

std::vector<MeshPiece> gather_pieces(const MpiSession& session, const MeshPiece& mine) {
    const std::vector<std::uint64_t> about = {mine.particles,
                                              std::uint64_t(mine.axis),
                                              mine.first_block,
                                              mine.end_block,
                                              std::bit_cast<std::uint64_t>(mine.extract_ms),
                                              std::bit_cast<std::uint32_t>(mine.face_lo),
                                              std::bit_cast<std::uint32_t>(mine.face_hi),
                                              std::bit_cast<std::uint32_t>(mine.voxel)};
    const auto abouts = gather_arrays(session, about, MPI_UINT64_T);
    auto vertices = gather_arrays(session, mine.vertices, MPI_FLOAT);
    auto indices = gather_arrays(session, mine.indices, MPI_UINT32_T);
    std::vector<MeshPiece> pieces(abouts.size());
    for (std::size_t r = 0; r < pieces.size(); ++r) {
        MeshPiece& p = pieces[r];
        p.vertices = std::move(vertices[r]), p.indices = std::move(indices[r]);
        p.particles = abouts[r][0], p.axis = static_cast<int>(abouts[r][1]);
        p.first_block = static_cast<std::uint32_t>(abouts[r][2]);
        p.end_block = static_cast<std::uint32_t>(abouts[r][3]);
        p.extract_ms = std::bit_cast<double>(abouts[r][4]);
        p.face_lo = std::bit_cast<float>(static_cast<std::uint32_t>(abouts[r][5]));
        p.face_hi = std::bit_cast<float>(static_cast<std::uint32_t>(abouts[r][6]));
        p.voxel = std::bit_cast<float>(static_cast<std::uint32_t>(abouts[r][7]));
    }
    return pieces;
}

}  // namespace rivulet::cluster
