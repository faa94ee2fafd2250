// twincal.BudgetedOptimum: u0(x) = argmin_u Q(x, u) (eq. 3) of a twin written in Python,
// searched within a budget of twin calls by controllers' LeastSquaresSearch (on the key points'
// deviations) or TrustRegionSearch (on Q), both asking for their controls in batches — where a
// twin without `optimum` otherwise gets NLopt's 2000 + 1000 calls, one control per call.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "python_twin.hpp"
#include "twincal/controllers/least_squares_search.hpp"
#include "twincal/controllers/trust_region_search.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/experiments/external_twin_settings.hpp"

namespace py = pybind11;

namespace twincal::python {
namespace {

/// The search's settings, as the keywords of BudgetedOptimum spell them (resolved: a method
/// and a budget chosen for the twin when not given).
struct BudgetedOptimumSettings {
  /// "least_squares" (the deviations; the default for a twin that answers them),
  /// "least_squares_speculative" (the same, each start and step asked for with its Jacobian's
  /// stencil: LeastSquaresSearchOptions::speculative_jacobian) or "trust_region" (Q; the default
  /// otherwise).
  std::string method;
  /// Twin evaluations per search; 2 (d + 1)² unless given, the budget docs/external.md
  /// recommends for the CLI's budgeted search.
  Index budget = 0;
  /// The least-squares restarts draw from RandomStream(seed): the CLI's optimum_seed.
  std::uint64_t seed = ExternalTwinSettings{}.optimum_seed;
  Index key_points = 0;  // of the twin: least squares needs them

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::check(least_squares_method(method) || method == "trust_region", "method", method,
                     "must be least_squares, least_squares_speculative or trust_region"),
         rule::check(!least_squares_method(method) || key_points >= 1, "method", method,
                     "least_squares needs a twin that answers its deviations (deviations_batch "
                     "and key_point_count)"),
         rule::at_least("budget", budget, Index{1})});
  }
};

/// What one search found and spent.
struct SearchOutcome {
  VectorX control;
  double quality = 0.0;
  std::uint64_t evaluations = 0;
  Index requests = 0;
  std::string status;  // "converged" or "budget_spent"
};

class BudgetedOptimum {
 public:
  /// @throws InvalidArgumentError naming the keyword whose rule is broken (or the twin's
  ///         malformed attribute, as PythonTwin does).
  BudgetedOptimum(py::object twin, std::optional<std::string> method, std::optional<Index> budget,
                  std::uint64_t seed)
      : twin_(std::make_unique<PythonTwin>(std::move(twin))) {
    const Index d = twin_->control_dimension();
    settings_.key_points = twin_->key_point_count();
    settings_.method = method.value_or(settings_.key_points > 0 ? "least_squares" : "trust_region");
    settings_.budget = budget.value_or(2 * (d + 1) * (d + 1));
    settings_.seed = seed;
    require_valid("BudgetedOptimum", settings_);
  }

  [[nodiscard]] const BudgetedOptimumSettings& settings() const noexcept { return settings_; }
  [[nodiscard]] const PythonTwin& twin() const noexcept { return *twin_; }
  [[nodiscard]] std::uint64_t evaluations() const noexcept { return evaluations_; }
  [[nodiscard]] std::uint64_t requests() const noexcept { return requests_; }
  [[nodiscard]] std::uint64_t searches() const noexcept { return searches_; }

  /// A search from `start` (the centre of the bounds unless given), counted; with the GIL held.
  /// @throws DimensionMismatchError, NonFiniteError, InvalidArgumentError for a bad start; the
  ///         twin's errors (a Python exception as itself).
  SearchOutcome search(py::handle assembly, const std::optional<VectorX>& start) {
    const VectorX from = start.value_or(0.5 * (twin_->lower_bounds() + twin_->upper_bounds()));
    if (start) require_dimension("start", from.size(), twin_->control_dimension());
    const PythonAssembly borrowed = twin_->borrow(assembly);
    SearchOutcome found;
    {
      py::gil_scoped_release release;
      found = run(borrowed, from);
    }
    evaluations_ += found.evaluations;
    requests_ += static_cast<std::uint64_t>(found.requests);
    ++searches_;
    return found;
  }

  /// The last search of `assembly` (the same object), or a new one from the centre: a
  /// controller asks for u0 and then z* of each assembly, which one search answers.
  const SearchOutcome& searched(py::handle assembly) {
    if (!last_assembly_ || !last_assembly_->is(assembly)) {
      SearchOutcome found = search(assembly, std::nullopt);
      last_ = std::move(found);
      last_assembly_ = py::reinterpret_borrow<py::object>(assembly);
    }
    return last_;
  }

  [[nodiscard]] const std::optional<py::object>& last_assembly() const noexcept {
    return last_assembly_;
  }
  [[nodiscard]] const SearchOutcome& last() const noexcept { return last_; }

 private:
  // Runs `method` (least squares or trust_region) from `start`; the GIL released.
  [[nodiscard]] SearchOutcome run(const PythonAssembly& assembly, const VectorX& start) const {
    const auto budget = static_cast<std::uint64_t>(settings_.budget);
    const VectorX& lower = twin_->lower_bounds();
    const VectorX& upper = twin_->upper_bounds();
    const auto outcome = [](const auto& found) {
      return SearchOutcome{found.argmin, found.minimum, found.evaluations, found.batches,
                           std::string(to_string(found.status))};
    };
    if (least_squares_method(settings_.method)) {
      const DeviationObjective deviations = [&](const Eigen::Ref<const MatrixX>& controls,
                                                Eigen::Ref<MatrixX> out) {
        twin_->deviations_batch(assembly, controls, out);
      };
      return outcome(LeastSquaresSearch(least_squares_options(settings_.method, budget))
                         .minimize(deviations, settings_.key_points, start, lower, upper,
                                   RandomStream(settings_.seed)));
    }
    const BatchObjective qualities = [&](const Eigen::Ref<const MatrixX>& controls,
                                         Eigen::Ref<VectorX> out) {
      twin_->quality_batch(assembly, controls, out);
    };
    return outcome(
        TrustRegionSearch({.evaluations = budget}).minimize(qualities, start, lower, upper));
  }

  std::unique_ptr<PythonTwin> twin_;  // at a fixed address: a borrowed assembly refers to it
  BudgetedOptimumSettings settings_;
  std::optional<py::object> last_assembly_;  // held, so that its identity cannot be reused
  SearchOutcome last_;
  std::uint64_t evaluations_ = 0;
  std::uint64_t requests_ = 0;
  std::uint64_t searches_ = 0;
};

py::dict outcome_dict(const SearchOutcome& found) {
  py::dict out;
  out["control"] = found.control;
  out["quality"] = found.quality;
  out["evaluations"] = found.evaluations;
  out["requests"] = found.requests;
  out["status"] = found.status;
  return out;
}

}  // namespace

void bind_optimum(py::module_& module) {
  py::class_<BudgetedOptimum>(
      module, "BudgetedOptimum",
      "A twin whose u0(x) = argmin_u Q(x, u) (eq. (3)) is searched within `budget` twin "
      "evaluations per assembly, the controls asked for in batches: `method` 'least_squares' "
      "(Levenberg-Marquardt on the key points' deviations, restarts while the budget lasts; the "
      "default for a twin with deviations_batch and key_point_count) or 'trust_region' (a "
      "model of Q^2 fitted by least squares, d + 1 controls per request; the default "
      "otherwise). `budget` defaults to 2 (d + 1)^2; the least-squares restarts draw from "
      "the seed `seed`, so a search depends only on the twin, the assembly, its start and the "
      "seed. Every search starts from the centre of the bounds. Every other attribute "
      "(quality_batch, deviations_batch, the bounds, assemblies, ...) is the twin's own, so a "
      "controller given it searches u0 this way instead of by NLopt's 2000 + 1000 calls. "
      "Raises InvalidArgumentError naming the keyword whose rule is broken.")
      .def(py::init([](py::object twin, std::optional<std::string> method,
                       std::optional<Index> budget, std::uint64_t seed) {
             return std::make_unique<BudgetedOptimum>(std::move(twin), std::move(method), budget,
                                                      seed);
           }),
           py::arg("twin"), py::kw_only(), py::arg("method") = py::none(),
           py::arg("budget") = py::none(), py::arg("seed") = BudgetedOptimumSettings{}.seed)
      .def(
          "optimum",
          [](BudgetedOptimum& self, py::handle assembly) {
            return self.searched(assembly).control;
          },
          py::arg("assembly"),
          "u0(x): the best control the search evaluated (searched once for the same assembly "
          "object in a row).")
      .def(
          "optimal_quality",
          [](BudgetedOptimum& self, py::handle assembly) {
            return self.searched(assembly).quality;
          },
          py::arg("assembly"), "z*(x) = Q(x, u0(x)), from the same search as optimum.")
      .def(
          "search",
          [](BudgetedOptimum& self, py::handle assembly, std::optional<VectorX> start) {
            return outcome_dict(self.search(assembly, start));
          },
          py::arg("assembly"), py::kw_only(), py::arg("start") = py::none(),
          "A new search for `assembly` from `start` (d values in the bounds; the centre by "
          "default): a dict of control, quality, evaluations, requests (calls of the twin) and "
          "status ('converged' or 'budget_spent').")
      .def_property_readonly(
          "last_search",
          [](const BudgetedOptimum& self) -> py::object {
            if (!self.last_assembly()) return py::none();
            return outcome_dict(self.last());
          },
          "What the search behind the last optimum or optimal_quality found and spent (a dict "
          "as search() returns), or None before the first.")
      .def_property_readonly(
          "method", [](const BudgetedOptimum& self) { return self.settings().method; },
          "'least_squares' or 'trust_region'.")
      .def_property_readonly(
          "budget", [](const BudgetedOptimum& self) { return self.settings().budget; },
          "Twin evaluations per search.")
      .def_property_readonly(
          "seed", [](const BudgetedOptimum& self) { return self.settings().seed; },
          "The seed of the least-squares restarts.")
      .def_property_readonly("evaluations", &BudgetedOptimum::evaluations,
                             "Twin evaluations (controls) over every search so far.")
      .def_property_readonly("requests", &BudgetedOptimum::requests,
                             "Calls of the twin (batches) over every search so far.")
      .def_property_readonly("searches", &BudgetedOptimum::searches, "Searches so far.")
      .def_property_readonly(
          "twin", [](const BudgetedOptimum& self) { return self.twin().object(); },
          "The twin searched.")
      .def(
          "__getattr__",
          [](const BudgetedOptimum& self, const std::string& name) {
            return self.twin().object().attr(name.c_str());
          },
          py::arg("name"), "The twin's own attribute `name`.")
      .def("__repr__", [](const BudgetedOptimum& self) {
        return fmt::format("twincal.BudgetedOptimum({}, method={}, budget={}, seed={})",
                           py::repr(self.twin().object()).cast<std::string>(),
                           self.settings().method, self.settings().budget, self.settings().seed);
      });
}

}  // namespace twincal::python
