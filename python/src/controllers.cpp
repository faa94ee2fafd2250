// The controllers over a twin written in Python or a twincal.Twin (python_twin.hpp): the
// baseline (Def. 2), the default controller (eq. 9), the w-controller (eqs. 11–14) with every
// candidate sampler and exploration loss (chosen at run time, as `twincal run` does), the
// per-component w-controllers (Sec. 4) and the active controller, each instantiated once, at
// Dynamic size. propose() and observe() run without the GIL; a Python twin re-acquires it for
// each batch.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "python_twin.hpp"
#include "twincal/controllers/active_controller.hpp"
#include "twincal/controllers/any_exploration_loss.hpp"
#include "twincal/controllers/controller.hpp"
#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/controllers/exploration_kind.hpp"
#include "twincal/controllers/individualized_controller.hpp"
#include "twincal/controllers/presets.hpp"
#include "twincal/controllers/sensitivity_weights.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/experiments/active_options_json.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/samplers/any_sampler.hpp"
#include "twincal/samplers/candidate_sampler.hpp"

namespace py = pybind11;

namespace twincal::python {
namespace {

/// The seed a controller takes when none is given: the CLI's (ExperimentConfig::seed).
const std::uint64_t default_seed = ExperimentConfig{}.seed;

using Baseline = IndividualizedController<PythonTwin>;
using Default = PaperDefaultController<PythonTwin>;
// The paper's filter, the sampler and the exploration loss chosen at run time.
using Lookahead =
    LookaheadController<PaperFilter<PythonTwin>, AnySampler, ExpectedQuality, AnyExplorationLoss>;
using PerComponent = PerComponentPaperController<PythonTwin>;
using Active = ActiveController<PythonTwin>;

// A Python value as JSON, through the json module: what json.dumps takes (without NaN) is what
// is taken here, and its TypeError or ValueError reaches the caller unchanged.
nlohmann::json json_of(const py::object& value) {
  const py::object dumps = py::module_::import("json").attr("dumps");
  return nlohmann::json::parse(dumps(value, py::arg("allow_nan") = false).cast<std::string>());
}

/// The Python object: the controller and the twin it refers to (kept at a fixed address).
template <typename C>
struct ControllerObject {
  std::unique_ptr<PythonTwin> twin;
  std::unique_ptr<C> controller;
};

template <typename C, typename Make>
ControllerObject<C> make_object(py::object twin, Make&& make) {
  ControllerObject<C> out;
  out.twin = std::make_unique<PythonTwin>(std::move(twin));
  out.controller = std::make_unique<C>(make(*out.twin));
  return out;
}

py::dict report_dict(const ProposalReport& r) {
  py::dict out;
  out["individual_control"] = r.individual_control;
  out["optimal_quality"] = r.optimal_quality;
  out["default_control"] = r.default_control;
  out["control"] = r.control;
  out["candidates_requested"] = r.candidates_requested;
  out["candidates_scored"] = r.candidates_scored;
  out["chosen"] = r.chosen;
  out["exploitation"] = r.exploitation;
  out["exploration"] = r.exploration;
  out["loss"] = r.loss;
  out["quality_evaluations"] = r.quality_evaluations;
  out["fallback"] = r.fallback;
  out["dropped_measurement"] = r.dropped_measurement;
  return out;
}

// A step report (AnyController::step_report()'s JSON) as a dict: booleans and counts as
// themselves, numbers decoded as the report wrote them (json_state::read_double: null is NaN,
// "inf" / "-inf" are ±∞).
py::dict step_dict(const nlohmann::json& report) {
  py::dict out;
  for (const auto& item : report.items()) {
    const nlohmann::json& value = item.value();
    const char* key = item.key().c_str();
    if (value.is_boolean()) {
      out[key] = value.get<bool>();
    } else if (value.is_number_integer()) {
      out[key] = value.get<std::int64_t>();
    } else {
      out[key] = json_state::read_double(value, item.key(), json_state::Values::any);
    }
  }
  return out;
}

PaperSettings paper_settings(double measurement_variance, double process_variance,
                             double initial_variance) {
  return {.process_variance = process_variance,
          .measurement_variance = measurement_variance,
          .initial_variance = initial_variance};
}

LookaheadOptions lookahead_options(double w, const std::optional<Index>& candidates,
                                   double box_half_width) {
  return {.w = w, .box_half_width = box_half_width, .candidates = candidates};
}

// The exploration loss `kind`; the weighted trace's W is `weights`, or the twin's sensitivity
// (sensitivity_weights.hpp) over its `assemblies` attribute. Called with the GIL held.
AnyExplorationLoss exploration_loss(const std::string& kind, const std::optional<VectorX>& weights,
                                    const PythonTwin& twin) {
  return make_exploration_loss(parse_enum<ExplorationKind>(kind, "exploration"), [&]() -> VectorX {
    if (weights) {
      require_dimension("weights", weights->size(), twin.control_dimension());
      return *weights;
    }
    const py::object object = twin.object();
    if (!py::hasattr(object, "assemblies")) {
      throw InvalidArgumentError("weights",
                                 "weights: missing; rule: exploration='weighted_trace' needs "
                                 "weights (d values >= 0) or a twin with an `assemblies` list "
                                 "to infer them from");
    }
    const py::list listed(object.attr("assemblies"));  // held while the twin is evaluated
    std::vector<PythonAssembly> assemblies;
    for (const py::handle assembly : listed) assemblies.push_back(twin.borrow(assembly));
    py::gil_scoped_release release;
    return sensitivity_weights(IndividualOptimum<PythonTwin>(twin), assemblies);
  });
}

// propose, observe, twin, and what the controller can tell about its last step and its belief.
template <typename C>
py::class_<ControllerObject<C>> bind_controller(py::module_& module, const char* name,
                                                const char* doc) {
  using Object = ControllerObject<C>;
  py::class_<Object> cls(module, name, doc);
  cls.def(
         "propose",
         [](Object& o, const py::object& assembly) {
           const PythonAssembly borrowed = o.twin->borrow(assembly);
           py::gil_scoped_release release;
           VectorX control = o.controller->propose(borrowed);
           return control;
         },
         py::arg("assembly"),
         "The control u_t to apply to `assembly` (d values, eq. (5a)). The twin is called in "
         "batches; its exceptions propagate as themselves.")
      .def(
          "observe",
          [](Object& o, const py::object& assembly, const VectorX& control, double z) {
            const PythonAssembly borrowed = o.twin->borrow(assembly);
            py::gil_scoped_release release;
            o.controller->observe(borrowed, control, z);
          },
          py::arg("assembly"), py::arg("control"), py::arg("z"),
          "Hands back the quality z the plant measured at `control` (the filter's update). A "
          "non-finite z raises NonFiniteError with the controller unchanged.")
      .def_property_readonly(
          "twin", [](const Object& o) { return o.twin->object(); }, "The twin.");
  if constexpr (EstimatingController<C>) {
    cls.def_property_readonly(
           "offset_estimate",
           [](const Object& o) { return VectorX(o.controller->offset_estimate()); },
           "The estimate of the plant's locator offset (eq. (8)'s mean).")
        .def_property_readonly(
            "offset_covariance", [](const Object& o) { return o.controller->offset_covariance(); },
            "Its covariance P (eq. (8)).");
  }
  if constexpr (requires(const C& c) { c.last_proposal(); }) {
    cls.def_property_readonly(
        "last_proposal", [](const Object& o) { return report_dict(o.controller->last_proposal()); },
        "What the last propose() did: u0, z*, the default control, the candidates, the chosen "
        "one's losses, the Q-evaluations, and why it fell back, if it did.");
  }
  if constexpr (requires(const C& c) { active_step_report_to_json(c.last_step()); }) {
    cls.def_property_readonly(
        "last_step",
        [](const Object& o) {
          return step_dict(active_step_report_to_json(o.controller->last_step()));
        },
        "What the last step did beyond last_proposal (ActiveStepReport, docs/controllers.md): "
        "the model's error and tau^2, the probe, the change gate's reading (change_ratio > 1: a "
        "change of velocity declared), the misfit and prediction scales, whether the control "
        "was corrected and audited; NaN where the estimator did not run.");
  }
  return cls;
}

// Defines `init`, a constructor over the paper's filter, on `cls`: its own arguments `args`,
// then the filter's settings as keywords with PaperSettings' defaults (init's last parameters).
template <typename C, typename Init, typename... Args>
void def_paper_init(py::class_<ControllerObject<C>> cls, Init&& init, const Args&... args) {
  cls.def(std::forward<Init>(init), args...,
          py::arg("measurement_variance") = PaperSettings{}.measurement_variance,
          py::arg("process_variance") = PaperSettings{}.process_variance,
          py::arg("initial_variance") = PaperSettings{}.initial_variance);
}

// def_paper_init for a w-controller: twin, then the keywords w, seed, candidates and
// box_half_width with LookaheadOptions' defaults, then `args`.
template <typename C, typename Init, typename... Args>
void def_lookahead_init(py::class_<ControllerObject<C>> cls, Init&& init, const Args&... args) {
  def_paper_init(std::move(cls), std::forward<Init>(init), py::arg("twin"), py::kw_only(),
                 py::arg("w") = LookaheadOptions{}.w, py::arg("seed") = default_seed,
                 py::arg("candidates") = py::none(),
                 py::arg("box_half_width") = LookaheadOptions{}.box_half_width, args...);
}

}  // namespace

void bind_controllers(py::module_& module) {
  bind_controller<Baseline>(
      module, "IndividualizedController",
      "The paper's baseline (Def. 2): u_t = u0(x_t) = twin.optimum(x_t), no calibration.")
      .def(py::init([](py::object twin) {
             return make_object<Baseline>(std::move(twin),
                                          [](const PythonTwin& t) { return Baseline(t); });
           }),
           py::arg("twin"));

  def_paper_init(
      bind_controller<Default>(
          module, "DefaultController",
          "The default controller (eq. (9)): u_t = u0(x_t) + the UKF's offset estimate, with the "
          "paper's filter settings (Merwe points, Sigma_u = process_variance I, delta_u0 ~ N(0, "
          "initial_variance I)); seeded."),
      py::init([](py::object twin, std::uint64_t seed, double measurement_variance,
                  double process_variance, double initial_variance) {
        const PaperSettings settings =
            paper_settings(measurement_variance, process_variance, initial_variance);
        return make_object<Default>(std::move(twin), [&](const PythonTwin& t) {
          return Default(make_paper_filter(t, RandomStream(seed), settings));
        });
      }),
      py::arg("twin"), py::kw_only(), py::arg("seed") = default_seed);

  def_lookahead_init(
      bind_controller<Lookahead>(
          module, "PaperController",
          "The paper's w-controller (eqs. (11)-(14)): candidates from N(u0 + delta_u, P) in a box, "
          "each scored by L_w = (1 - w) E[Q] + w L_explore(P+(u)); the twin evaluates candidates x "
          "sigma points in one batch per assembly. The paper's: sampler='sobol' (scrambled, "
          "QMCPy's default) and exploration='trace' ((1/d) sqrt(tr P+)); the ablations: sampler "
          "'halton', 'random' or 'latin_hypercube', exploration 'weighted_trace' (Sec. 4; W = "
          "`weights`, or inferred from the twin's curvature over its `assemblies`), 'log_det' or "
          "'max_eigenvalue'. Seeded."),
      py::init([](py::object twin, double w, std::uint64_t seed,
                  const std::optional<Index>& candidates, double box_half_width,
                  const std::string& sampler, const std::string& exploration,
                  const std::optional<VectorX>& weights, double measurement_variance,
                  double process_variance, double initial_variance) {
        const LookaheadOptions options = lookahead_options(w, candidates, box_half_width);
        const CandidateSampler sampler_kind = parse_enum<CandidateSampler>(sampler, "sampler");
        const PaperSettings settings =
            paper_settings(measurement_variance, process_variance, initial_variance);
        return make_object<Lookahead>(std::move(twin), [&](const PythonTwin& t) {
          const RandomStream stream(seed);
          return Lookahead(make_paper_filter(t, stream, settings),
                           AnySampler(sampler_kind, t.control_dimension(),
                                      stream.substream("candidates").seed()),
                           options, ExpectedQuality{}, exploration_loss(exploration, weights, t));
        });
      }),
      py::arg("sampler") = "sobol", py::arg("exploration") = "trace",
      py::arg("weights") = py::none(), "candidates: per assembly, default the paper's 2^(2+d).");

  def_lookahead_init(
      bind_controller<PerComponent>(
          module, "PerComponentController",
          "The per-component simplification the paper proposes for many locators (Sec. 4): d "
          "one-locator w-controllers (the paper's, with Sobol candidates and the trace loss), all "
          "updated with the shared quality; candidates per component default to 2^3. Component i "
          "is seeded from `seed` and i."),
      py::init([](py::object twin, double w, std::uint64_t seed,
                  const std::optional<Index>& candidates, double box_half_width,
                  double measurement_variance, double process_variance, double initial_variance) {
        const LookaheadOptions options = lookahead_options(w, candidates, box_half_width);
        const PaperSettings settings =
            paper_settings(measurement_variance, process_variance, initial_variance);
        return make_object<PerComponent>(std::move(twin), [&](const PythonTwin& t) {
          return make_per_component_paper_controller(t, RandomStream(seed), options, settings);
        });
      }));

  bind_controller<Active>(
      module, "ActiveController",
      "The active controller (docs/controllers.md, beyond the paper): known probes, the twin's "
      "local quadratic model and a moving-horizon estimate of a drifting offset; cost "
      "polynomial in d. Seeded. `options`: a dict of the settings to change from their defaults, "
      "by their C++ names, the estimator's under 'trajectory' and the local model's under "
      "'surrogate' (docs/cli.md, the config's `active`), e.g. {'regret_probe': 0.2, "
      "'trajectory': {'velocity_fraction': 0.02}}; an unknown key or a value that breaks a rule "
      "raises InvalidArgumentError naming it.")
      .def(py::init([](py::object twin, std::uint64_t seed, double measurement_variance,
                       double initial_variance, const py::object& options) {
             ActiveOptions settings;
             settings.measurement_variance = measurement_variance;
             settings.initial_variance = initial_variance;
             if (!options.is_none()) {
               apply_active_overrides(json_of(options), settings, "options");
               if (std::optional<std::string> problem = settings.validate()) {
                 throw InvalidArgumentError("options", "options." + *problem);
               }
             }
             return make_object<Active>(std::move(twin), [&](const PythonTwin& t) {
               return Active(t, RandomStream(seed), settings);
             });
           }),
           py::arg("twin"), py::kw_only(), py::arg("seed") = default_seed,
           py::arg("measurement_variance") = ActiveOptions{}.measurement_variance,
           py::arg("initial_variance") = ActiveOptions{}.initial_variance,
           py::arg("options") = py::none());
}

}  // namespace twincal::python
