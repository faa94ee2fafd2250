#pragma once
/// @file
/// `ExternalTwinBackend`: where an external twin's evaluations run — the run-time interface
/// that ExternalTwinPool (N processes on this machine) implements, and MpiTwinPool
/// (apps/distributed: twin processes on the other ranks of an MPI job) too. An owner such as the
/// experiments' ExternalCaseTwin holds one and does not know which.
///
/// A backend has `workers()` independent workers. quality_batch spreads a batch over them;
/// worker_quality_batch sends one request to one worker, for owners that keep one request in
/// flight per worker (searching one assembly's optimum per worker). Either way the qualities do
/// not depend on the worker that computed them, so results do not depend on the backend or its
/// worker count. A twin of `key_points` m > 0 also answers its key points' deviations
/// (deviations_batch, m × k), spread the same way. Failures are ExternalTwinError
/// (external_twin.hpp). Thread-safe for concurrent const use.

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/core/eigen.hpp"

namespace twincal {

class ExternalTwinBackend {
 public:
  virtual ~ExternalTwinBackend() = default;

  [[nodiscard]] virtual Index workers() const = 0;
  [[nodiscard]] virtual Index control_dimension() const = 0;
  [[nodiscard]] virtual const std::vector<std::string>& locator_names() const = 0;
  [[nodiscard]] virtual const VectorX& lower_bounds() const = 0;
  [[nodiscard]] virtual const VectorX& upper_bounds() const = 0;
  /// m, the key points of deviations_batch; 0 for a twin that answers qualities only.
  [[nodiscard]] virtual Index key_point_count() const = 0;

  /// Every column of `controls`, spread over the workers; NaN where the twin had no quality.
  virtual void quality_batch(const nlohmann::json& assembly,
                             const Eigen::Ref<const MatrixX>& controls,
                             Eigen::Ref<VectorX> out) const = 0;
  /// Every column of `controls` on worker `worker` (0 ≤ worker < workers()) alone.
  virtual void worker_quality_batch(Index worker, const nlohmann::json& assembly,
                                    const Eigen::Ref<const MatrixX>& controls,
                                    Eigen::Ref<VectorX> out) const = 0;
  /// The key points' deviations of every column of `controls` (out is m × k), spread over the
  /// workers; a NaN column where the twin could not evaluate a control.
  /// @throws InvalidArgumentError when key_point_count() is 0.
  virtual void deviations_batch(const nlohmann::json& assembly,
                                const Eigen::Ref<const MatrixX>& controls,
                                Eigen::Ref<MatrixX> out) const = 0;
  /// The deviations of every column of `controls` on worker `worker` alone.
  virtual void worker_deviations_batch(Index worker, const nlohmann::json& assembly,
                                       const Eigen::Ref<const MatrixX>& controls,
                                       Eigen::Ref<MatrixX> out) const = 0;

 protected:
  ExternalTwinBackend() = default;
  ExternalTwinBackend(const ExternalTwinBackend&) = default;
  ExternalTwinBackend(ExternalTwinBackend&&) = default;
  ExternalTwinBackend& operator=(const ExternalTwinBackend&) = default;
  ExternalTwinBackend& operator=(ExternalTwinBackend&&) = default;
};

}  // namespace twincal
