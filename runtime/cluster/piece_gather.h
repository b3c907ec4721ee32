#pragma once
// The pieces of one frame (runtime/lib/mesh_decomposition.h), each meshed on its own rank, brought to
// rank 0.
#include <vector>

#include "cluster/mpi_session.h"
#include "runtime/lib/mesh_decomposition.h"

namespace rivulet::cluster {

// Every rank passes its piece; rank 0 gets all of them in rank order, the others an empty list.
std::vector<MeshPiece> gather_pieces(const MpiSession& session, const MeshPiece& mine);

}  // namespace rivulet::cluster
