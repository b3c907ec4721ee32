#pragma once
// What an MPI launcher tells the processes it starts, read without MPI (so a build without MPI can say
// it cannot join the job).

namespace rivulet::cluster {

// The number of processes in this process's MPI job, from the variables launchers set: Open MPI's
// mpirun (OMPI_COMM_WORLD_SIZE), PMI launchers (PMI_SIZE), Slurm's srun with PMIx (SLURM_NTASKS beside
// PMIX_RANK). 0 when no launcher started this process; 1 for a job of one process.
int launcher_world_size();

}  // namespace rivulet::cluster
