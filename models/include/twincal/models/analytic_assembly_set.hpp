#pragma once
/// @file
/// `AnalyticAssemblySet`: the assemblies of the analytic twins, built like the paper's episodes
/// from `upper_parts` × `lower_parts` parts (10 × 10 = 100 assemblies by default), with seeded
/// per-part parameters.
///
/// Each part contributes additively to the assembly's two parameters, so parts interact the way
/// joined parts do (an assembly is not an independent draw):
///   q0(x) = q0_upper(i) + q0_lower(j)  > 0       (the irreducible defect, z*(x) = sqrt(q0(x)))
///   a(x)  = a_upper(i)  + a_lower(j)   ∈ R^d     (the optimal locator adjustment u0(x))
/// with q0 parts uniform in [q0_min/2, q0_max/2] and a-part entries uniform in
/// [−optimum_half_width/2, optimum_half_width/2].

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/models/assembly_id.hpp"

namespace twincal {

struct AnalyticAssemblyOptions {
  Index dimension = 3;                     ///< d, the number of locators
  Index upper_parts = 10;                  ///< number of upper parts
  Index lower_parts = 10;                  ///< number of lower parts
  double q0_min = 0.25;                    ///< smallest q0(x) = z*(x)²
  double q0_max = 1.0;                     ///< largest q0(x)
  double optimum_half_width = 0.2;         ///< |a_k(x)| ≤ this
  double bound = 1.0;                      ///< admissible controls: [−bound, bound]^d
  std::vector<std::string> locator_names;  ///< d names; empty gives "u1", …, "ud"

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::at_least("dimension", dimension, Index{1}),
         rule::at_least("upper_parts", upper_parts, Index{1}),
         rule::at_least("lower_parts", lower_parts, Index{1}),
         rule::positive_range("q0_min", q0_min, "q0_max", q0_max),
         rule::check_fields(
             optimum_half_width >= 0.0 && bound > optimum_half_width && std::isfinite(bound),
             "optimum_half_width and bound", std::array{optimum_half_width, bound},
             "0 <= optimum_half_width < bound < inf (every optimum is admissible)"),
         rule::check(locator_names.empty() || std::ssize(locator_names) == dimension,
                     "locator_names", fmt::join(locator_names, ", "),
                     "must be empty or hold dimension = {} names", dimension)});
  }
};

class AnalyticAssemblySet {
 public:
  /// Draws the per-part parameters from `stream` (substreams "q0" and "optimum").
  /// @throws InvalidArgumentError when the options are inconsistent.
  AnalyticAssemblySet(const AnalyticAssemblyOptions& options, const RandomStream& stream)
      : upper_parts_((require_valid("options", options), options.upper_parts)),
        lower_parts_(options.lower_parts),
        q0_(upper_parts_ * lower_parts_),
        optimum_(options.dimension, upper_parts_ * lower_parts_),
        lower_bounds_(VectorX::Constant(options.dimension, -options.bound)),
        upper_bounds_(VectorX::Constant(options.dimension, options.bound)),
        locator_names_(options.locator_names) {
    RandomStream q0_stream = stream.substream("q0");
    RandomStream optimum_stream = stream.substream("optimum");
    const auto draw = [](RandomStream& s, double low, double high) {
      return low + (high - low) * s.uniform();
    };
    const Index d = options.dimension;
    VectorX q0_upper(upper_parts_);
    VectorX q0_lower(lower_parts_);
    for (double& q : q0_upper) q = draw(q0_stream, 0.5 * options.q0_min, 0.5 * options.q0_max);
    for (double& q : q0_lower) q = draw(q0_stream, 0.5 * options.q0_min, 0.5 * options.q0_max);
    MatrixX a_upper(d, upper_parts_);
    MatrixX a_lower(d, lower_parts_);
    const double w = 0.5 * options.optimum_half_width;
    for (double& a : a_upper.reshaped()) a = draw(optimum_stream, -w, w);
    for (double& a : a_lower.reshaped()) a = draw(optimum_stream, -w, w);
    for (Index i = 0; i < upper_parts_; ++i) {
      for (Index j = 0; j < lower_parts_; ++j) {
        const Index k = index_of({i, j});
        q0_(k) = q0_upper(i) + q0_lower(j);
        optimum_.col(k) = a_upper.col(i) + a_lower.col(j);
      }
    }
    if (locator_names_.empty()) {
      for (Index k = 0; k < d; ++k) locator_names_.push_back(fmt::format("u{}", k + 1));
    }
  }

  [[nodiscard]] Index dimension() const noexcept { return optimum_.rows(); }
  [[nodiscard]] Index size() const noexcept { return q0_.size(); }
  [[nodiscard]] Index upper_parts() const noexcept { return upper_parts_; }
  [[nodiscard]] Index lower_parts() const noexcept { return lower_parts_; }

  /// Every assembly, upper part major: (0,0), (0,1), …, (U−1, L−1).
  [[nodiscard]] std::vector<AssemblyId> assemblies() const {
    std::vector<AssemblyId> all;
    all.reserve(static_cast<std::size_t>(size()));
    for (Index i = 0; i < upper_parts_; ++i) {
      for (Index j = 0; j < lower_parts_; ++j) all.push_back({i, j});
    }
    return all;
  }

  /// Position of `assembly` in assemblies().
  /// @throws InvalidArgumentError when a part index is out of range.
  [[nodiscard]] Index index_of(const AssemblyId& assembly) const {
    require_part("assembly.upper", assembly.upper, upper_parts_);
    require_part("assembly.lower", assembly.lower, lower_parts_);
    return assembly.upper * lower_parts_ + assembly.lower;
  }

  /// q0(x) > 0.
  [[nodiscard]] double q0(const AssemblyId& assembly) const { return q0_(index_of(assembly)); }

  /// a(x): the optimal control u0(x) of the analytic twins, as a view of the stored column.
  [[nodiscard]] MatrixX::ConstColXpr optimum(const AssemblyId& assembly) const {
    return optimum_.col(index_of(assembly));
  }

  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept {
    return locator_names_;
  }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return lower_bounds_; }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return upper_bounds_; }

 private:
  static void require_part(std::string_view name, Index index, Index count) {
    if (index >= 0 && index < count) return;
    throw InvalidArgumentError(
        std::string(name),
        fmt::format("{}: value is {}; rule: must lie in [0, {}]", name, index, count - 1));
  }

  Index upper_parts_;
  Index lower_parts_;
  VectorX q0_;
  MatrixX optimum_;  // d × (upper · lower)
  VectorX lower_bounds_;
  VectorX upper_bounds_;
  std::vector<std::string> locator_names_;
};

}  // namespace twincal
