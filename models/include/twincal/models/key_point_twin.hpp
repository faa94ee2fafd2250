#pragma once
/// @file
/// `KeyPointTwin<Nonlinearity>`: an analytic twin built like an FEM variation simulation — the
/// deviations of m key points of the assembly, r(x, u), and the quality their RMS,
///   r(x, u) = B (u − a(x)) + w(x),  then the Nonlinearity policy,  Q(x, u) = ‖r‖ / √m.
/// B = √m G diag(√λ) Vᵀ with G (m × d) orthonormal columns, V a random rotation and λ
/// log-uniform in [min_curvature, max_curvature], so BᵀB/m = V diag(λ) Vᵀ; w(x) ⟂ range(B) with
/// ‖w‖²/m = q0(x); q0(x) and a(x) come from an AnalyticAssemblySet. With NoNonlinearity,
/// Q² = q0(x) + (u − a(x))ᵀ BᵀB/m (u − a(x)) exactly: the RmsQuadraticTwin's shape, with its
/// optimum a(x). With contact, stiffening or kinks (deviation_nonlinearity.hpp) Q² is not a
/// quadratic and the optimum is not known: u0(x) is searched, as for a real twin.

#include <cmath>
#include <concepts>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/qr.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/models/analytic_assembly_set.hpp"
#include "twincal/models/analytic_twin_base.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/deviation_nonlinearity.hpp"
#include "twincal/models/no_nonlinearity.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

struct KeyPointTwinOptions {
  AnalyticAssemblyOptions assemblies;
  Index key_points = 60;       ///< m, at least d + 1 (w(x) needs a direction outside range(B))
  double min_curvature = 0.5;  ///< smallest eigenvalue of BᵀB/m
  double max_curvature = 5.0;  ///< largest eigenvalue of BᵀB/m
  double strength = 1.0;       ///< s of the nonlinearity (its header says what it scales)

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::nested("assemblies", assemblies),
         rule::check(key_points > assemblies.dimension, "key_points", key_points,
                     "must be > dimension = {}", assemblies.dimension),
         rule::positive_range("min_curvature", min_curvature, "max_curvature", max_curvature),
         rule::non_negative_finite("strength", strength)});
  }
};

/// The assemblies, names and bounds are AnalyticTwinBase's; this class adds B, w(x), the
/// nonlinearity and Q.
template <DeviationNonlinearity Nonlinearity>
class KeyPointTwin : public AnalyticTwinBase {
 public:
  /// Draws the assemblies (substream "assemblies"), B ("influence"), w ("residuals") and the
  /// nonlinearity ("nonlinearity") from `stream`.
  /// @throws InvalidArgumentError when the options are inconsistent (the nonlinearity's own
  ///         rules on the strength included).
  KeyPointTwin(const KeyPointTwinOptions& options, const RandomStream& stream)
      : AnalyticTwinBase(draw_assemblies(options, stream)),
        nonlinearity_(options.key_points, options.assemblies.dimension, options.strength,
                      stream.substream("nonlinearity")),
        strength_(options.strength) {
    const Index d = control_dimension();
    const Index m = options.key_points;
    RandomStream influence = stream.substream("influence");
    MatrixX gaussian(m, d);
    influence.fill_normal(gaussian);
    Eigen::HouseholderQR<MatrixX> qr(gaussian);
    const MatrixX columns = qr.householderQ() * MatrixX::Identity(m, d);  // G
    MatrixX square(d, d);
    influence.fill_normal(square);
    const MatrixX rotation = Eigen::HouseholderQR<MatrixX>(square).householderQ();  // V
    VectorX eigenvalues(d);
    const double log_min = std::log(options.min_curvature);
    const double log_max = std::log(options.max_curvature);
    for (double& lambda : eigenvalues) {
      lambda = std::exp(log_min + (log_max - log_min) * influence.uniform());
    }
    influence_ = std::sqrt(static_cast<double>(m)) * columns *
                 eigenvalues.cwiseSqrt().asDiagonal() * rotation.transpose();

    RandomStream residual_stream = stream.substream("residuals");
    const std::vector<AssemblyId> all = assemblies();
    residuals_.resize(m, static_cast<Index>(all.size()));
    VectorX draw(m);
    for (std::size_t k = 0; k < all.size(); ++k) {
      residual_stream.fill_normal(draw);
      draw -= columns * (columns.transpose() * draw);  // ⟂ range(B)
      const double q0 = assembly_set().q0(all[k]);
      residuals_.col(static_cast<Index>(k)) =
          draw * std::sqrt(q0 * static_cast<double>(m)) / draw.norm();
    }
  }

  [[nodiscard]] Index key_point_count() const noexcept { return influence_.rows(); }
  /// B.
  [[nodiscard]] const MatrixX& influence() const noexcept { return influence_; }
  [[nodiscard]] const Nonlinearity& nonlinearity() const noexcept { return nonlinearity_; }
  [[nodiscard]] double strength() const noexcept { return strength_; }

  /// Where a search for u0(x) starts: a(x), the optimum of the affine part (searched_optimum_twin
  /// in controllers polishes from here).
  [[nodiscard]] VectorX search_start(const AssemblyId& assembly) const {
    return assembly_set().optimum(assembly);
  }

  /// u0(x) = a(x) and z*(x) = sqrt(q0(x)): exact without a nonlinearity (Q² is then the
  /// RMS-quadratic twin's); with one they are not known, and are searched.
  [[nodiscard]] VectorX optimum(
      const AssemblyId& assembly) const requires std::same_as<Nonlinearity, NoNonlinearity> {
    return assembly_set().optimum(assembly);
  }
  [[nodiscard]] double optimal_quality(
      const AssemblyId& assembly) const requires std::same_as<Nonlinearity, NoNonlinearity> {
    return std::sqrt(assembly_set().q0(assembly));
  }

  /// The key points' deviations r(x, u), nonlinearity applied.
  /// @throws InvalidArgumentError (unknown assembly), DimensionMismatchError (control).
  [[nodiscard]] VectorX deviations(const AssemblyId& assembly,
                                   const Eigen::Ref<const VectorX>& control) const {
    require_control(control, control_dimension());
    Scratch scratch = make_scratch();
    evaluate(assembly, assembly_set().index_of(assembly), control, scratch);
    return scratch.deviations;
  }

  /// out.col(j) = r(x, controls.col(j)) (TwinWithDeviations); one scratch per batch.
  /// @throws InvalidArgumentError (unknown assembly), DimensionMismatchError (controls, out).
  void deviations_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const {
    require_deviations_batch(controls, out, control_dimension(), key_point_count());
    const Index index = assembly_set().index_of(assembly);
    Scratch scratch = make_scratch();
    for (Index j = 0; j < controls.cols(); ++j) {
      evaluate(assembly, index, controls.col(j), scratch);
      out.col(j) = scratch.deviations;
    }
  }

  /// Q(x, u) = RMS of r(x, u).
  [[nodiscard]] double quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const {
    require_control(control, control_dimension());
    Scratch scratch = make_scratch();
    return evaluate(assembly, assembly_set().index_of(assembly), control, scratch);
  }

  /// out(j) = Q(x, controls.col(j)); one pair of scratch vectors per batch.
  void quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    require_control_batch(controls, out, control_dimension());
    const Index index = assembly_set().index_of(assembly);
    Scratch scratch = make_scratch();
    for (Index j = 0; j < controls.cols(); ++j) {
      out(j) = evaluate(assembly, index, controls.col(j), scratch);
    }
  }

 private:
  struct Scratch {
    VectorX error;       // e
    VectorX moved;       // B e
    VectorX deviations;  // r
  };
  [[nodiscard]] Scratch make_scratch() const {
    return {VectorX(control_dimension()), VectorX(key_point_count()), VectorX(key_point_count())};
  }

  // r = B e + w(x), e = u − a(x), then the nonlinearity; returns ‖r‖/√m.
  template <typename Control>
  double evaluate(const AssemblyId& assembly, Index index, const Control& control,
                  Scratch& scratch) const {
    VectorX& error = scratch.error;
    VectorX& r = scratch.deviations;
    error = control - assembly_set().optimum(assembly);
    scratch.moved.noalias() = influence_ * error;
    r = residuals_.col(index) + scratch.moved;
    nonlinearity_.apply(control, error, scratch.moved, r);
    return std::sqrt(r.squaredNorm() / static_cast<double>(r.size()));
  }

  Nonlinearity nonlinearity_;
  double strength_;
  MatrixX influence_;  // B
  MatrixX residuals_;  // w(x), one column per assembly in assemblies() order
};

}  // namespace twincal
