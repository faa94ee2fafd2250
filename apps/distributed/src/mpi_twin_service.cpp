#include "twincal/distributed/mpi_twin_service.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <utility>

#include <fmt/format.h>

#include "mpi_messages.hpp"
#include "twincal/core/error.hpp"
#include "twincal/distributed/mpi_twin_pool.hpp"
#include "twincal/external/external_twin.hpp"
#include "twincal/external/external_twin_pool.hpp"

namespace twincal {

using nlohmann::json;

MpiTwinService::MpiTwinService(const MpiEnvironment& mpi) : mpi_(mpi) {
  if (mpi.rank() != 0) {
    throw InvalidArgumentError(
        "rank", fmt::format("rank: is {}; rule: the MPI twin service runs on rank 0", mpi.rank()));
  }
  if (mpi.size() < 2) {
    throw InvalidArgumentError(
        "ranks",
        "ranks: the MPI job has 1; rule: an MPI twin pool needs at least 2 (rank 0 "
        "runs the study, the others the twin)");
  }
}

std::future<json> MpiTwinService::request(int rank, int tag, json message) {
  const std::lock_guard lock(mutex_);
  const std::int64_t id = next_request_++;
  message["request"] = id;
  std::promise<json> reply;
  std::future<json> future = reply.get_future();
  waiting_.emplace(id, std::move(reply));
  outgoing_.push_back({rank, tag, json::to_cbor(message)});
  wake_.notify_one();
  return future;
}

std::int64_t MpiTwinService::next_twin_id() {
  const std::lock_guard lock(mutex_);
  return next_twin_++;
}

ExternalTwinBackendFactory MpiTwinService::factory() {
  return [this](const ExternalTwinSettings& settings) -> std::unique_ptr<ExternalTwinBackend> {
    return std::make_unique<MpiTwinPool>(*this, settings);
  };
}

void MpiTwinService::run(const std::function<void()>& work) {
  std::exception_ptr failure;
  std::thread thread([&] {
    try {
      work();
    } catch (...) {
      failure = std::current_exception();
    }
    const std::lock_guard lock(mutex_);
    work_done_ = true;
    wake_.notify_one();
  });
  try {
    carry_messages();
  } catch (const std::exception& error) {
    // Only MPI or a reply that is not ours can get here, and the work waits for its replies.
    fmt::print(stderr, "twincal: rank 0 cannot carry the twin pool's messages: {}\n", error.what());
    mpi_.abort(1);
  }
  thread.join();
  for (int rank = 1; rank < static_cast<int>(mpi_.size()); ++rank) {
    MPI_Send(nullptr, 0, MPI_BYTE, rank, stop_tag, mpi_.communicator());
  }
  if (failure) std::rethrow_exception(failure);
}

void MpiTwinService::carry_messages() {
  const MPI_Comm communicator = mpi_.communicator();
  auto pause = mpi_messages::first_pause;
  for (;;) {
    std::deque<Outgoing> sending;
    {
      const std::lock_guard lock(mutex_);
      sending.swap(outgoing_);
      // Every request is answered, so the replies still outstanding will come.
      if (sending.empty() && work_done_ && waiting_.empty()) return;
    }
    for (const Outgoing& message : sending) {
      mpi_messages::send_bytes(communicator, message.bytes, message.rank, message.tag);
    }
    bool received = false;
    while (const std::optional<MPI_Status> status =
               mpi_messages::probe(communicator, MPI_ANY_SOURCE, reply_tag)) {
      json reply = json::from_cbor(mpi_messages::receive_bytes(communicator, *status));
      const std::int64_t id = reply.at("request").get<std::int64_t>();
      const std::lock_guard lock(mutex_);
      const auto waiting = waiting_.find(id);
      if (waiting == waiting_.end()) {
        throw Error("MPI", fmt::format("MPI: rank {} answered request {}, which is not waiting",
                                       status->MPI_SOURCE, id));
      }
      waiting->second.set_value(std::move(reply));
      waiting_.erase(waiting);
      received = true;
    }
    if (!sending.empty() || received) {
      pause = mpi_messages::first_pause;
      continue;
    }
    std::unique_lock lock(mutex_);
    wake_.wait_for(lock, pause,
                   [&] { return !outgoing_.empty() || (work_done_ && waiting_.empty()); });
    pause = std::min(pause * 2, mpi_messages::longest_pause);
  }
}

void serve_twin_requests(const MpiEnvironment& mpi) {
  const MPI_Comm communicator = mpi.communicator();
  std::map<std::int64_t, std::unique_ptr<ExternalTwinPool>> twins;
  for (;;) {
    const MPI_Status status = mpi_messages::wait_for_message(communicator, 0, MPI_ANY_TAG);
    const std::vector<std::uint8_t> bytes = mpi_messages::receive_bytes(communicator, status);
    if (status.MPI_TAG == MpiTwinService::stop_tag) return;
    const json message = json::from_cbor(bytes);
    json reply{{"request", message.at("request")}};
    try {
      const std::int64_t twin = message.at("twin").get<std::int64_t>();
      if (status.MPI_TAG == MpiTwinService::start_tag) {
        ExternalTwinSettings settings;
        from_json(message.at("settings"), settings);
        twins[twin] = std::make_unique<ExternalTwinPool>(external_twin_pool_options(settings));
        reply["started"] = true;
      } else {
        const auto found = twins.find(twin);
        if (found == twins.end()) {
          throw Error("twin", fmt::format("twin: {} was not started on this rank", twin));
        }
        const json& data = message.at("controls");
        const Index rows = message.at("rows").get<Index>();
        const Index cols = message.at("cols").get<Index>();
        const std::vector<double> given = data.get<std::vector<double>>();
        if (std::ssize(given) != rows * cols) {
          throw Error("controls", "controls: their data does not fill rows × cols");
        }
        const Eigen::Map<const MatrixX> controls(given.data(), rows, cols);
        const ExternalTwinPool& pool = *found->second;
        // Column-major, as rank 0 reads them: 1 × cols qualities or m × cols deviations.
        const bool deviations = message.value("deviations", false);
        MatrixX values(deviations ? pool.key_point_count() : 1, cols);
        if (deviations) {
          pool.deviations_batch(message.at("assembly"), controls, values);
        } else {
          pool.quality_batch(message.at("assembly"), controls,
                             Eigen::Map<VectorX>(values.data(), cols));
        }
        reply["values"] = std::vector<double>(values.data(), values.data() + values.size());
      }
    } catch (const ExternalTwinError& error) {
      reply["failure"] = static_cast<int>(error.failure());
      reply["detail"] = error.detail();
    } catch (const std::exception& error) {
      reply["error"] = error.what();
    }
    mpi_messages::send_bytes(communicator, json::to_cbor(reply), 0, MpiTwinService::reply_tag);
  }
}

}  // namespace twincal
