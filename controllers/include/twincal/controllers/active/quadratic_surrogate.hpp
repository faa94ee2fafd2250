#pragma once
/// @file
/// `QuadraticSurrogate<Twin, N>`: fits the QuadraticModel of Q²(x, ·) around a control v0 from the
/// twin itself, by finite differences in one twin batch, and checks it.
///
/// From Q² (any twin):
/// - Full fit: Q² at v0, v0 ± h_i e_i and v0 + h_i e_i + h_j e_j (i < j), (d + 1)(d + 2)/2
///   evaluations, gives c, g and H; exact (to rounding) for a twin whose Q² is quadratic.
/// - Gradient fit: with H kept from the last full fit, Q² at v0 and v0 + h_i e_i, d + 1
///   evaluations, gives c and g. A compliant twin has one H for every assembly (y = A x + B u + c),
///   so the full fit is needed only every `hessian_refresh` assemblies.
/// - Refit (refit_gradient(): an earlier assembly's model moved to where it is now used, its H
///   given): Q² at v0 and v0 ± h_i e_i, 2d + 1 evaluations, g by central differences, which need
///   no H. The controller refits only models that failed their check, so the given H is wrong
///   there; forward differences corrected by it (d + 1 evaluations) left the analytic family
///   answering only Q at 8.62 × its baselines summed over 48 cells with 11 runs lost, central
///   ones at 7.12 with 3, both at quality_step_fraction 0.025 (docs/reproduction.md, "Black-box
///   twins that answer only Q").
/// From the key points' deviations (a TwinWithDeviations with m > 0 key points, unless
/// `from_deviations` is off), Gauss–Newton, with Q² = ‖r‖²/m:
///   c = ‖r(v0)‖²/m,  g = Jᵀr(v0)/m,  H = JᵀJ/m.
/// - Full fit: r at v0 and v0 ± h_i e_i, 2d + 1 evaluations, give the Jacobian J of r by central
///   differences, and a fresh H; where the Q² fit pays (d + 1)(d + 2)/2 for one.
/// - Gradient fit: with J kept from the last full fit, r at v0 alone, 1 evaluation. A compliant
///   twin has one J for every assembly (r = A x + B u + c).
/// Exact for an affine r (the linear FEM twins, key points without a nonlinearity); on a
/// piecewise-affine r (contact) exact on the piece v0 lies in where no kink is within a step,
/// while a quadratic through Q² at (d + 1)(d + 2)/2 points averages the pieces they fall on. It
/// leaves out Σ r_k ∇²r_k, the curvature of r itself (stiffening), which the check sees. Central
/// differences: with forward ones (d + 1 evaluations) the black-box twins' residuals summed 7 %
/// higher and a kink episode of the tests lost its offset (docs/reproduction.md, "Black-box
/// twins").
/// - Check: the model against the twin at given points (the controller uses points where the
///   model is about to be used); the largest relative error of Q² decides whether the twin is
///   quadratic enough to be updated with exact moments, or needs sigma points.
/// Steps h_i are a fraction of the twin's box per locator (QuadraticSurrogateOptions::
/// step_fraction from the deviations, quality_step_fraction from Q²). Every evaluation is counted.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/controllers/active/quadratic_model.hpp"
#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

struct QuadraticSurrogateOptions {
  /// Finite-difference step per locator of fits from the key points' deviations, as a fraction
  /// of the twin's box width on that locator.
  double step_fraction = 0.05;
  /// The same for fits from Q² alone (a twin that answers only its quality). Measured on twins
  /// answering only Q with the refits' central differences (docs/reproduction.md, "Black-box
  /// twins that answer only Q"): half of it, 0.025, took the analytic family's 48 cells from
  /// 7.38 to 7.12 × their baselines summed, but the user's ten shapes over 200 cells from 29.03
  /// (8 runs lost) to 31.05 (45): a quality that jumps (the snap shape, d = 12) from 2.40 to 6.74
  /// (2 → 36 lost of 100), since a jump inside a shorter stencil is a larger difference quotient.
  double quality_step_fraction = 0.05;
  /// Assemblies between full fits of H (of J, from the deviations; 1: every assembly).
  Index hessian_refresh = 25;
  /// Largest relative error |Q²_model − Q²_twin| / max(Q²_twin, c) accepted at the check points.
  double tolerance = 1e-3;
  /// Fit from the key points' deviations (Gauss–Newton: 2d + 1 evaluations for J and H, 1 while
  /// J is kept) where the twin answers them; false fits from Q² alone. On the analytic twins with
  /// contact, stiffening and kinks it took the active controller's residuals summed over 60 cells
  /// from 16.5 to 11.3 × their baselines, and its lost runs from 65 to 29 (docs/reproduction.md,
  /// "Black-box twins").
  bool from_deviations = true;

  /// Whether fits come from the deviations for a twin that answers `key_points` of them (0: it
  /// answers only Q): the one rule the surrogate and whoever reports on it follow.
  [[nodiscard]] bool fits_from_deviations(Index key_points) const noexcept {
    return from_deviations && key_points > 0;
  }

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::in_left_open("step_fraction", step_fraction, 0.0, 0.5),
         rule::in_left_open("quality_step_fraction", quality_step_fraction, 0.0, 0.5),
         rule::at_least("hessian_refresh", hessian_refresh, Index{1}),
         rule::positive_finite("tolerance", tolerance)});
  }
};

template <Twin T, int N = Dynamic>
class QuadraticSurrogate {
 public:
  using Assembly = typename T::Assembly;

  /// Refers to `twin`, which must outlive the surrogate.
  /// @throws InvalidArgumentError (options; a twin box of zero or non-finite width).
  QuadraticSurrogate(const T& twin, QuadraticSurrogateOptions options = {})
      : twin_(&twin), options_(options) {
    require_valid("QuadraticSurrogateOptions", options_);
    const Index d = twin.control_dimension();
    if constexpr (N != Dynamic) require_dimension("twin.control_dimension()", d, N);
    hessian_.setZero(d, d);
    if constexpr (TwinWithDeviations<T>) {
      const Index m = twin.key_point_count();
      if (options_.fits_from_deviations(m)) {
        deviations_.resize(m, 2 * d + 1);
        jacobian_.setZero(m, d);
        fresh_jacobian_.resize(m, d);
      }
    }
    const double fraction =
        uses_deviations() ? options_.step_fraction : options_.quality_step_fraction;
    steps_.resize(d);
    for (Index i = 0; i < d; ++i) {
      const double width = twin.upper_bounds()(i) - twin.lower_bounds()(i);
      if (!(width > 0.0) || !std::isfinite(width)) {
        throw InvalidArgumentError(
            "twin bounds", fmt::format("twin bounds: locator {} has a box of width {}; rule: "
                                       "the box must be finite with upper > lower",
                                       i, width));
      }
      steps_(i) = fraction * width;
    }
    const Index full = (d + 1) * (d + 2) / 2;
    points_.resize(d, full);
    values_.resize(full);
  }

  [[nodiscard]] Index dimension() const noexcept { return steps_.size(); }
  [[nodiscard]] const QuadraticSurrogateOptions& options() const noexcept { return options_; }
  /// Whether fits are Gauss–Newton fits from the key points' deviations (see the file comment).
  [[nodiscard]] bool uses_deviations() const noexcept { return deviations_.size() > 0; }
  /// The finite-difference step per locator: step_fraction of the box from the deviations,
  /// quality_step_fraction from Q².
  [[nodiscard]] const VectorX& steps() const noexcept { return steps_; }
  /// Evaluations of a full fit, (d + 1)(d + 2)/2 (2d + 1 from the deviations), of a gradient
  /// fit, d + 1 (1), and of a refit_gradient(), 2d + 1 from either.
  [[nodiscard]] Index full_fit_evaluations() const noexcept {
    return uses_deviations() ? 2 * dimension() + 1 : values_.size();
  }
  [[nodiscard]] Index gradient_fit_evaluations() const noexcept {
    return uses_deviations() ? 1 : dimension() + 1;
  }
  [[nodiscard]] Index refit_evaluations() const noexcept { return 2 * dimension() + 1; }
  /// Whether the next fit will be a full one.
  [[nodiscard]] bool hessian_stale() const noexcept {
    return !has_hessian_ || age_ >= options_.hessian_refresh;
  }
  /// Forces the next fit to refit H (e.g. after a failed check).
  void invalidate_hessian() noexcept { has_hessian_ = false; }

  /// Fits `model` around `center` for `assembly` (full, gradient or Gauss–Newton fit, see the
  /// file comment).
  /// @returns the twin evaluations spent.
  /// @throws NonFiniteError naming the point when the twin returns a non-finite quality or
  ///         deviation; the twin's own errors propagate. The surrogate is unchanged when it throws.
  std::uint64_t fit(const Assembly& assembly, const Vector<N>& center, QuadraticModel<N>& model) {
    require_dimension("center", center.size(), dimension());
    const bool full = hessian_stale();
    std::uint64_t spent = 0;
    if (uses_deviations()) {
      spent = full ? fit_from_deviations(assembly, center, model)
                   : fit_with_kept_jacobian(assembly, center, model);
      if (full) {
        jacobian_.swap(fresh_jacobian_);
        hessian_ = model.hessian;
      }
    } else {
      spent = fit_from_squares(assembly, center, full, model);
    }
    if (full) {
      has_hessian_ = true;
      age_ = 0;
    }
    ++age_;
    return spent;
  }

  /// A gradient fit around `center` with the given `hessian` (refit_evaluations()), for an
  /// assembly measured earlier whose model is refitted where it is now used; the surrogate's own
  /// H and its age are unchanged. From Q² the gradient comes from central differences, which do
  /// not use `hessian` (the model keeps it); from the deviations it is a full Gauss–Newton fit,
  /// whose H is fitted there too. `hessian` is checked for its shape either way.
  /// @returns the twin evaluations spent.
  /// @throws as fit(); the surrogate is unchanged.
  template <typename Hessian>
  std::uint64_t refit_gradient(const Assembly& assembly, const Vector<N>& center,
                               const Eigen::MatrixBase<Hessian>& hessian,
                               QuadraticModel<N>& model) {
    const Index d = dimension();
    require_dimension("center", center.size(), d);
    require_shape("hessian", hessian, d, d);
    if (uses_deviations()) return fit_from_deviations(assembly, center, model);
    const Index count = refit_evaluations();
    evaluate_squares(assembly, axis_stencil(center, true), values_.head(count));
    model.center = center;
    model.value = values_(0);
    model.half_gradient.resize(d);
    model.hessian = hessian;
    central_gradient_from_values(model);
    return static_cast<std::uint64_t>(count);
  }

  /// The largest relative error of the model's Q² against the twin's at the columns of
  /// `points` (one twin batch), written to `error`.
  /// @returns the twin evaluations spent.
  std::uint64_t check(const Assembly& assembly, const QuadraticModel<N>& model,
                      const Eigen::Ref<const MatrixX>& points, double& error) {
    require_dimension("points", points.rows(), dimension(), "rows");
    const Index count = points.cols();
    if (values_.size() < count) values_.resize(count);
    evaluate_squares(assembly, points, values_.head(count));
    error = 0.0;
    for (Index c = 0; c < count; ++c) {
      const double twin = values_(c);
      const double scale = std::max({twin, model.value, std::numeric_limits<double>::min()});
      error = std::max(error, std::abs(model(points.col(c)) - twin) / scale);
    }
    return static_cast<std::uint64_t>(count);
  }

  static constexpr std::string_view json_format = "twincal.quadratic_surrogate";

  /// The kept H (and from the deviations the kept J), whether there is one and its age
  /// (assemblies since the last full fit): what decides the next fit's kind and its H. The steps
  /// are settings, the points workspaces.
  [[nodiscard]] nlohmann::json save() const {
    nlohmann::json saved = {{"format", json_format},
                            {"dimension", dimension()},
                            {"hessian", json_state::matrix_to_json(hessian_)},
                            {"has_hessian", has_hessian_},
                            {"age", age_}};
    if (uses_deviations()) saved["jacobian"] = json_state::matrix_to_json(jacobian_);
    return saved;
  }

  /// Restores a snapshot of save() into a surrogate of the same twin and options (from the
  /// deviations it needs "jacobian", which a surrogate fitted from Q² does not save).
  /// @throws InvalidArgumentError, DimensionMismatchError, NonFiniteError naming the field; the
  ///         surrogate unchanged.
  void restore(const nlohmann::json& saved) {
    const Index d = dimension();
    json_state::require_header(saved, json_format, d);
    SquareMatrix<N> hessian(d, d);
    json_state::read_matrix(json_state::field(saved, "hessian"), "hessian", hessian);
    const bool has_hessian = json_state::read_bool(saved, "has_hessian");
    const Index age = json_state::read_integer_field(saved, "age", 0);
    MatrixX jacobian(jacobian_.rows(), jacobian_.cols());
    if (uses_deviations()) {
      json_state::read_matrix(json_state::field(saved, "jacobian"), "jacobian", jacobian);
    }
    hessian_ = hessian;
    has_hessian_ = has_hessian;
    age_ = age;
    if (uses_deviations()) jacobian_ = jacobian;
  }

 private:
  // Leading columns of a workspace (points_, deviations_): a view, named rather than `auto`.
  using Columns = Eigen::Block<MatrixX, Dynamic, Dynamic, true>;

  // The fit from Q² of the file comment, full or with H kept; a full one writes hessian_.
  std::uint64_t fit_from_squares(const Assembly& assembly, const Vector<N>& center, bool full,
                                 QuadraticModel<N>& model) {
    const Index d = dimension();
    const Index count = full ? full_fit_evaluations() : gradient_fit_evaluations();
    Columns points = points_.leftCols(count);
    axis_stencil(center, full);
    if (full) {
      points.rightCols(count - 1 - 2 * d).colwise() = center;
      Index column = 1 + 2 * d;
      for (Index i = 0; i < d; ++i) {
        for (Index j = i + 1; j < d; ++j, ++column) {
          points(i, column) += steps_(i);
          points(j, column) += steps_(j);
        }
      }
    }
    evaluate_squares(assembly, points, values_.head(count));

    const double f0 = values_(0);
    model.center = center;
    model.value = f0;
    model.half_gradient.resize(d);
    if (full) {
      central_gradient_from_values(model);
      for (Index i = 0; i < d; ++i) {
        const double h = steps_(i);
        hessian_(i, i) = (values_(1 + i) - 2.0 * f0 + values_(1 + d + i)) / (2.0 * h * h);
      }
      Index column = 1 + 2 * d;
      for (Index i = 0; i < d; ++i) {
        for (Index j = i + 1; j < d; ++j, ++column) {
          const double mixed = (values_(column) - values_(1 + i) - values_(1 + j) + f0) /
                               (2.0 * steps_(i) * steps_(j));
          hessian_(i, j) = mixed;
          hessian_(j, i) = mixed;
        }
      }
    } else {
      gradient_from_values(hessian_, model);
    }
    model.hessian = hessian_;
    return static_cast<std::uint64_t>(count);
  }

  // The full Gauss–Newton fit of the file comment: J into fresh_jacobian_; writes only `model`
  // and the scratch.
  std::uint64_t fit_from_deviations(const Assembly& assembly, const Vector<N>& center,
                                    QuadraticModel<N>& model) {
    const Index d = dimension();
    const Index count = 2 * d + 1;
    if constexpr (TwinWithDeviations<T>) {
      twin_->deviations_batch(assembly, axis_stencil(center, true), deviations_);
    }
    require_finite_deviations(count);
    const double m = static_cast<double>(deviations_.rows());
    for (Index i = 0; i < d; ++i) {
      fresh_jacobian_.col(i) =
          (deviations_.col(1 + i) - deviations_.col(1 + d + i)) / (2.0 * steps_(i));
    }
    value_and_gradient(center, fresh_jacobian_, model);
    model.hessian.resize(d, d);
    model.hessian.noalias() = fresh_jacobian_.transpose().lazyProduct(fresh_jacobian_) / m;
    return static_cast<std::uint64_t>(count);
  }

  // The gradient fit from the deviations: r at v0, J and H kept.
  std::uint64_t fit_with_kept_jacobian(const Assembly& assembly, const Vector<N>& center,
                                       QuadraticModel<N>& model) {
    Columns point = points_.leftCols(1);
    point.col(0) = center;
    Columns residual = deviations_.leftCols(1);
    if constexpr (TwinWithDeviations<T>) twin_->deviations_batch(assembly, point, residual);
    require_finite_deviations(1);
    value_and_gradient(center, jacobian_, model);
    model.hessian = hessian_;
    return 1;
  }

  // c = ‖r(v0)‖²/m and g = Jᵀr(v0)/m, r(v0) the first column of deviations_. Coefficient-wise
  // products: no blocking workspace, so a fit allocates nothing.
  void value_and_gradient(const Vector<N>& center, const MatrixX& jacobian,
                          QuadraticModel<N>& model) const {
    const double m = static_cast<double>(deviations_.rows());
    model.center = center;
    model.value = deviations_.col(0).squaredNorm() / m;
    model.half_gradient.resize(dimension());
    model.half_gradient.noalias() = jacobian.transpose().lazyProduct(deviations_.col(0)) / m;
  }

  // The first `count` columns of deviations_ are finite.
  void require_finite_deviations(Index count) const {
    for (Index c = 0; c < count; ++c) {
      for (Index k = 0; k < deviations_.rows(); ++k) {
        if (std::isfinite(deviations_(k, c))) continue;
        throw NonFiniteError("twin deviations",
                             fmt::format("twin deviations: r(x, v) is not finite at v = column {} "
                                         "of the surrogate's points (key point {} is {}); rule: "
                                         "the twin must return finite deviations",
                                         c, k, deviations_(k, c)));
      }
    }
  }

  // The first columns of points_: v0, v0 + h_i e_i and, two-sided, v0 − h_i e_i (d + 1 or
  // 2d + 1 columns; the fits' stencils all begin with these).
  Columns axis_stencil(const Vector<N>& center, bool two_sided) {
    const Index d = dimension();
    Columns points = points_.leftCols(two_sided ? 2 * d + 1 : d + 1);
    points.colwise() = center;
    for (Index i = 0; i < d; ++i) {
      points(i, 1 + i) += steps_(i);
      if (two_sided) points(i, 1 + d + i) -= steps_(i);
    }
    return points;
  }

  // g from Q² at v0 ± h_i e_i (values_ of the two-sided axis stencil): central differences,
  // exact for a quadratic whatever its H.
  void central_gradient_from_values(QuadraticModel<N>& model) const {
    const Index d = dimension();
    for (Index i = 0; i < d; ++i) {
      model.half_gradient(i) = (values_(1 + i) - values_(1 + d + i)) / (4.0 * steps_(i));
    }
  }

  // g from Q² at v0 and v0 + h_i e_i (values_) with H known: one-sided differences corrected
  // for the curvature.
  void gradient_from_values(const SquareMatrix<N>& hessian, QuadraticModel<N>& model) const {
    const double f0 = values_(0);
    for (Index i = 0; i < dimension(); ++i) {
      const double h = steps_(i);
      model.half_gradient(i) = (values_(1 + i) - f0 - h * h * hessian(i, i)) / (2.0 * h);
    }
  }

  template <typename Points, typename Out>
  void evaluate_squares(const Assembly& assembly, const Points& points, Out&& out) const {
    twin_->quality_batch(assembly, points, out);
    for (Index c = 0; c < out.size(); ++c) {
      if (!std::isfinite(out(c))) {
        throw NonFiniteError("twin quality",
                             fmt::format("twin quality: Q(x, v) is {} at v = column {} of the "
                                         "surrogate's points; rule: the twin must return finite "
                                         "qualities",
                                         out(c), c));
      }
      out(c) *= out(c);
    }
  }

  const T* twin_;
  QuadraticSurrogateOptions options_;
  VectorX steps_;
  SquareMatrix<N> hessian_;
  bool has_hessian_ = false;
  Index age_ = 0;
  MatrixX points_;
  VectorX values_;
  MatrixX deviations_;      // m × (2d + 1) from the deviations, else empty
  MatrixX jacobian_;        // m × d, J kept from the last full fit
  MatrixX fresh_jacobian_;  // m × d, J of the fit at hand
};

}  // namespace twincal
