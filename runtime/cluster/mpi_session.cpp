#include "cluster/mpi_session.h"

#include <stdexcept>

#include "cluster/launcher_env.h"

namespace rivulet::cluster {

MpiSession::MpiSession() {
    if (launcher_world_size() == 0) return;
    int provided = MPI_THREAD_SINGLE;
    if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS)
        throw std::runtime_error("MPI_Init_thread failed");
    joined_ = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    if (provided < MPI_THREAD_SERIALIZED && size_ > 1) {
        MPI_Finalize();
        joined_ = false;
        throw std::runtime_error("this MPI library does not offer MPI_THREAD_SERIALIZED, which rank 0 needs");
    }
}

MpiSession::~MpiSession() {
    if (joined_) MPI_Finalize();
}

}  // namespace rivulet::cluster
