#include "twincal/calculix/influence_coefficient_twin.hpp"

#include <cmath>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "twincal/core/bounded_least_squares.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {
namespace {

CalculixTwin linear_copy(const CalculixTwin& twin, std::vector<VectorX> upper,
                         std::vector<VectorX> lower) {
  CalculixOptions options = twin.model().options();
  options.contact = false;
  options.geometric_nonlinearity = false;
  options.refinement = 1;  // the twin's layout is already on the refined grid
  return {twin.model().layout(), options, std::move(upper), std::move(lower)};
}

// A map built on a failed solve would be wrong everywhere: the failure is the construction's.
void require_solved(const CalculixBatchSummary& summary, InfluenceLinearization linearization,
                    std::string_view what) {
  if (summary.failed.empty()) return;
  throw CalculixError(CalculixFailure::no_convergence,
                      fmt::format("influence coefficients ({}): the solve of {} failed: {}",
                                  to_string(linearization), what, summary.last_failure),
                      "");
}

}  // namespace

const char* to_string(InfluenceLinearization linearization) noexcept {
  switch (linearization) {
    case InfluenceLinearization::small_displacement:
      return "small-displacement";
    case InfluenceLinearization::secant:
      return "secant";
  }
  return "unknown";
}

std::optional<InfluenceLinearization> parse_influence_linearization(
    std::string_view text) noexcept {
  for (const InfluenceLinearization linearization :
       {InfluenceLinearization::small_displacement, InfluenceLinearization::secant}) {
    if (text == to_string(linearization)) return linearization;
  }
  return std::nullopt;
}

std::optional<std::string> InfluenceCoefficientOptions::validate() const {
  return first_problem(
      {rule::check(linearization == InfluenceLinearization::small_displacement ||
                       linearization == InfluenceLinearization::secant,
                   "linearization", static_cast<int>(linearization),
                   "must be small_displacement or secant"),
       rule::in_left_open("secant_step_fraction", secant_step_fraction, 0.0, 0.5)});
}

InfluenceCoefficientTwin::InfluenceCoefficientTwin(const CalculixTwin& twin,
                                                   const InfluenceCoefficientOptions& options)
    : options_((require_valid("InfluenceCoefficientOptions", options), options)),
      locator_names_(twin.locator_names()),
      lower_bounds_(twin.lower_bounds()),
      upper_bounds_(twin.upper_bounds()) {
  const Index d = twin.control_dimension();
  const Index m = twin.model().key_point_count();
  const Index upper_nodes = twin.model().mesh(SheetMetalPart::upper).node_count();
  const Index lower_nodes = twin.model().mesh(SheetMetalPart::lower).node_count();
  std::vector<VectorX> uppers;
  std::vector<VectorX> lowers;
  for (Index i = 0; i < twin.upper_part_count(); ++i) uppers.push_back(twin.parts({i, 0}).upper);
  for (Index j = 0; j < twin.lower_part_count(); ++j) lowers.push_back(twin.parts({0, j}).lower);
  const bool secant = options_.linearization == InfluenceLinearization::secant;
  solver_ = secant ? std::make_shared<const CalculixTwin>(twin)
                   : std::make_shared<const CalculixTwin>(linear_copy(twin, uppers, lowers));
  const auto solve = [&](const CalculixParts& parts, const Eigen::Ref<const MatrixX>& controls,
                         const std::string& label) {
    MatrixX y(m, controls.cols());
    const CalculixBatchSummary summary = solver_->key_deviations(parts, controls, y, label);
    solver_runs_ += summary.solver_runs;
    require_solved(summary, options_.linearization, label);
    return y;
  };
  const CalculixParts flat{VectorX::Zero(upper_nodes), VectorX::Zero(lower_nodes)};
  // The flat assembly's response at c; 0 for the linear solve, whose flat parts do not deviate.
  VectorX flat_response = VectorX::Zero(m);
  if (secant) {
    operating_point_ = 0.5 * (lower_bounds_ + upper_bounds_);
    const VectorX half_step = options_.secant_step_fraction * (upper_bounds_ - lower_bounds_);
    MatrixX controls = operating_point_.replicate(1, 2 * d + 1);
    for (Index k = 0; k < d; ++k) {
      controls(k, 1 + 2 * k) += half_step(k);
      controls(k, 2 + 2 * k) -= half_step(k);
    }
    const MatrixX y = solve(flat, controls, "flat parts at the secants' ends");
    flat_response = y.col(0);
    influence_.resize(m, d);
    for (Index k = 0; k < d; ++k) {
      influence_.col(k) = (y.col(1 + 2 * k) - y.col(2 + 2 * k)) / (2.0 * half_step(k));
    }
  } else {
    operating_point_ = VectorX::Zero(d);
    influence_ = solve(flat, MatrixX::Identity(d, d), "the unit locator displacements");
  }
  upper_responses_.resize(m, static_cast<Index>(uppers.size()));
  lower_responses_.resize(m, static_cast<Index>(lowers.size()));
  for (std::size_t i = 0; i < uppers.size(); ++i) {
    upper_responses_.col(static_cast<Index>(i)) =
        solve({uppers[i], flat.lower}, operating_point_, fmt::format("upper part {}", i)) -
        influence_ * operating_point_;
  }
  // y_U(i) already carries −B c; the lower part's response is taken relative to the flat one's
  // so that the flat assembly's own response at c is counted once.
  for (std::size_t j = 0; j < lowers.size(); ++j) {
    lower_responses_.col(static_cast<Index>(j)) =
        solve({flat.upper, lowers[j]}, operating_point_, fmt::format("lower part {}", j)) -
        flat_response;
  }
}

VectorX InfluenceCoefficientTwin::solved_unadjusted_deviations(const CalculixParts& parts,
                                                               const std::string& label) const {
  MatrixX y(influence_.rows(), 1);
  require_solved(solver_->key_deviations(parts, operating_point_, y, label), options_.linearization,
                 label);
  return y.col(0) - influence_ * operating_point_;
}

VectorX InfluenceCoefficientTwin::unadjusted_deviations(const AssemblyId& assembly) const {
  if (assembly.upper < 0 || assembly.upper >= upper_responses_.cols() || assembly.lower < 0 ||
      assembly.lower >= lower_responses_.cols()) {
    throw InvalidArgumentError(
        "assembly", fmt::format("assembly: {}; rule: upper in [0, {}), lower in [0, {})", assembly,
                                upper_responses_.cols(), lower_responses_.cols()));
  }
  return upper_responses_.col(assembly.upper) + lower_responses_.col(assembly.lower);
}

double InfluenceCoefficientTwin::quality(const AssemblyId& assembly,
                                         const Eigen::Ref<const VectorX>& control) const {
  require_control(control, control_dimension());
  const VectorX y = unadjusted_deviations(assembly) + influence_ * control;
  return y.norm() / std::sqrt(static_cast<double>(y.size()));
}

void InfluenceCoefficientTwin::quality_batch(const AssemblyId& assembly,
                                             const Eigen::Ref<const MatrixX>& controls,
                                             Eigen::Ref<VectorX> out) const {
  qualities_from(unadjusted_deviations(assembly), controls, out);
}

void InfluenceCoefficientTwin::deviations_batch(const AssemblyId& assembly,
                                                const Eigen::Ref<const MatrixX>& controls,
                                                Eigen::Ref<MatrixX> out) const {
  require_deviations_batch(controls, out, control_dimension(), key_point_count());
  deviations_from(unadjusted_deviations(assembly), controls, out);
}

void InfluenceCoefficientTwin::deviations_batch(const CalculixParts& parts,
                                                const Eigen::Ref<const MatrixX>& controls,
                                                Eigen::Ref<MatrixX> out) const {
  require_deviations_batch(controls, out, control_dimension(), key_point_count());
  deviations_from(unadjusted_deviations(parts), controls, out);
}

VectorX InfluenceCoefficientTwin::unadjusted_deviations(const CalculixParts& parts) const {
  return solved_unadjusted_deviations(parts, "scanned parts");
}

void InfluenceCoefficientTwin::quality_batch(const CalculixParts& parts,
                                             const Eigen::Ref<const MatrixX>& controls,
                                             Eigen::Ref<VectorX> out) const {
  require_dimension("controls (rows)", controls.rows(), control_dimension());
  qualities_from(unadjusted_deviations(parts), controls, out);
}

void InfluenceCoefficientTwin::deviations_from(const VectorX& y0,
                                               const Eigen::Ref<const MatrixX>& controls,
                                               Eigen::Ref<MatrixX> out) const {
  for (Index k = 0; k < controls.cols(); ++k) {
    out.col(k) = y0;
    out.col(k).noalias() += influence_ * controls.col(k);
  }
}

void InfluenceCoefficientTwin::qualities_from(const VectorX& y0,
                                              const Eigen::Ref<const MatrixX>& controls,
                                              Eigen::Ref<VectorX> out) const {
  require_dimension("controls (rows)", controls.rows(), control_dimension());
  require_dimension("out", out.size(), controls.cols());
  MatrixX y(y0.size(), controls.cols());
  deviations_from(y0, controls, y);
  out = y.colwise().norm().transpose() / std::sqrt(static_cast<double>(y0.size()));
}

VectorX InfluenceCoefficientTwin::optimum(const AssemblyId& assembly) const {
  return bounded_least_squares(influence_, unadjusted_deviations(assembly), lower_bounds_,
                               upper_bounds_)
      .solution;
}

double InfluenceCoefficientTwin::optimal_quality(const AssemblyId& assembly) const {
  return quality(assembly, optimum(assembly));
}

}  // namespace twincal
