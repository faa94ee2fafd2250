#pragma once
/// @file
/// `InfluenceCoefficientTwin`: the fast linear twin of a CalculiX model by the method of
/// influence coefficients (Liu & Hu 1997; docs/sheet_metal.md): the linear solve is affine in
/// the parts and the control, y(x, u) = y_U(i) + y_L(j) + B u, so d + U + L linear CalculiX
/// solves (B from unit locator displacements on flat parts, one response per part) give every
/// Q(x, u) = ‖y‖/√m afterwards as a d × m product. It is what a cell's controller would run
/// next to the plant when the real twin is too slow (docs/calculix.md, "Twin ≠ plant").

#include <memory>
#include <string>
#include <vector>

#include "twincal/calculix/calculix_twin.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

class InfluenceCoefficientTwin {
 public:
  using Assembly = AssemblyId;

  /// Solves `twin`'s model with contact and large displacements off: one deck of d unit
  /// controls on flat parts, one deck per part.
  /// @throws CalculixError when a linear solve fails (a linear solve does not fail to
  ///         converge, so any failure is the solver's or the deck's).
  explicit InfluenceCoefficientTwin(const CalculixTwin& twin);

  [[nodiscard]] Index control_dimension() const noexcept { return influence_.cols(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept {
    return locator_names_;
  }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return lower_bounds_; }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return upper_bounds_; }
  /// B (m × d, mm per mm): the key points' response to each locator.
  [[nodiscard]] const MatrixX& influence() const noexcept { return influence_; }
  /// CalculiX solves the construction took.
  [[nodiscard]] Index solver_runs() const noexcept { return solver_runs_; }

  /// y0 = y_U(i) + y_L(j), the key-point deviations at u = 0.
  /// @throws InvalidArgumentError for an assembly outside the parts.
  [[nodiscard]] VectorX unadjusted_deviations(const AssemblyId& assembly) const;
  /// y0 of any parts (a scanned assembly): one linear CalculiX solve.
  /// @throws CalculixError when that solve fails.
  [[nodiscard]] VectorX unadjusted_deviations(const CalculixParts& parts) const;
  [[nodiscard]] double quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const;
  void quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const;
  /// Q for any parts (a scanned assembly): one linear CalculiX solve for their y0, then B.
  /// @throws CalculixError when that solve fails.
  void quality_batch(const CalculixParts& parts, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const;
  /// m, the key points (TwinWithDeviations).
  [[nodiscard]] Index key_point_count() const noexcept { return influence_.rows(); }
  /// out.col(k) = y0 + B controls.col(k) (m × k; TwinWithDeviations).
  /// @throws InvalidArgumentError for an assembly outside the parts, DimensionMismatchError for
  ///         controls or out of the wrong shape.
  void deviations_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const;
  /// The deviations of any parts (a scanned assembly): one linear solve for y0, then B.
  /// @throws CalculixError when that solve fails; DimensionMismatchError for bad shapes.
  void deviations_batch(const CalculixParts& parts, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const;
  /// u0(x) = argmin over the box of ‖y0 + B u‖ (bounded least squares, exact), eq. (3).
  [[nodiscard]] VectorX optimum(const AssemblyId& assembly) const;
  [[nodiscard]] double optimal_quality(const AssemblyId& assembly) const;

 private:
  // y0 + B u for every column u of `controls`, column by column: a batch gives each control's
  // deviations to the bit.
  void deviations_from(const VectorX& y0, const Eigen::Ref<const MatrixX>& controls,
                       Eigen::Ref<MatrixX> out) const;
  // Q = ‖y0 + B u‖/√m for every column u of `controls`: the RMS of deviations_from's columns.
  void qualities_from(const VectorX& y0, const Eigen::Ref<const MatrixX>& controls,
                      Eigen::Ref<VectorX> out) const;

  std::vector<std::string> locator_names_;
  VectorX lower_bounds_;
  VectorX upper_bounds_;
  std::shared_ptr<const CalculixTwin> linear_;  ///< the linear model, for parts not listed
  MatrixX influence_;
  MatrixX upper_responses_;  ///< m × U
  MatrixX lower_responses_;  ///< m × L
  Index solver_runs_ = 0;
};

static_assert(TwinWithOptimum<InfluenceCoefficientTwin> &&
              TwinWithDeviations<InfluenceCoefficientTwin>);

}  // namespace twincal
