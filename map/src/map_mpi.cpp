// map_mpi.cpp — MapTransport over Boost.MPI (map/mpi.hpp).
#include "backlash/map/mpi.hpp"

#include <boost/mpi/collectives.hpp>
#include <boost/mpi/communicator.hpp>
#include <boost/mpi/environment.hpp>

#include <cstdlib>

namespace backlash::map {

namespace {

class MpiTransport : public MapTransport {
 public:
  int rank() const override { return world_.rank(); }
  int size() const override { return world_.size(); }
  std::vector<std::string> gather(const std::string& piece) override {
    std::vector<std::string> pieces;
    boost::mpi::gather(world_, piece, pieces, 0);
    return pieces;
  }
  void broadcast(std::string& value) override { boost::mpi::broadcast(world_, value, 0); }

 private:
  boost::mpi::communicator world_;
};

}  // namespace

bool launched_by_mpi() {
  for (const char* variable : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (std::getenv(variable)) return true;
  return false;
}

std::unique_ptr<MapTransport> mpi_transport() {
  // MPI_Finalize runs at exit, after every transport is gone.
  static boost::mpi::environment environment(boost::mpi::threading::single, true);
  return std::make_unique<MpiTransport>();
}

}  // namespace backlash::map
