#include "cluster/piece_gather.h"

#include <bit>

#include "cluster/gather_arrays.h"

namespace rivulet::cluster {
std::vector<MeshPiece> gather_pieces(const MpiSession& session, const MeshPiece& mine) {
    const std::vector<std::uint64_t> about = {mine.particles,
                                              std::uint64_t(mine.axis),
                                              mine.first_block,
                                              mine.end_block,
                                              std::bit_cast<std::uint64_t>(mine.extract_ms),
                                              std::bit_cast<std::uint32_t>(mine.face_lo),
                                              std::bit_cast<std::uint32_t>(mine.face_hi),
                                              std::bit_cast<std::uint32_t>(mine.voxel)};
    const auto abouts = gather_arrays(session, about, MPI_UINT64_T, "mesh pieces");
    auto vertices = gather_arrays(session, mine.vertices, MPI_FLOAT, "mesh pieces");
    auto indices = gather_arrays(session, mine.indices, MPI_UINT32_T, "mesh pieces");
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
