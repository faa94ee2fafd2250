#include "twincal/distributed/mpi_environment.hpp"

#include <cstdlib>

#include <fmt/format.h>

#include "twincal/core/error.hpp"

namespace twincal {

MpiEnvironment::MpiEnvironment(int& argc, char**& argv) { initialize(&argc, &argv); }

MpiEnvironment::MpiEnvironment() { initialize(nullptr, nullptr); }

void MpiEnvironment::initialize(int* argc, char*** argv) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized != 0) {
    throw Error("MPI", "MPI: already initialized; rule: one MpiEnvironment per process");
  }
  int provided = MPI_THREAD_SINGLE;
  if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
    throw Error("MPI", "MPI: MPI_Init_thread failed");
  }
  if (provided < MPI_THREAD_FUNNELED) {
    MPI_Finalize();
    throw Error("MPI", fmt::format("MPI: the library provides thread level {}; rule: twincal "
                                   "needs MPI_THREAD_FUNNELED ({}) or more",
                                   provided, MPI_THREAD_FUNNELED));
  }
  MPI_Comm_dup(MPI_COMM_WORLD, &communicator_);
  int rank = 0;
  int size = 1;
  MPI_Comm_rank(communicator_, &rank);
  MPI_Comm_size(communicator_, &size);
  rank_ = rank;
  size_ = size;
}

MpiEnvironment::~MpiEnvironment() {
  if (communicator_ != MPI_COMM_NULL) MPI_Comm_free(&communicator_);
  MPI_Finalize();
}

void MpiEnvironment::abort(int code) const noexcept {
  MPI_Abort(communicator_ != MPI_COMM_NULL ? communicator_ : MPI_COMM_WORLD, code);
  std::abort();  // MPI_Abort does not return; this is for the compiler
}

}  // namespace twincal
