// The controllers over a twin written in Python (python_twin.hpp): the baseline (Def. 2), the
// default controller (eq. 9), the paper's w-controller (eqs. 11–14) and the active controller,
// each instantiated once, at Dynamic size. propose() and observe() run without the GIL; the
// twin re-acquires it for each batch.
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "python_twin.hpp"
#include "twincal/controllers/active_controller.hpp"
#include "twincal/controllers/controller.hpp"
#include "twincal/controllers/individualized_controller.hpp"
#include "twincal/controllers/presets.hpp"
#include "twincal/core/random_stream.hpp"

namespace py = pybind11;

namespace twincal::python {
namespace {

using Baseline = IndividualizedController<PythonTwin>;
using Default = PaperDefaultController<PythonTwin>;
using Paper = PaperController<PythonTwin>;
using Active = ActiveController<PythonTwin>;

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
  return out;
}

PaperSettings paper_settings(double measurement_variance, double process_variance,
                             double initial_variance) {
  PaperSettings settings;
  settings.measurement_variance = measurement_variance;
  settings.process_variance = process_variance;
  settings.initial_variance = initial_variance;
  return settings;
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
           const PythonAssembly borrowed{assembly.ptr()};
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
            const PythonAssembly borrowed{assembly.ptr()};
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
  return cls;
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

  bind_controller<Default>(
      module, "DefaultController",
      "The default controller (eq. (9)): u_t = u0(x_t) + the UKF's offset estimate, with the "
      "paper's filter settings (Merwe points, Sigma_u = process_variance I, delta_u0 ~ N(0, "
      "initial_variance I)); seeded.")
      .def(py::init([](py::object twin, std::uint64_t seed, double measurement_variance,
                       double process_variance, double initial_variance) {
             const PaperSettings settings =
                 paper_settings(measurement_variance, process_variance, initial_variance);
             return make_object<Default>(std::move(twin), [&](const PythonTwin& t) {
               return Default(make_paper_filter(t, RandomStream(seed), settings));
             });
           }),
           py::arg("twin"), py::kw_only(), py::arg("seed") = 2023,
           py::arg("measurement_variance") = 1e-4, py::arg("process_variance") = 1e-3,
           py::arg("initial_variance") = 1e-3);

  bind_controller<Paper>(
      module, "PaperController",
      "The paper's w-controller (eqs. (11)-(14)): scrambled Sobol candidates from N(u0 + "
      "delta_u, P) in a box, each scored by L_w = (1 - w) E[Q] + w (1/d) sqrt(tr P+(u)); the "
      "twin evaluates candidates x sigma points in one batch per assembly. Seeded.")
      .def(py::init([](py::object twin, double w, std::uint64_t seed,
                       const std::optional<Index>& candidates, double box_half_width,
                       double measurement_variance, double process_variance,
                       double initial_variance) {
             LookaheadOptions options;
             options.w = w;
             options.candidates = candidates;
             options.box_half_width = box_half_width;
             const PaperSettings settings =
                 paper_settings(measurement_variance, process_variance, initial_variance);
             return make_object<Paper>(std::move(twin), [&](const PythonTwin& t) {
               return make_paper_controller(t, RandomStream(seed), options, settings);
             });
           }),
           py::arg("twin"), py::kw_only(), py::arg("w") = 0.5, py::arg("seed") = 2023,
           py::arg("candidates") = py::none(), py::arg("box_half_width") = 0.1,
           py::arg("measurement_variance") = 1e-4, py::arg("process_variance") = 1e-3,
           py::arg("initial_variance") = 1e-3,
           "candidates: per assembly, default the paper's 2^(2+d).");

  bind_controller<Active>(
      module, "ActiveController",
      "The active controller (docs/controllers.md, beyond the paper): known probes, the twin's "
      "local quadratic model and a moving-horizon estimate of a drifting offset; cost "
      "polynomial in d. Seeded.")
      .def(py::init([](py::object twin, std::uint64_t seed, double measurement_variance,
                       double initial_variance) {
             ActiveOptions options;
             options.measurement_variance = measurement_variance;
             options.initial_variance = initial_variance;
             return make_object<Active>(std::move(twin), [&](const PythonTwin& t) {
               return Active(t, RandomStream(seed), options);
             });
           }),
           py::arg("twin"), py::kw_only(), py::arg("seed") = 2023,
           py::arg("measurement_variance") = 1e-4, py::arg("initial_variance") = 1e-3);
}

}  // namespace twincal::python
