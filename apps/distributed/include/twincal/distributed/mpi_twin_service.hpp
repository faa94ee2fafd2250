#pragma once
/// @file
/// `MpiTwinService`: rank 0's side of external twins whose workers are the other ranks of an
/// MPI job (MpiTwinPool), and `serve_twin_requests`, the other ranks' side.
///
/// MPI is initialized with MPI_THREAD_FUNNELED (MpiEnvironment), so only the main thread may
/// call it, while a study calls its twins from many threads (episodes, u0 searches). The service
/// therefore runs the study in a thread of its own (`run`) and carries every message on the
/// main thread: a pool's request waits in a queue until the main thread sends it, and its reply
/// is handed back through a future. Each worker rank serves one request at a time, in the order
/// they arrive, on an ExternalTwinPool of the twin's own `workers` processes (which restarts a
/// crashed, hung or garbled process and retries once, as on one machine).
///
/// Messages (CBOR through nlohmann::json): "start" a twin (its ExternalTwinSettings) on every
/// worker rank, "evaluate" a chunk of controls, "stop"; each rank answers a start and an
/// evaluation with one reply.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <future>
#include <map>
#include <mutex>
#include <vector>

#include <nlohmann/json.hpp>

#include "twincal/distributed/mpi_environment.hpp"
#include "twincal/experiments/external_case_twin.hpp"

namespace twincal {

class MpiTwinService {
 public:
  /// On rank 0 of `mpi`, which must have at least one other rank.
  /// @throws InvalidArgumentError on another rank or in a job of one rank.
  explicit MpiTwinService(const MpiEnvironment& mpi);
  MpiTwinService(const MpiTwinService&) = delete;
  MpiTwinService& operator=(const MpiTwinService&) = delete;
  ~MpiTwinService() = default;

  /// The ranks that evaluate twins (every rank but 0).
  [[nodiscard]] Index worker_ranks() const noexcept { return mpi_.size() - 1; }

  /// Runs `work` in a thread of its own while the calling (main) thread carries the messages,
  /// then tells every worker rank to stop. Rethrows what `work` threw.
  void run(const std::function<void()>& work);

  /// A factory that makes an MpiTwinPool on this service for each external twin.
  [[nodiscard]] ExternalTwinBackendFactory factory();

  /// Queues `message` for worker rank `rank` (1 … worker_ranks()) with MPI tag `tag`; the
  /// future holds its reply. Thread-safe; the message is sent by run()'s main thread.
  [[nodiscard]] std::future<nlohmann::json> request(int rank, int tag, nlohmann::json message);

  /// A new twin id, for the "start" message of a pool.
  [[nodiscard]] std::int64_t next_twin_id();

  static constexpr int start_tag = 11;
  static constexpr int evaluate_tag = 12;
  static constexpr int stop_tag = 13;
  static constexpr int reply_tag = 14;

 private:
  struct Outgoing {
    int rank;
    int tag;
    std::vector<std::uint8_t> bytes;
  };

  // The main thread's loop: sends what is queued, hands replies to their futures, until the
  // work is done and no reply is outstanding.
  void carry_messages();

  const MpiEnvironment& mpi_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Outgoing> outgoing_;
  std::map<std::int64_t, std::promise<nlohmann::json>> waiting_;  // by request id
  std::int64_t next_request_ = 0;
  std::int64_t next_twin_ = 0;
  bool work_done_ = false;
};

/// The worker ranks' loop: serves "start" and "evaluate" messages from rank 0 until "stop".
/// Every twin failure is answered, not thrown, so the rank serves on.
void serve_twin_requests(const MpiEnvironment& mpi);

}  // namespace twincal
