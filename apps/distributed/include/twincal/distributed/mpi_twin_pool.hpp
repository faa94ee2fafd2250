#pragma once
/// @file
/// `MpiTwinPool`: an external twin whose workers are the other ranks of an MPI job — the
/// ExternalTwinBackend that `twincal run|paper|sweep|scaling --mpi-twin-pool` gives every
/// external twin, so that one episode's batches (candidates × sigma points) and its u0 searches
/// spread over a cluster (docs/distributed.md).
///
/// Worker w is rank w + 1, which runs the twin's program as an ExternalTwinPool of the settings'
/// `workers` processes. A batch of k controls is cut as ExternalTwinPool cuts it: into
/// min(ranks, k) contiguous chunks of ⌊k/ranks⌋ or ⌈k/ranks⌉ columns, chunk i to rank i + 1,
/// all at once; the answers land in their columns' places, so the qualities do not depend on the
/// number of ranks. A rank retries a failed chunk once on a restarted process (its pool's
/// policy); a second failure comes back and is thrown, after every chunk has finished, as the
/// ExternalTwinError of the lowest failing chunk, its detail naming the rank.

#include <cstdint>
#include <string>
#include <vector>

#include "twincal/distributed/mpi_twin_service.hpp"
#include "twincal/experiments/external_twin_settings.hpp"
#include "twincal/external/external_twin_backend.hpp"

namespace twincal {

class MpiTwinPool final : public ExternalTwinBackend {
 public:
  /// Starts the twin of `settings` on every worker rank of `service`.
  /// @throws InvalidArgumentError for invalid settings; ExternalTwinError(start_failed) naming
  ///         the first rank that could not start it.
  MpiTwinPool(MpiTwinService& service, const ExternalTwinSettings& settings);

  [[nodiscard]] Index workers() const override { return service_->worker_ranks(); }
  [[nodiscard]] Index control_dimension() const override { return lower_bounds_.size(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const override {
    return locator_names_;
  }
  [[nodiscard]] const VectorX& lower_bounds() const override { return lower_bounds_; }
  [[nodiscard]] const VectorX& upper_bounds() const override { return upper_bounds_; }
  [[nodiscard]] Index key_point_count() const override { return key_points_; }

  /// @throws DimensionMismatchError, NonFiniteError (controls) before anything is sent;
  ///         ExternalTwinError when a chunk fails on its rank (after the rank's retry).
  void quality_batch(const nlohmann::json& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const override;
  void worker_quality_batch(Index worker, const nlohmann::json& assembly,
                            const Eigen::Ref<const MatrixX>& controls,
                            Eigen::Ref<VectorX> out) const override;
  /// As quality_batch, with the key points' deviations (m × k; the ranks' pools ask their
  /// processes for them). @throws InvalidArgumentError when key_points is 0.
  void deviations_batch(const nlohmann::json& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const override;
  void worker_deviations_batch(Index worker, const nlohmann::json& assembly,
                               const Eigen::Ref<const MatrixX>& controls,
                               Eigen::Ref<MatrixX> out) const override;

 private:
  // Sends columns [begin, begin + count) to `rank`, asking for qualities or deviations; the
  // reply's future.
  [[nodiscard]] std::future<nlohmann::json> send_chunk(int rank, const nlohmann::json& assembly,
                                                       const Eigen::Ref<const MatrixX>& controls,
                                                       Index begin, Index count,
                                                       bool deviations) const;
  // Copies a reply's values (1 × count qualities or m × count deviations) into `out`, or throws
  // its failure.
  void take_reply(const nlohmann::json& reply, int rank, const nlohmann::json& assembly,
                  const Eigen::Ref<const MatrixX>& controls, Eigen::Ref<MatrixX> out) const;
  // The whole batch, spread over the ranks: rows of `out` are 1 (qualities) or m (deviations).
  void spread(const nlohmann::json& assembly, const Eigen::Ref<const MatrixX>& controls,
              bool deviations, Eigen::Ref<MatrixX> out) const;
  // One request of every column to the rank of `worker`.
  void ask_worker(Index worker, const nlohmann::json& assembly,
                  const Eigen::Ref<const MatrixX>& controls, bool deviations,
                  Eigen::Ref<MatrixX> out) const;

  MpiTwinService* service_;
  std::int64_t twin_id_;
  std::vector<std::string> locator_names_;
  VectorX lower_bounds_;
  VectorX upper_bounds_;
  Index key_points_;
};

}  // namespace twincal
