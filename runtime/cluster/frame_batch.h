#pragma once
// The frames of a sequence spread over the ranks of an MPI job. Rank 0 hands out frame indices as ranks
// ask for work, so uneven frames balance, and meshes frames itself between hand-outs; at the end it
// gathers every frame's outcome. A frame that fails is an outcome like any other: it stops no rank.
#include <functional>
#include <string>
#include <vector>

#include "cluster/mpi_session.h"

namespace rivulet::cluster {

struct FrameOutcome {
    int index = 0;
    int rank = 0;
    bool ok = true;
    std::string error;   // why the frame failed
    double seconds = 0;  // wall time of the frame on its rank (read, extract, write)
    std::string record;  // what the caller says about the frame (its JSON record, serialized)
};

struct RankLoad {
    int frames = 0;
    double busy_seconds = 0;
};

struct BatchResult {
    std::vector<FrameOutcome> frames;  // rank 0: every frame, in frame order; other ranks: empty
    std::vector<RankLoad> ranks;       // rank 0: per rank
    double wall_seconds = 0;           // rank 0: from the start to the last frame's end
    int failed = 0;                    // every rank: frames that failed on any rank
};

// Runs mesh_frame(i) on this rank for its share of the frames 0..count-1; mesh_frame reports a failure
// in its outcome rather than by throwing. On rank 0, progress(done) follows the frames as they complete
// (called from one thread at a time). Every rank of the session must call it.
BatchResult run_frames_over_ranks(const MpiSession& session, int count,
                                  const std::function<FrameOutcome(int)>& mesh_frame,
                                  const std::function<void(int)>& progress);

}  // namespace rivulet::cluster
