// ExternalTwinPool (external_twin_pool.hpp): a batch split over worker processes.
#include "twincal/external/external_twin_pool.hpp"

#include <exception>
#include <thread>
#include <utility>

#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {
namespace {

// Failures after which the worker was (or must be) restarted, and a retry may succeed.
bool retryable(ExternalTwinFailure failure) noexcept {
  switch (failure) {
    case ExternalTwinFailure::crashed:
    case ExternalTwinFailure::timeout:
    case ExternalTwinFailure::malformed_reply:
    case ExternalTwinFailure::wrong_count:
      return true;
    case ExternalTwinFailure::start_failed:
    case ExternalTwinFailure::twin_error:
    case ExternalTwinFailure::implausible_quality:  // a deterministic twin answers it again
      return false;
  }
  return false;
}

}  // namespace

ExternalTwinPool::ExternalTwinPool(ExternalTwinPoolOptions options)
    : options_(std::move(options)), retries_(std::make_unique<std::atomic<std::uint64_t>>(0)) {
  require_valid("options", options_);
  workers_.reserve(static_cast<std::size_t>(options_.workers));
  for (Index w = 0; w < options_.workers; ++w) {
    workers_.push_back(std::make_unique<ExternalTwin>(options_.twin));
  }
}

int ExternalTwinPool::starts() const {
  int total = 0;
  for (const auto& worker : workers_) total += worker->starts();
  return total;
}

double ExternalTwinPool::quality(const Assembly& assembly,
                                 const Eigen::Ref<const VectorX>& control) const {
  require_control(control, control_dimension());
  double value = 0.0;
  quality_batch(assembly, control, Eigen::Map<VectorX>(&value, 1));
  return value;
}

void ExternalTwinPool::quality_batch(const Assembly& assembly,
                                     const Eigen::Ref<const MatrixX>& controls,
                                     Eigen::Ref<VectorX> out) const {
  require_control_batch(controls, out, control_dimension());
  require_finite("controls", controls);
  spread(controls.cols(), [&](const ExternalTwin& worker, Index begin, Index count) {
    worker.quality_batch(assembly, controls.middleCols(begin, count), out.segment(begin, count));
  });
}

void ExternalTwinPool::deviations_batch(const Assembly& assembly,
                                        const Eigen::Ref<const MatrixX>& controls,
                                        Eigen::Ref<MatrixX> out) const {
  require_key_points(key_point_count());
  require_deviations_batch(controls, out, control_dimension(), key_point_count());
  require_finite("controls", controls);
  spread(controls.cols(), [&](const ExternalTwin& worker, Index begin, Index count) {
    worker.deviations_batch(assembly, controls.middleCols(begin, count),
                            out.middleCols(begin, count));
  });
}

void ExternalTwinPool::spread(Index k, const ChunkRequest& request) const {
  const Index chunks = std::min(k, workers());
  if (chunks == 0) return;
  // Chunk c covers [c·k/chunks, (c+1)·k/chunks): sizes differ by at most one.
  const auto begin_of = [&](Index c) { return c * k / chunks; };
  std::vector<std::exception_ptr> failures(static_cast<std::size_t>(chunks));
  const auto run = [&](Index c) {
    try {
      evaluate_chunk(c, begin_of(c), begin_of(c + 1) - begin_of(c), request);
    } catch (...) {
      failures[static_cast<std::size_t>(c)] = std::current_exception();
    }
  };
  {
    std::vector<std::jthread> threads;
    threads.reserve(static_cast<std::size_t>(chunks - 1));
    for (Index c = 1; c < chunks; ++c) threads.emplace_back(run, c);
    run(0);
  }  // joined
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
}

void ExternalTwinPool::evaluate_chunk(Index w, Index begin, Index count,
                                      const ChunkRequest& request) const {
  const ExternalTwin& worker = *workers_[static_cast<std::size_t>(w)];
  std::string first;
  for (int attempt = 0;; ++attempt) {
    try {
      request(worker, begin, count);
      return;
    } catch (const ExternalTwinError& error) {
      const std::string where =
          fmt::format("worker {} of {}, controls {}…{}", w, workers(), begin, begin + count - 1);
      if (attempt == 0 && options_.retry && retryable(error.failure())) {
        if (error.failure() == ExternalTwinFailure::wrong_count) worker.restart();
        first = error.detail();
        retries_->fetch_add(1);
        continue;
      }
      throw ExternalTwinError(
          error.failure(), error.assembly(), error.controls(),
          attempt == 0 ? fmt::format("{} ({})", error.detail(), where)
                       : fmt::format("{} ({}, on the retry after a restart; the first attempt: {})",
                                     error.detail(), where, first));
    }
  }
}

}  // namespace twincal
