#pragma once
/// @file
/// `CalculixTwin`: the CalculiX assembly twin (docs/calculix.md) — Q(x, u) of a lap joint
/// solved by CalculiX per request, with sheet-to-sheet contact and large displacements. It
/// satisfies `Twin` with `Assembly = AssemblyId` (seeded synthetic parts, the FEM twin's part
/// fields) and evaluates any other parts (scans) with `evaluate`. Program
/// `twincal_calculix_twin` serves it over the external-twin protocol (docs/external.md).

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "twincal/calculix/calculix_error.hpp"
#include "twincal/calculix/calculix_model.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/twin.hpp"
#include "twincal/sheet_metal/part_field.hpp"

namespace twincal {

/// What one `evaluate` call took.
struct CalculixBatchSummary {
  Index solver_runs = 0;        ///< CalculiX processes started
  double solver_seconds = 0.0;  ///< their wall time, summed
  std::vector<Index> failed;    ///< columns without a converged solve (their Q is NaN)
  std::string last_failure;     ///< the last failed column's message and log tail
};

class CalculixTwin {
 public:
  using Assembly = AssemblyId;

  /// A twin over given parts: nodal free normal deviations w on the CalculiX meshes
  /// (`model().mesh(part).node_count()` entries each, row by row).
  /// @throws InvalidArgumentError (options, layout, no parts), DimensionMismatchError,
  ///         NonFiniteError (a part).
  CalculixTwin(SheetMetalLayout layout, CalculixOptions options, std::vector<VectorX> upper_parts,
               std::vector<VectorX> lower_parts);

  /// `upper_parts` × `lower_parts` synthetic parts drawn as `SheetMetalTwin::generate` draws
  /// them (`RandomStream(seed)`, substreams "upper"/"lower", i), on the CalculiX meshes.
  [[nodiscard]] static CalculixTwin generate(SheetMetalLayout layout, CalculixOptions options,
                                             std::uint64_t seed, Index upper_parts,
                                             Index lower_parts, const PartFieldOptions& field = {});

  [[nodiscard]] const CalculixModel& model() const noexcept { return *model_; }
  [[nodiscard]] Index control_dimension() const noexcept { return model_->control_dimension(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept {
    return locator_names_;
  }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return lower_bounds_; }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return upper_bounds_; }
  [[nodiscard]] Index upper_part_count() const noexcept {
    return static_cast<Index>(upper_parts_.size());
  }
  [[nodiscard]] Index lower_part_count() const noexcept {
    return static_cast<Index>(lower_parts_.size());
  }
  /// @throws InvalidArgumentError for an assembly outside the parts.
  [[nodiscard]] CalculixParts parts(const AssemblyId& assembly) const;

  /// Q(x, u) in mm; NaN when CalculiX does not converge (an `Evaluator` makes that a typed
  /// `non_finite` error, which the controllers' fallback policy handles).
  /// @throws CalculixError when the solver is missing, refuses the deck, crashes or times out.
  [[nodiscard]] double quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const;
  void quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const;

  /// m, the key points (TwinWithDeviations).
  [[nodiscard]] Index key_point_count() const noexcept;
  /// out.col(k) = the key-point deviations y(x, controls.col(k)) (m × k, mm), in one deck as
  /// `key_deviations`; a column whose solve fails is NaN throughout (TwinWithDeviations).
  /// @throws as quality_batch, and DimensionMismatchError for out.
  void deviations_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const;

  /// Q for every column of `controls` on any parts, in one deck where the solves converge: a
  /// column whose solve fails is solved again alone from the undeformed state, and is NaN (and
  /// listed in the summary) when that fails too; the columns after it go on in a new deck.
  /// `label` names the assembly in messages. Thread-safe: each call has its own scratch
  /// directory under `options.scratch_root`, removed afterwards unless `keep_files`.
  CalculixBatchSummary evaluate(const CalculixParts& parts,
                                const Eigen::Ref<const MatrixX>& controls, Eigen::Ref<VectorX> out,
                                std::string_view label) const;

  /// As `evaluate`, with the key-point deviations y (m × k, mm) instead of Q = RMS(y); a failed
  /// column is NaN throughout.
  CalculixBatchSummary key_deviations(const CalculixParts& parts,
                                      const Eigen::Ref<const MatrixX>& controls,
                                      Eigen::Ref<MatrixX> out, std::string_view label) const;

 private:
  std::shared_ptr<const CalculixModel> model_;
  std::vector<std::string> locator_names_;
  VectorX lower_bounds_;
  VectorX upper_bounds_;
  std::vector<VectorX> upper_parts_;
  std::vector<VectorX> lower_parts_;
  std::shared_ptr<std::atomic<std::uint64_t>> jobs_;
};

static_assert(TwinWithDeviations<CalculixTwin>);

}  // namespace twincal
