#pragma once
/// @file
/// `MpiEnvironment`: MPI for the life of the object — MPI_Init_thread with
/// MPI_THREAD_FUNNELED (rank 0 runs an episode in a second thread that never calls MPI) and a
/// communicator of twincal's own (a duplicate of MPI_COMM_WORLD, so its messages cannot meet a
/// library's), then MPI_Finalize. One per process, made by the program's main path only.

#include <mpi.h>

#include "twincal/core/eigen.hpp"

namespace twincal {

class MpiEnvironment {
 public:
  /// @throws Error when MPI was initialized before or cannot give MPI_THREAD_FUNNELED.
  MpiEnvironment(int& argc, char**& argv);
  /// Without the program's arguments (MPI-2 and later need none).
  MpiEnvironment();
  ~MpiEnvironment();
  MpiEnvironment(const MpiEnvironment&) = delete;
  MpiEnvironment& operator=(const MpiEnvironment&) = delete;

  [[nodiscard]] MPI_Comm communicator() const noexcept { return communicator_; }
  [[nodiscard]] Index rank() const noexcept { return rank_; }
  [[nodiscard]] Index size() const noexcept { return size_; }

  /// Ends every rank of the job (MPI_Abort) with exit code `code`: the way out for a rank that
  /// cannot go on while others wait for it.
  [[noreturn]] void abort(int code) const noexcept;

 private:
  void initialize(int* argc, char*** argv);

  MPI_Comm communicator_ = MPI_COMM_NULL;
  Index rank_ = 0;
  Index size_ = 1;
};

}  // namespace twincal
