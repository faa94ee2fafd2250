#pragma once
// Point-to-point messages of twincal's MPI code (private to apps/distributed): waiting without
// spinning a core, and byte messages of any length up to 2^31 − 1.

#include <mpi.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <vector>

namespace twincal::mpi_messages {

/// How long a waiting thread sleeps between probes: doubling from the first to the longest.
/// The longest bounds the latency a message can wait unseen (a twin call answered by another
/// rank pays it twice); at 500 µs it is 1 % of a 0.1 s twin call, while an idle rank wakes at
/// most 2000 times a second.
inline constexpr std::chrono::microseconds first_pause{20};
inline constexpr std::chrono::microseconds longest_pause{500};

/// The status of a message from `source` with `tag` (MPI_ANY_* allowed) once one has arrived,
/// probing with MPI_Iprobe and sleeping between probes (first_pause … longest_pause). MPI's
/// blocking calls poll at full speed, which would take the CPU from the work running beside them
/// (an episode in another thread, or another rank on an oversubscribed node).
MPI_Status wait_for_message(MPI_Comm communicator, int source, int tag);

/// The status of a waiting message from `source` with `tag`, if one has arrived.
std::optional<MPI_Status> probe(MPI_Comm communicator, int source, int tag);

/// Receives the message that `status` announced, as bytes.
std::vector<std::uint8_t> receive_bytes(MPI_Comm communicator, const MPI_Status& status);

/// Sends `bytes` to `destination` with `tag`.
/// @throws Error for a message longer than 2^31 − 1 bytes.
void send_bytes(MPI_Comm communicator, const std::vector<std::uint8_t>& bytes, int destination,
                int tag);

}  // namespace twincal::mpi_messages
