// backlash/map/mpi.hpp — the MPI ranks of `mpirun -n N backlash map ...` as a MapTransport
// (map/map.hpp), over Boost.MPI on Debian's OpenMPI.  Target backlash::map_mpi, built when the
// CMake option BACKLASH_MPI is on (the default when MPI and Boost.MPI are found).
#pragma once

#include "backlash/map/map.hpp"

#include <memory>

namespace backlash::map {

/// True when this process was started by an MPI launcher (mpirun/mpiexec/srun set their
/// environment: OMPI_COMM_WORLD_SIZE, PMI_SIZE, PMIX_RANK): only then is MPI initialised, so
/// that a plain `backlash map` never depends on an MPI runtime.
bool launched_by_mpi();

/// MPI initialised (once, for the life of the process) and COMM_WORLD as a transport.
std::unique_ptr<MapTransport> mpi_transport();

}  // namespace backlash::map
