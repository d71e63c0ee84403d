// backlash/api/map_mpi.hpp — the MPI ranks of `mpirun -n N backlash map ...` under the facade's
// namespace: backlash/map/mpi.hpp (target backlash::map_mpi, built when BACKLASH_MPI is on).
#pragma once

#include "backlash/api/map.hpp"
#include "backlash/map/mpi.hpp"

namespace backlash::api {

using map::launched_by_mpi;
using map::mpi_transport;

}  // namespace backlash::api
