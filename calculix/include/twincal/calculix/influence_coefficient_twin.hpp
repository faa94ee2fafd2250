#pragma once
/// @file
/// `InfluenceCoefficientTwin`: the fast affine twin of a CalculiX model by the method of
/// influence coefficients (Liu & Hu 1997; docs/sheet_metal.md): y(x, u) = y_U(i) + y_L(j) + B u,
/// so a few CalculiX solves at construction (B, one response per part) give every
/// Q(x, u) = ‖y‖/√m afterwards as a d × m product. By default they are the linear solve's
/// (d + U + L solves; it is exactly affine); with `InfluenceLinearization::secant` they are
/// secants of the model's own contact and large-displacement solve around the box's centre
/// (2d + 1 + U + L solves). It is what a cell's controller would run next to the plant when the
/// real twin is too slow (docs/calculix.md, "Twin ≠ plant").

#include <memory>
#include <string>
#include <vector>

#include "twincal/calculix/calculix_twin.hpp"
#include "twincal/calculix/influence_coefficient_options.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

class InfluenceCoefficientTwin {
 public:
  using Assembly = AssemblyId;

  /// small_displacement: solves `twin`'s model with contact and large displacements off, one
  /// deck of d unit controls on flat parts and one deck per part. secant: solves `twin` itself
  /// at the box's centre c and at c ± h_k e_k on flat parts (one deck), B's column k the central
  /// difference over 2 h_k, and each part with a flat partner at c; y_U(i) = y(part i, c) − B c,
  /// y_L(j) = y(part j, c) − y(flat, c), so y(x, c) is the sum of the two parts' responses at
  /// the centre and y(flat, c ± h_k e_k) is reproduced along each axis up to the secant's
  /// curvature.
  /// @throws InvalidArgumentError for invalid options (nothing is solved);
  ///         CalculixError when a solve fails (a linear solve does not fail to converge, so
  ///         there any failure is the solver's or the deck's; a secant's contact solve may).
  explicit InfluenceCoefficientTwin(const CalculixTwin& twin,
                                    const InfluenceCoefficientOptions& options = {});

  [[nodiscard]] Index control_dimension() const noexcept { return influence_.cols(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept {
    return locator_names_;
  }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return lower_bounds_; }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return upper_bounds_; }
  /// B (m × d, mm per mm): the key points' response to each locator.
  [[nodiscard]] const MatrixX& influence() const noexcept { return influence_; }
  /// The options it was built with.
  [[nodiscard]] const InfluenceCoefficientOptions& options() const noexcept { return options_; }
  /// CalculiX solves the construction took.
  [[nodiscard]] Index solver_runs() const noexcept { return solver_runs_; }

  /// y0 = y_U(i) + y_L(j), the key-point deviations at u = 0.
  /// @throws InvalidArgumentError for an assembly outside the parts.
  [[nodiscard]] VectorX unadjusted_deviations(const AssemblyId& assembly) const;
  /// y0 of any parts (a scanned assembly): one CalculiX solve (linear, or at the secant's
  /// centre c: y(parts, c) − B c).
  /// @throws CalculixError when that solve fails.
  [[nodiscard]] VectorX unadjusted_deviations(const CalculixParts& parts) const;
  [[nodiscard]] double quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const;
  void quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const;
  /// Q for any parts (a scanned assembly): one CalculiX solve for their y0, then B.
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
  /// The deviations of any parts (a scanned assembly): one solve for y0, then B.
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

  // y(parts, c) − B c: one solve of `solver_` at the operating point.
  [[nodiscard]] VectorX solved_unadjusted_deviations(const CalculixParts& parts,
                                                     const std::string& label) const;

  InfluenceCoefficientOptions options_;
  std::vector<std::string> locator_names_;
  VectorX lower_bounds_;
  VectorX upper_bounds_;
  /// The model the map was solved on (linear, or `twin` itself), for parts not listed.
  std::shared_ptr<const CalculixTwin> solver_;
  VectorX operating_point_;  ///< c: 0 (small_displacement) or the box's centre (secant)
  MatrixX influence_;
  MatrixX upper_responses_;  ///< m × U
  MatrixX lower_responses_;  ///< m × L
  Index solver_runs_ = 0;
};

static_assert(TwinWithOptimum<InfluenceCoefficientTwin> &&
              TwinWithDeviations<InfluenceCoefficientTwin>);

}  // namespace twincal
