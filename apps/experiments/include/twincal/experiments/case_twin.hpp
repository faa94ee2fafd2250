#pragma once
/// @file
/// `CaseTwin`: the twin an episode's controllers see — a full twin (AnyTwin) restricted to the
/// controlled locators S, the others held at the individualized optimum u0(x) (eq. 3), as in the
/// paper's one- and three-locator experiments (Sec. 3):
///   Q_S(x, v) = Q(x, u),  u_S = v,  u_j = u0_j(x) for j ∉ S;  u0_S(x), z*(x) unchanged.
/// Unlike models' LocatorSubset it computes u0(x) and z*(x) once per assembly at construction
/// (they do not depend on the controller or the run) and embeds controls into a per-thread
/// grow-only workspace, so evaluations do not allocate. It counts the Q-evaluations made
/// through it per thread (the plant's own evaluation, `plant_quality`, is not counted), which is
/// how an episode reports its Q-evaluations per assembly whatever the controller.
/// The plant can be another twin (Assumption 1 broken, as in every real cell: the contact FEM
/// behind a linear twin, a nonlinearity the twin lacks): the controllers see the twin, the cell
/// measures the plant, each at the same controls (the uncontrolled locators at the twin's u0).
/// Thread-safe for concurrent const use.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "twincal/core/eigen.hpp"
#include "twincal/experiments/any_twin.hpp"
#include "twincal/experiments/scanned_assembly.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

class CaseTwin {
 public:
  using Assembly = AssemblyId;

  /// Restricts `twin` to `locators` (indices into the full twin, in that order); the plant is
  /// `plant` when given, otherwise the twin itself.
  /// @throws InvalidArgumentError when `locators` is empty, repeats or is out of range, the
  ///         twin lists no assemblies, or the plant has other locators or assemblies than the
  ///         twin.
  CaseTwin(AnyTwin twin, std::vector<Index> locators, std::optional<AnyTwin> plant = std::nullopt);

  [[nodiscard]] Index control_dimension() const noexcept { return std::ssize(locators_); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept { return names_; }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return lower_bounds_; }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return upper_bounds_; }
  /// Indices of the controlled locators in the full twin.
  [[nodiscard]] const std::vector<Index>& locators() const noexcept { return locators_; }
  [[nodiscard]] const AnyTwin& full_twin() const noexcept { return twin_; }
  /// Registers the assembly of scanned `parts` with the full twin (AnyTwin::add_scanned, which
  /// searches its optimum unless `known`, the full twin's u0 and z*, is given) and computes its
  /// u0_S; parts registered before give their id again. Not for use concurrent with other calls.
  /// @throws InvalidArgumentError (field "parts") for a twin that takes no scanned parts; the
  ///         twin's errors; nothing changes then.
  AssemblyId add_scanned(const nlohmann::json& parts,
                         const std::optional<ScannedOptimum>& known = std::nullopt);

  /// How many scanned assemblies are registered; the next one gets scanned_assembly(count).
  [[nodiscard]] Index scanned_count() const noexcept { return std::ssize(scanned_positions_); }

  /// The full twin's assemblies, in its order (not the scanned ones).
  [[nodiscard]] const std::vector<AssemblyId>& assemblies() const noexcept {
    return twin_.assemblies();
  }

  /// Q_S(x, v); counted.
  [[nodiscard]] double quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const;
  /// out(j) = Q_S(x, controls.col(j)) with one batch call of the full twin; counted.
  void quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const;
  /// m, the full twin's key points where it answers their deviations; 0 where it answers only Q.
  [[nodiscard]] Index key_point_count() const { return twin_.key_point_count(); }
  /// out.col(j) = r(x, u) at the full control of controls.col(j), one batch call of the full
  /// twin; counted as Q-evaluations.
  /// @throws InvalidArgumentError (field "deviations") for a twin that answers only Q; the
  ///         twin's errors.
  void deviations_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const;
  /// Q_S(x, v) for the plant (the "real" cell); not counted.
  [[nodiscard]] double plant_quality(const AssemblyId& assembly,
                                     const Eigen::Ref<const VectorX>& control) const;
  /// Whether the plant is another twin than the controllers'.
  [[nodiscard]] bool separate_plant() const noexcept { return plant_.has_value(); }
  /// The plant where it is another twin than the controllers' (separate_plant()), else nothing.
  [[nodiscard]] const std::optional<AnyTwin>& plant() const noexcept { return plant_; }
  /// The best quality the plant can give x: z*(x) of the plant (its own optimum over every
  /// locator), which is the twin's z*(x) when the plant is the twin. With a separate plant and a
  /// subset of locators it is a lower bound of what the controlled locators can reach.
  [[nodiscard]] double plant_optimal_quality(const AssemblyId& assembly) const {
    return plant_ ? plant_optimal_qualities_(position(assembly)) : optimal_quality(assembly);
  }

  /// u0_S(x).
  [[nodiscard]] VectorX optimum(const AssemblyId& assembly) const {
    return optima_.col(position(assembly));
  }
  /// z*(x).
  [[nodiscard]] double optimal_quality(const AssemblyId& assembly) const {
    return optimal_qualities_(position(assembly));
  }

  /// Q-evaluations made through any CaseTwin on the calling thread so far.
  [[nodiscard]] static std::uint64_t evaluations_on_this_thread() noexcept;

 private:
  [[nodiscard]] Index position(const AssemblyId& assembly) const;
  // Q of `model` (the twin or the plant) at the full control of `control`.
  [[nodiscard]] double evaluate(const AnyTwin& model, const AssemblyId& assembly,
                                const Eigen::Ref<const VectorX>& control) const;
  // The full control u0(x) with the controlled entries replaced, into `out` (D × k).
  void embed(Index position, const Eigen::Ref<const MatrixX>& controls,
             Eigen::Ref<MatrixX> out) const;
  // The same into this thread's workspace (D × k), which the next call reuses.
  [[nodiscard]] Eigen::Block<MatrixX, Dynamic, Dynamic, true> embedded(
      const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls) const;
  // Column j of the optima: u0(x) of the full twin, its controlled entries u0_S(x), and z*(x).
  void store_optimum(Index j, const VectorX& full, double z_star);

  AnyTwin twin_;
  std::optional<AnyTwin> plant_;
  VectorX plant_optimal_qualities_;  // the plant's z*(x), with a separate plant
  std::vector<Index> locators_;
  std::vector<std::string> names_;
  VectorX lower_bounds_;
  VectorX upper_bounds_;
  Index lower_parts_ = 0;                 // assembly (i, j) is at i·lower_parts_ + j in the lookup
  std::vector<Index> lookup_;             // position in assemblies(), −1 for an unknown id
  std::vector<Index> scanned_positions_;  // position of scanned assembly k, −1 if not here
  MatrixX full_optima_;                   // u0(x), D × assemblies
  MatrixX optima_;                        // u0_S(x), |S| × assemblies
  VectorX optimal_qualities_;             // z*(x)
};

static_assert(TwinWithOptimum<CaseTwin> && TwinWithDeviations<CaseTwin>);

/// How far the case's Q_S² is from a quadratic (models/quadratic_departure.hpp): the median over
/// its first `assemblies` assemblies of the departure over u0_S(x) ± ¼ box width, each sampled
/// from RandomStream(k) for the k-th assembly. 0 for the linear FEM and RMS-quadratic twins.
/// Costs `assemblies` · 10 (d + 1)(d + 2)/2 twin evaluations (not counted as a controller's).
[[nodiscard]] double median_quadratic_departure(const CaseTwin& twin, Index assemblies = 10);

}  // namespace twincal
