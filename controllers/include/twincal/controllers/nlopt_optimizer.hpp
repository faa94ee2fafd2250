#pragma once
/// @file
/// `NloptOptimizer`: a global derivative-free search (DIRECT-L by default) followed by a local
/// polish (BOBYQA by default) from the better of the global result and the start point, through
/// NLopt's C interface. The paper approximates u0(x) (eq. 3) "by a global optimizer that have run
/// an extensive number of iterations"; the budgets here make that explicit and reproducible.
///
/// Errors: an objective that throws stops the search and its exception reaches the caller
/// unchanged; a non-finite objective value stops it with NonFiniteError naming the control.

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <nlopt.h>
#include <Eigen/Core>

#include "twincal/controllers/optimizer.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/format.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

struct NloptOptimizerOptions {
  nlopt_algorithm global_algorithm = NLOPT_GN_DIRECT_L;  ///< must be a GN_ algorithm
  std::uint64_t global_evaluations = 2000;            ///< budget of the global phase (0 skips it)
  nlopt_algorithm local_algorithm = NLOPT_LN_BOBYQA;  ///< must be an LN_ algorithm
  std::uint64_t local_evaluations = 1000;             ///< budget of the local phase (0 skips it)
  double x_tolerance = 1e-10;  ///< local phase stops when a step changes u by less (relative)
  double f_tolerance = 0.0;    ///< and/or when f changes by less (absolute; 0 = off)

  [[nodiscard]] std::optional<std::string> validate() const {
    const std::string_view global = nlopt_algorithm_to_string(global_algorithm);
    const std::string_view local = nlopt_algorithm_to_string(local_algorithm);
    return first_problem(
        {rule::check(global.starts_with("GN_"), "global_algorithm", global,
                     "must be a derivative-free global (GN_) one"),
         rule::check(local.starts_with("LN_"), "local_algorithm", local,
                     "must be a derivative-free local (LN_) one"),
         rule::check_fields(global_evaluations > 0 || local_evaluations > 0,
                            "global_evaluations and local_evaluations",
                            std::array{global_evaluations, local_evaluations},
                            "at least one phase must run"),
         rule::check(x_tolerance >= 0.0, "x_tolerance", x_tolerance, "must be >= 0"),
         rule::check(f_tolerance >= 0.0, "f_tolerance", f_tolerance, "must be >= 0")});
  }
};

class NloptOptimizer {
 public:
  explicit NloptOptimizer(NloptOptimizerOptions options = {}) : options_(options) {
    require_valid("NloptOptimizerOptions", options_);
  }

  [[nodiscard]] const NloptOptimizerOptions& options() const noexcept { return options_; }

  /// @throws DimensionMismatchError / NonFiniteError / InvalidArgumentError for inconsistent
  ///         start and bounds (lower > upper, start outside), NonFiniteError for a non-finite f,
  ///         and whatever f throws.
  [[nodiscard]] OptimizationResult minimize(const Objective& objective, const VectorX& start,
                                            const VectorX& lower, const VectorX& upper) const {
    require_search_box(start, lower, upper);
    Search search{objective, nullptr, 0, {}, start, std::numeric_limits<double>::infinity()};
    OptimizationResult result;
    VectorX x = start;
    if (options_.global_evaluations > 0) {
      run_phase(search, options_.global_algorithm, options_.global_evaluations, x, lower, upper,
                result.summary);
    }
    if (options_.local_evaluations > 0) {
      x = search.best_x;  // the better of the start and the global result
      run_phase(search, options_.local_algorithm, options_.local_evaluations, x, lower, upper,
                result.summary);
    }
    result.argmin = search.best_x;
    result.minimum = search.best_f;
    result.evaluations = search.evaluations;
    return result;
  }

 private:
  struct Search {
    const Objective& objective;
    nlopt_opt running;  // the phase in progress, so a failing evaluation can stop it
    std::uint64_t evaluations;
    std::exception_ptr error;
    VectorX best_x;
    double best_f;
  };

  static double evaluate(unsigned n, const double* x, double* /*gradient*/, void* data) {
    auto& search = *static_cast<Search*>(data);
    try {
      const Eigen::Map<const VectorX> u(x, static_cast<Index>(n));
      const double f = search.objective(u);
      ++search.evaluations;
      if (!std::isfinite(f)) {
        throw NonFiniteError("objective", fmt::format("objective: value at u = {} is {}; rule: "
                                                      "must be finite",
                                                      u, f));
      }
      if (f < search.best_f) {
        search.best_f = f;
        search.best_x = u;
      }
      return f;
    } catch (...) {
      search.error = std::current_exception();
      nlopt_force_stop(search.running);
      return std::numeric_limits<double>::quiet_NaN();
    }
  }

  void run_phase(Search& search, nlopt_algorithm algorithm, std::uint64_t budget, VectorX& x,
                 const VectorX& lower, const VectorX& upper, std::string& summary) const {
    const auto n = static_cast<unsigned>(x.size());
    const std::unique_ptr<nlopt_opt_s, decltype(&nlopt_destroy)> opt(nlopt_create(algorithm, n),
                                                                     &nlopt_destroy);
    if (!opt) throw std::bad_alloc();
    nlopt_set_lower_bounds(opt.get(), lower.data());
    nlopt_set_upper_bounds(opt.get(), upper.data());
    nlopt_set_min_objective(opt.get(), &NloptOptimizer::evaluate, &search);
    nlopt_set_maxeval(opt.get(), static_cast<int>(std::min<std::uint64_t>(budget, INT_MAX)));
    nlopt_set_xtol_rel(opt.get(), options_.x_tolerance);
    nlopt_set_ftol_abs(opt.get(), options_.f_tolerance);
    search.running = opt.get();
    const std::uint64_t before = search.evaluations;
    double f = std::numeric_limits<double>::quiet_NaN();
    const nlopt_result code = nlopt_optimize(opt.get(), x.data(), &f);
    if (search.error) std::rethrow_exception(search.error);
    if (code < 0 && code != NLOPT_ROUNDOFF_LIMITED) {
      throw InvalidArgumentError("NloptOptimizer",
                                 fmt::format("NloptOptimizer: {} failed with NLopt code {} ({})",
                                             nlopt_algorithm_to_string(algorithm),
                                             static_cast<int>(code), nlopt_result_to_string(code)));
    }
    if (!summary.empty()) summary += '\n';
    summary +=
        fmt::format("{}: {} evaluations, best {:.10g} ({})", nlopt_algorithm_to_string(algorithm),
                    search.evaluations - before, search.best_f, nlopt_result_to_string(code));
  }

  NloptOptimizerOptions options_;
};

}  // namespace twincal
