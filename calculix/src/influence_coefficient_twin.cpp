#include "twincal/calculix/influence_coefficient_twin.hpp"

#include <cmath>

#include <fmt/format.h>

#include "twincal/core/bounded_least_squares.hpp"
#include "twincal/core/error.hpp"
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

}  // namespace

InfluenceCoefficientTwin::InfluenceCoefficientTwin(const CalculixTwin& twin)
    : locator_names_(twin.locator_names()),
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
  linear_ = std::make_shared<const CalculixTwin>(linear_copy(twin, uppers, lowers));
  const auto solve = [&](const CalculixParts& parts, const Eigen::Ref<const MatrixX>& controls,
                         const std::string& label) {
    MatrixX y(m, controls.cols());
    const CalculixBatchSummary summary = linear_->key_deviations(parts, controls, y, label);
    solver_runs_ += summary.solver_runs;
    if (!summary.failed.empty()) {
      throw CalculixError(CalculixFailure::no_convergence,
                          "influence coefficients: a linear solve failed: " + summary.last_failure,
                          "");
    }
    return y;
  };
  const CalculixParts flat{VectorX::Zero(upper_nodes), VectorX::Zero(lower_nodes)};
  influence_ = solve(flat, MatrixX::Identity(d, d), "the unit locator displacements");
  upper_responses_.resize(m, static_cast<Index>(uppers.size()));
  lower_responses_.resize(m, static_cast<Index>(lowers.size()));
  const VectorX zero = VectorX::Zero(d);
  for (std::size_t i = 0; i < uppers.size(); ++i) {
    upper_responses_.col(static_cast<Index>(i)) =
        solve({uppers[i], flat.lower}, zero, fmt::format("upper part {}", i));
  }
  for (std::size_t j = 0; j < lowers.size(); ++j) {
    lower_responses_.col(static_cast<Index>(j)) =
        solve({flat.upper, lowers[j]}, zero, fmt::format("lower part {}", j));
  }
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
  VectorX y0(influence_.rows());
  const CalculixBatchSummary summary =
      linear_->key_deviations(parts, VectorX::Zero(control_dimension()), y0, "scanned parts");
  if (!summary.failed.empty()) {
    throw CalculixError(
        CalculixFailure::no_convergence,
        "influence coefficients: the linear solve of scanned parts failed: " + summary.last_failure,
        "");
  }
  return y0;
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
