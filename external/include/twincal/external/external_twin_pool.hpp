#pragma once
/// @file
/// `ExternalTwinPool`: N worker processes of one external twin command (external_twin.hpp), so
/// that a batch — the w-controller's candidates × sigma points, 231 controls per assembly at
/// d = 3 — is evaluated N controls at a time. A twin that takes seconds per call (an FEM job
/// behind a script) waits rather than computes in twincal, so N can exceed the core count.
///
/// A batch of k controls is cut into min(N, k) contiguous chunks of ⌊k/N⌋ or ⌈k/N⌉ columns;
/// chunk i goes to worker i as one request, all chunks at once (one thread per chunk), and the
/// answers land in their columns' places, so the result does not depend on N. A chunk whose
/// worker crashed, timed out (the worker is killed: the time limit is ExternalTwinOptions'
/// `timeout` per request), answered garbage or the wrong number of qualities is retried once on
/// a restarted worker; a second failure, or a failure that a retry cannot mend (the twin's own
/// {"error": …}, a command that cannot start), is thrown as an ExternalTwinError naming the
/// worker, after every chunk has finished. The error of the lowest failing chunk is the one
/// thrown, so a failure is reported the same way whatever the timing.
///
/// Deviations (deviations_batch, for a twin of `key_points` m > 0) are spread and retried the
/// same way, each chunk's m × count block landing in its columns.
///
/// Thread-safe: concurrent batches share the workers, each worker serving one request at a
/// time. It is the ExternalTwinBackend of a twin run on this machine.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/core/eigen.hpp"
#include "twincal/external/external_twin.hpp"
#include "twincal/external/external_twin_backend.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

struct ExternalTwinPoolOptions {
  ExternalTwinOptions twin;  ///< every worker's command, locators, bounds and time limits
  Index workers = 4;         ///< processes; 1 … max_workers
  bool retry = true;         ///< retry a crashed, hung or garbled chunk once on a restarted worker

  static constexpr Index max_workers = 256;

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem({rule::check(workers >= 1 && workers <= max_workers, "workers", workers,
                                      "must lie in [1, {}]", max_workers),
                          rule::nested("twin", twin)});
  }
};

class ExternalTwinPool final : public ExternalTwinBackend {
 public:
  using Assembly = nlohmann::json;

  /// Starts the workers, one after the other.
  /// @throws InvalidArgumentError for invalid options; ExternalTwinError(start_failed).
  explicit ExternalTwinPool(ExternalTwinPoolOptions options);

  ExternalTwinPool(const ExternalTwinPool&) = delete;
  ExternalTwinPool& operator=(const ExternalTwinPool&) = delete;
  ExternalTwinPool(ExternalTwinPool&&) noexcept = default;
  ExternalTwinPool& operator=(ExternalTwinPool&&) noexcept = default;
  ~ExternalTwinPool() override = default;  // each worker closes its child's input, then kills it

  [[nodiscard]] Index workers() const noexcept override { return std::ssize(workers_); }
  [[nodiscard]] Index control_dimension() const noexcept override {
    return workers_.front()->control_dimension();
  }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept override {
    return workers_.front()->locator_names();
  }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept override {
    return workers_.front()->lower_bounds();
  }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept override {
    return workers_.front()->upper_bounds();
  }
  [[nodiscard]] Index key_point_count() const noexcept override {
    return workers_.front()->key_point_count();
  }
  [[nodiscard]] const ExternalTwinPoolOptions& options() const noexcept { return options_; }
  /// Worker `w` itself (0 ≤ w < workers()), for owners that keep one worker busy per thread
  /// (e.g. searching one assembly's optimum per worker); no retry on this path.
  [[nodiscard]] const ExternalTwin& worker(Index w) const {
    return *workers_.at(static_cast<std::size_t>(w));
  }

  /// Processes started over all workers (workers() after construction; +1 per restart).
  [[nodiscard]] int starts() const;
  /// Chunks retried after a failure, over the pool's life.
  [[nodiscard]] std::uint64_t retries() const noexcept { return retries_->load(); }

  /// Q(x, u): one control, on worker 0.
  [[nodiscard]] double quality(const Assembly& assembly,
                               const Eigen::Ref<const VectorX>& control) const;

  /// Every column of `controls`, spread over the workers; a null quality comes back as NaN.
  /// @throws DimensionMismatchError, NonFiniteError (controls) before anything is sent;
  ///         ExternalTwinError when a chunk fails (after its retry), `out` then unspecified.
  void quality_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const override;
  /// Every column of `controls` as one request to worker `worker` (no retry: worker(w)'s path).
  void worker_quality_batch(Index worker, const Assembly& assembly,
                            const Eigen::Ref<const MatrixX>& controls,
                            Eigen::Ref<VectorX> out) const override {
    this->worker(worker).quality_batch(assembly, controls, out);
  }

  /// The key points' deviations of every column of `controls` (m × k), spread over the workers
  /// as quality_batch spreads qualities; a NaN column where the twin could not evaluate.
  /// @throws InvalidArgumentError when key_points is 0; otherwise as quality_batch.
  void deviations_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const override;
  /// The deviations of every column of `controls` as one request to worker `worker` (no retry).
  void worker_deviations_batch(Index worker, const Assembly& assembly,
                               const Eigen::Ref<const MatrixX>& controls,
                               Eigen::Ref<MatrixX> out) const override {
    this->worker(worker).deviations_batch(assembly, controls, out);
  }

 private:
  // Columns [begin, begin + count) of a batch, asked of one worker.
  using ChunkRequest = std::function<void(const ExternalTwin& worker, Index begin, Index count)>;
  // Cuts k columns into chunks, one per worker, and runs them at once; rethrows the lowest
  // failing chunk's error after every chunk has finished.
  void spread(Index k, const ChunkRequest& request) const;
  // Runs columns [begin, begin + count) on worker `w`, retrying once.
  void evaluate_chunk(Index w, Index begin, Index count, const ChunkRequest& request) const;

  ExternalTwinPoolOptions options_;
  std::vector<std::unique_ptr<ExternalTwin>> workers_;
  std::unique_ptr<std::atomic<std::uint64_t>> retries_;  // heap: keeps the pool movable
};

static_assert(TwinWithDeviations<ExternalTwinPool>);

}  // namespace twincal
