#pragma once
// Membership of an MPI job for the commands that spread work over ranks (`mpirun -n K rivulet mesh`).
// A process that no MPI launcher started (no mpirun, no srun) is a job of one rank and never calls MPI,
// so the command line works as it does without MPI.
#include <mpi.h>

namespace rivulet::cluster {

class MpiSession {
  public:
    // Joins the job (MPI_Init_thread) when a launcher started the process (launcher_env.h). Rank 0 of a job
    // talks to the others from a second thread while its own thread meshes, hence MPI_THREAD_SERIALIZED.
    MpiSession();
    ~MpiSession();
    MpiSession(const MpiSession&) = delete;
    MpiSession& operator=(const MpiSession&) = delete;

    int rank() const { return rank_; }
    int size() const { return size_; }
    MPI_Comm comm() const { return MPI_COMM_WORLD; }

  private:
    bool joined_ = false;
    int rank_ = 0;
    int size_ = 1;
};

}  // namespace rivulet::cluster
