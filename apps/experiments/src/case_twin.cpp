#include "twincal/experiments/case_twin.hpp"

#include <algorithm>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/experiments/scanned_assembly.hpp"
#include "twincal/models/locator_subset.hpp"
#include "twincal/models/quadratic_departure.hpp"

namespace twincal {
namespace {

thread_local std::uint64_t thread_evaluations = 0;

// Per-thread grow-only workspace for the full controls: a batch of a size seen before reuses it.
Eigen::Block<MatrixX, Dynamic, Dynamic, true> full_controls(Index rows, Index cols) {
  thread_local MatrixX buffer;
  if (buffer.rows() != rows || buffer.cols() < cols) {
    buffer.resize(rows, std::max(cols, buffer.rows() == rows ? buffer.cols() : Index{0}));
  }
  return buffer.leftCols(cols);
}

}  // namespace

CaseTwin::CaseTwin(AnyTwin twin, std::vector<Index> locators, std::optional<AnyTwin> plant)
    : twin_(std::move(twin)), plant_(std::move(plant)), locators_(std::move(locators)) {
  const Index d = twin_.control_dimension();
  require_locator_indices(locators_, d);
  const std::vector<AssemblyId>& all = twin_.assemblies();
  if (all.empty()) {
    throw InvalidArgumentError("twin.assemblies()",
                               "twin.assemblies(): is empty; rule: must list >= 1 assembly");
  }
  const Index k = control_dimension();
  lower_bounds_.resize(k);
  upper_bounds_.resize(k);
  for (Index i = 0; i < k; ++i) {
    const Index l = locators_[static_cast<std::size_t>(i)];
    names_.push_back(twin_.locator_names()[static_cast<std::size_t>(l)]);
    lower_bounds_(i) = twin_.lower_bounds()(l);
    upper_bounds_(i) = twin_.upper_bounds()(l);
  }

  Index uppers = 0;
  for (const AssemblyId& a : all) {
    if (a.upper < 0 || a.lower < 0) {
      throw InvalidArgumentError(
          "twin.assemblies()",
          fmt::format("twin.assemblies(): lists {}; rule: part indices must be >= 0", a));
    }
    uppers = std::max(uppers, a.upper + 1);
    lower_parts_ = std::max(lower_parts_, a.lower + 1);
  }
  lookup_.assign(static_cast<std::size_t>(uppers * lower_parts_), -1);
  const Index n = std::ssize(all);
  full_optima_.resize(d, n);
  optima_.resize(k, n);
  optimal_qualities_.resize(n);
  for (Index j = 0; j < n; ++j) {
    const AssemblyId& a = all[static_cast<std::size_t>(j)];
    lookup_[static_cast<std::size_t>(a.upper * lower_parts_ + a.lower)] = j;
    const double z_star = twin_.optimal_quality(a);
    require_finite("z*", z_star);
    store_optimum(j, twin_.optimum(a), z_star);
  }
  if (plant_) {
    if (plant_->control_dimension() != d || plant_->locator_names() != twin_.locator_names() ||
        plant_->assemblies() != all) {
      throw InvalidArgumentError(
          "plant",
          fmt::format("plant: has {} locators and {} assemblies against the twin's {} "
                      "and {}; rule: the plant must have the twin's locators and "
                      "assemblies",
                      plant_->control_dimension(), plant_->assemblies().size(), d, all.size()));
    }
    plant_optimal_qualities_.resize(n);
    for (Index j = 0; j < n; ++j) {
      plant_optimal_qualities_(j) = plant_->optimal_quality(all[static_cast<std::size_t>(j)]);
      require_finite("plant z*", plant_optimal_qualities_(j));
    }
  }
}

void CaseTwin::store_optimum(Index j, const VectorX& full, double z_star) {
  full_optima_.col(j) = full;
  for (Index i = 0; i < control_dimension(); ++i)
    optima_(i, j) = full(locators_[static_cast<std::size_t>(i)]);
  optimal_qualities_(j) = z_star;
}

AssemblyId CaseTwin::add_scanned(const nlohmann::json& parts,
                                 const std::optional<ScannedOptimum>& known) {
  if (plant_) {
    throw InvalidArgumentError(
        "parts",
        "parts: are given to a case whose plant is a simulated twin; rule: scanned "
        "parts come from a real cell, which is its own plant");
  }
  const AssemblyId id = twin_.add_scanned(parts, known);
  const std::optional<Index> k = scanned_index(id);
  if (!k) {
    throw InvalidArgumentError(
        "parts", fmt::format("parts: the twin registered them as {}; rule: a scanned assembly's "
                             "id is (k, -1)",
                             id));
  }
  if (*k < std::ssize(scanned_positions_) && scanned_positions_[static_cast<std::size_t>(*k)] >= 0)
    return id;  // registered before (the twin shares its registrations with its copies)
  const VectorX full = twin_.optimum(id);
  const double z_star = twin_.optimal_quality(id);
  require_finite("z*", z_star);
  const Index j = full_optima_.cols();
  full_optima_.conservativeResize(Eigen::NoChange, j + 1);
  optima_.conservativeResize(Eigen::NoChange, j + 1);
  optimal_qualities_.conservativeResize(j + 1);
  store_optimum(j, full, z_star);
  if (*k >= std::ssize(scanned_positions_))
    scanned_positions_.resize(static_cast<std::size_t>(*k + 1), -1);
  scanned_positions_[static_cast<std::size_t>(*k)] = j;
  return id;
}

Index CaseTwin::position(const AssemblyId& assembly) const {
  if (const std::optional<Index> k = scanned_index(assembly)) {
    const Index found = *k < std::ssize(scanned_positions_)
                            ? scanned_positions_[static_cast<std::size_t>(*k)]
                            : Index{-1};
    if (found >= 0) return found;
    throw InvalidArgumentError(
        "assembly",
        fmt::format("assembly: scanned assembly {} is unknown; rule: must be registered first "
                    "(add_scanned)",
                    *k));
  }
  const Index slot = assembly.upper * lower_parts_ + assembly.lower;
  const Index found = assembly.lower >= 0 && assembly.lower < lower_parts_ && slot >= 0 &&
                              slot < std::ssize(lookup_)
                          ? lookup_[static_cast<std::size_t>(slot)]
                          : -1;
  if (found < 0) {
    throw InvalidArgumentError(
        "assembly",
        fmt::format("assembly: {} is unknown; rule: must be one of the twin's", assembly));
  }
  return found;
}

void CaseTwin::embed(Index position, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<MatrixX> out) const {
  for (Index c = 0; c < controls.cols(); ++c) {
    out.col(c) = full_optima_.col(position);
    for (Index i = 0; i < control_dimension(); ++i) {
      out(locators_[static_cast<std::size_t>(i)], c) = controls(i, c);
    }
  }
}

Eigen::Block<MatrixX, Dynamic, Dynamic, true> CaseTwin::embedded(
    const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls) const {
  Eigen::Block<MatrixX, Dynamic, Dynamic, true> full =
      full_controls(twin_.control_dimension(), controls.cols());
  embed(position(assembly), controls, full);
  return full;
}

double CaseTwin::evaluate(const AnyTwin& model, const AssemblyId& assembly,
                          const Eigen::Ref<const VectorX>& control) const {
  require_control(control, control_dimension());
  return model.quality(assembly, embedded(assembly, control).col(0));
}

double CaseTwin::plant_quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const {
  return evaluate(plant_ ? *plant_ : twin_, assembly, control);
}

double CaseTwin::quality(const AssemblyId& assembly,
                         const Eigen::Ref<const VectorX>& control) const {
  const double value = evaluate(twin_, assembly, control);
  ++thread_evaluations;
  return value;
}

void CaseTwin::quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                             Eigen::Ref<VectorX> out) const {
  require_control_batch(controls, out, control_dimension());
  twin_.quality_batch(assembly, embedded(assembly, controls), out);
  thread_evaluations += static_cast<std::uint64_t>(controls.cols());
}

void CaseTwin::deviations_batch(const AssemblyId& assembly,
                                const Eigen::Ref<const MatrixX>& controls,
                                Eigen::Ref<MatrixX> out) const {
  require_deviations_batch(controls, out, control_dimension(), key_point_count());
  twin_.deviations_batch(assembly, embedded(assembly, controls), out);
  thread_evaluations += static_cast<std::uint64_t>(controls.cols());
}

std::uint64_t CaseTwin::evaluations_on_this_thread() noexcept { return thread_evaluations; }

double median_quadratic_departure(const CaseTwin& twin, Index assemblies) {
  const std::vector<AssemblyId>& all = twin.assemblies();
  const Index count = std::min(assemblies, std::ssize(all));
  std::vector<double> departures;
  const std::uint64_t before = thread_evaluations;
  for (Index k = 0; k < count; ++k) {
    const AssemblyId& x = all[static_cast<std::size_t>(k)];
    departures.push_back(
        quadratic_departure(twin, x, twin.optimum(x), RandomStream(static_cast<std::uint64_t>(k))));
  }
  thread_evaluations = before;  // a property of the twin, not of any controller's step
  if (departures.empty()) return 0.0;
  std::sort(departures.begin(), departures.end());
  const std::size_t n = departures.size();
  return n % 2 == 1 ? departures[n / 2] : 0.5 * (departures[n / 2 - 1] + departures[n / 2]);
}

}  // namespace twincal
