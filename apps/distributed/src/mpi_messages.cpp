#include "mpi_messages.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <thread>

#include <fmt/format.h>

#include "twincal/core/error.hpp"

namespace twincal::mpi_messages {

MPI_Status wait_for_message(MPI_Comm communicator, int source, int tag) {
  auto pause = first_pause;
  for (;;) {
    if (const std::optional<MPI_Status> status = probe(communicator, source, tag)) return *status;
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, longest_pause);
  }
}

std::optional<MPI_Status> probe(MPI_Comm communicator, int source, int tag) {
  MPI_Status status;
  int arrived = 0;
  MPI_Iprobe(source, tag, communicator, &arrived, &status);
  if (arrived == 0) return std::nullopt;
  return status;
}

std::vector<std::uint8_t> receive_bytes(MPI_Comm communicator, const MPI_Status& status) {
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(count));
  MPI_Recv(bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, communicator,
           MPI_STATUS_IGNORE);
  return bytes;
}

void send_bytes(MPI_Comm communicator, const std::vector<std::uint8_t>& bytes, int destination,
                int tag) {
  if (bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    throw Error("MPI",
                fmt::format("MPI: a message of {} bytes; rule: at most 2^31 − 1", bytes.size()));
  }
  MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, destination, tag, communicator);
}

}  // namespace twincal::mpi_messages
