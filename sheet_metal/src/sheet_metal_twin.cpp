#include "twincal/sheet_metal/sheet_metal_twin.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include <fmt/format.h>
#include <Eigen/QR>

#include "twincal/core/bounded_least_squares.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/sheet_metal/sheet_metal_process.hpp"

namespace twincal {

namespace {

void require_parts(std::string_view name, const std::vector<VectorX>& parts, Index dofs) {
  if (parts.empty()) {
    throw InvalidArgumentError(std::string(name),
                               fmt::format("{}: is empty; rule: needs at least one part", name));
  }
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string label = fmt::format("{}[{}]", name, i);
    require_dimension(label, parts[i].size(), dofs);
    require_finite(label, parts[i]);
  }
}

}  // namespace

std::optional<std::string> SheetMetalTwinOptions::validate() const {
  return first_problem({rule::nested("section", section), rule::nested("field", field),
                        rule::at_least("upper_parts", upper_parts, decltype(upper_parts){1}),
                        rule::at_least("lower_parts", lower_parts, decltype(lower_parts){1}),
                        rule::positive_finite("locator_bound", locator_bound)});
}

SheetMetalTwin::SheetMetalTwin(SheetMetalLayout layout, const SheetMetalTwinOptions& options,
                               std::vector<VectorX> upper_parts, std::vector<VectorX> lower_parts)
    : options_(options),
      upper_parts_(std::move(upper_parts)),
      lower_parts_(std::move(lower_parts)) {
  // Cheap checks first, before meshing and factorizing.
  require_valid("options", options);
  require_valid("layout", layout);
  require_parts("upper_parts", upper_parts_, layout.mesh(SheetMetalPart::upper).dof_count());
  require_parts("lower_parts", lower_parts_, layout.mesh(SheetMetalPart::lower).dof_count());
  process_ = std::make_shared<const SheetMetalProcess>(std::move(layout), options.section);
  const SheetMetalProcess& process = *process_;

  const Index d = process.control_dimension();
  const Index m = process.key_point_count();
  for (const LayoutPoint& locator : process.layout().locators)
    locator_names_.push_back(locator.name);
  lower_bounds_ = VectorX::Constant(d, -options.locator_bound);
  upper_bounds_ = VectorX::Constant(d, options.locator_bound);

  // The affine map: B from unit controls, A applied part by part (each part alone, the other
  // one nominal), c = 0.
  influence_ = process.control_influence();
  const VectorX zero_control = VectorX::Zero(d);
  const VectorX upper_nominal = VectorX::Zero(process.dof_count(SheetMetalPart::upper));
  const VectorX lower_nominal = VectorX::Zero(process.dof_count(SheetMetalPart::lower));
  upper_response_.resize(m, upper_part_count());
  for (Index i = 0; i < upper_part_count(); ++i) {
    upper_response_.col(i) = process.key_deviation(upper_parts_[static_cast<std::size_t>(i)],
                                                   lower_nominal, zero_control);
  }
  lower_response_.resize(m, lower_part_count());
  for (Index j = 0; j < lower_part_count(); ++j) {
    lower_response_.col(j) = process.key_deviation(
        upper_nominal, lower_parts_[static_cast<std::size_t>(j)], zero_control);
  }

  const double scale = 1.0 / static_cast<double>(m);
  curvature_ = scale * (influence_.transpose() * influence_);
  const Index n = upper_part_count() * lower_part_count();
  linear_.resize(d, n);
  constant_.resize(n);
  optimum_.resize(d, n);
  optimal_quality_.resize(n);
  // Minimum-norm least squares; singular values below 1e-9 σ_max count as zero (directions of u
  // that cannot move Q measurably must not produce huge controls).
  Eigen::CompleteOrthogonalDecomposition<MatrixX> least_squares;
  least_squares.setThreshold(1e-9);
  least_squares.compute(influence_);
  for (Index i = 0; i < upper_part_count(); ++i) {
    for (Index j = 0; j < lower_part_count(); ++j) {
      const Index c = i * lower_part_count() + j;
      const VectorX y0 = upper_response_.col(i) + lower_response_.col(j);
      linear_.col(c) = scale * (influence_.transpose() * y0);
      constant_(c) = scale * y0.squaredNorm();
      const VectorX u0 =
          options.bounded_optimum
              ? bounded_least_squares(influence_, y0, lower_bounds_, upper_bounds_).solution
              : VectorX(least_squares.solve(-y0));
      optimum_.col(c) = u0;
      optimal_quality_(c) = std::sqrt(scale) * (y0 + influence_ * u0).norm();
    }
  }
}

SheetMetalTwin SheetMetalTwin::generate(SheetMetalLayout layout,
                                        const SheetMetalTwinOptions& options, std::uint64_t seed) {
  require_valid("options", options);
  const PartField field(options.field);
  const PlateMesh upper_mesh = layout.mesh(SheetMetalPart::upper);
  const PlateMesh lower_mesh = layout.mesh(SheetMetalPart::lower);
  const RandomStream root(seed);
  std::vector<VectorX> upper = field.sample_parts(upper_mesh, root, "upper", options.upper_parts);
  std::vector<VectorX> lower = field.sample_parts(lower_mesh, root, "lower", options.lower_parts);
  return {std::move(layout), options, std::move(upper), std::move(lower)};
}

SheetMetalLayout SheetMetalTwin::layout_of(SheetMetalCase which) {
  return which == SheetMetalCase::body ? SheetMetalLayout::body() : SheetMetalLayout::door();
}

SheetMetalTwin SheetMetalTwin::make(SheetMetalCase which, std::uint64_t seed,
                                    const SheetMetalTwinOptions& options) {
  return generate(layout_of(which), options, seed);
}

SheetMetalTwin SheetMetalTwin::make(SheetMetalCase which, std::uint64_t seed) {
  return make(which, seed, SheetMetalTwinOptions{});
}

SheetMetalTwin SheetMetalTwin::body(std::uint64_t seed) { return make(SheetMetalCase::body, seed); }

SheetMetalTwin SheetMetalTwin::door(std::uint64_t seed) { return make(SheetMetalCase::door, seed); }

Index SheetMetalTwin::column(const AssemblyId& assembly) const {
  if (assembly.upper < 0 || assembly.upper >= upper_part_count() || assembly.lower < 0 ||
      assembly.lower >= lower_part_count()) {
    throw InvalidArgumentError(
        "assembly", fmt::format("assembly: is {}; rule: upper must lie in [0, {}) and lower in "
                                "[0, {})",
                                assembly, upper_part_count(), lower_part_count()));
  }
  return assembly.upper * lower_part_count() + assembly.lower;
}

double SheetMetalTwin::evaluate(Index c, const Eigen::Ref<const VectorX>& control) const {
  // q + 2gᵀu + uᵀHu with H symmetric: the strict upper triangle counted twice. Scalar loops, no
  // temporaries (no allocation per call).
  const Index d = control_dimension();
  double value = constant_(c);
  for (Index l = 0; l < d; ++l) {
    const double ul = control(l);
    double row = 0.5 * curvature_(l, l) * ul + linear_(l, c);
    for (Index k = l + 1; k < d; ++k) row += curvature_(k, l) * control(k);
    value += 2.0 * ul * row;
  }
  return std::sqrt(std::max(value, 0.0));
}

double SheetMetalTwin::quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const {
  require_control(control, control_dimension());
  return evaluate(column(assembly), control);
}

void SheetMetalTwin::quality_batch(const AssemblyId& assembly,
                                   const Eigen::Ref<const MatrixX>& controls,
                                   Eigen::Ref<VectorX> out) const {
  require_control_batch(controls, out, control_dimension());
  const Index c = column(assembly);
  for (Index j = 0; j < controls.cols(); ++j) out(j) = evaluate(c, controls.col(j));
}

VectorX SheetMetalTwin::optimum(const AssemblyId& assembly) const {
  return optimum_.col(column(assembly));
}

double SheetMetalTwin::optimal_quality(const AssemblyId& assembly) const {
  return optimal_quality_(column(assembly));
}

std::vector<AssemblyId> SheetMetalTwin::assemblies() const {
  std::vector<AssemblyId> all;
  all.reserve(static_cast<std::size_t>(upper_part_count() * lower_part_count()));
  for (Index i = 0; i < upper_part_count(); ++i) {
    for (Index j = 0; j < lower_part_count(); ++j) all.push_back({i, j});
  }
  return all;
}

VectorX SheetMetalTwin::locator_effects() const {
  const Index d = control_dimension();
  const Index n = constant_.size();
  VectorX effects = VectorX::Zero(d);
  for (Index c = 0; c < n; ++c) {
    const double nominal = std::sqrt(constant_(c));
    for (Index k = 0; k < d; ++k) {
      // Q² along u_k alone is q + 2 g_k u_k + H_kk u_k², minimal at −g_k/H_kk (clipped to the box).
      const double h = curvature_(k, k);
      const double uk =
          h > 0.0 ? std::clamp(-linear_(k, c) / h, lower_bounds_(k), upper_bounds_(k)) : 0.0;
      const double value = constant_(c) + 2.0 * linear_(k, c) * uk + h * uk * uk;
      effects(k) += nominal - std::sqrt(std::max(value, 0.0));
    }
  }
  return effects / static_cast<double>(n);
}

std::array<Index, 3> SheetMetalTwin::significant_locators() const {
  const VectorX effects = locator_effects();
  std::vector<Index> order(static_cast<std::size_t>(effects.size()));
  std::iota(order.begin(), order.end(), Index{0});
  // Ties (exactly equal effects) go to the lower index, so the choice is deterministic.
  std::stable_sort(order.begin(), order.end(),
                   [&](Index a, Index b) { return effects(a) > effects(b); });
  return {order[0], order[1], order[2]};
}

double SheetMetalTwin::achievable_gain() const {
  double nominal = 0.0;
  for (Index c = 0; c < constant_.size(); ++c) nominal += std::sqrt(constant_(c));
  return 1.0 - optimal_quality_.sum() / nominal;
}

VectorX SheetMetalTwin::key_deviation(const AssemblyId& assembly,
                                      const Eigen::Ref<const VectorX>& control) const {
  require_control(control, control_dimension());
  const Index c = column(assembly);
  const Index i = c / lower_part_count();
  const Index j = c % lower_part_count();
  VectorX y = upper_response_.col(i) + lower_response_.col(j);
  y.noalias() += influence_ * control;
  return y;
}

void SheetMetalTwin::deviations_batch(const AssemblyId& assembly,
                                      const Eigen::Ref<const MatrixX>& controls,
                                      Eigen::Ref<MatrixX> out) const {
  require_deviations_batch(controls, out, control_dimension(), key_point_count());
  const Index c = column(assembly);
  const Index i = c / lower_part_count();
  const Index j = c % lower_part_count();
  // Column by column, as key_deviation: a matrix product sums in another order than a
  // matrix-vector one, and a batch must give each control's deviations to the bit.
  for (Index k = 0; k < controls.cols(); ++k) {
    out.col(k) = upper_response_.col(i) + lower_response_.col(j);
    out.col(k).noalias() += influence_ * controls.col(k);
  }
}

const VectorX& SheetMetalTwin::upper_part(Index i) const {
  if (i < 0 || i >= upper_part_count()) {
    throw InvalidArgumentError(
        "i", fmt::format("i: is {}; rule: must lie in [0, {})", i, upper_part_count()));
  }
  return upper_parts_[static_cast<std::size_t>(i)];
}

const VectorX& SheetMetalTwin::lower_part(Index j) const {
  if (j < 0 || j >= lower_part_count()) {
    throw InvalidArgumentError(
        "j", fmt::format("j: is {}; rule: must lie in [0, {})", j, lower_part_count()));
  }
  return lower_parts_[static_cast<std::size_t>(j)];
}

}  // namespace twincal
