// twincal.Twin: the twins compiled into twincal (native_twin.hpp), callable from Python with the
// protocol of a Python twin, so that the same object serves filterpy code, a Python twin's
// delegate and twincal's controllers.
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "native_twin.hpp"
#include "twincal/core/error.hpp"
#include "twincal/experiments/experiment_choices.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/experiments/twin_cases.hpp"

namespace py = pybind11;

namespace twincal::python {

AssemblyId NativeTwin::assembly(py::handle assembly) const {
  const std::vector<AssemblyId>& all = twin->assemblies();
  if (py::isinstance<py::int_>(assembly)) {
    const auto index = assembly.cast<Index>();
    if (index >= 0 && index < std::ssize(all)) return all[static_cast<std::size_t>(index)];
  } else if (py::isinstance<py::sequence>(assembly) && !py::isinstance<py::str>(assembly) &&
             py::len(assembly) == 2) {
    const auto pair = py::reinterpret_borrow<py::sequence>(assembly);
    if (py::isinstance<py::int_>(pair[0]) && py::isinstance<py::int_>(pair[1])) {
      const AssemblyId id{pair[0].cast<Index>(), pair[1].cast<Index>()};
      for (const AssemblyId& known : all) {
        if (known == id) return id;
      }
    }
  }
  throw InvalidArgumentError(
      "assembly", fmt::format("assembly: value is {}; rule: an (upper, lower) pair of the "
                              "twin's assemblies or an index in [0, {})",
                              py::repr(assembly).cast<std::string>(), all.size()));
}

namespace {

NativeTwin make_native_twin(const std::string& twin_case, const std::string& locators,
                            Index dimension, std::uint64_t seed) {
  ExperimentConfig config;
  config.twin_case = parse_enum<TwinCase>(twin_case, "case");
  config.locators = locators;
  config.analytic_dimension = dimension;
  config.twin_seed = seed;
  if (auto problem = config.validate()) throw InvalidArgumentError("Twin", *problem);
  py::gil_scoped_release release;  // an FEM twin takes a moment to assemble
  return NativeTwin{std::make_shared<const CaseTwin>(make_case_twin(config))};
}

// `evaluate(id, out)` for the assembly `assembly` spells, without the GIL (the twin is
// compiled), returning `out`.
template <typename Out, typename Evaluate>
Out evaluate_released(const NativeTwin& t, const py::handle& assembly, Out out,
                      const Evaluate& evaluate) {
  const AssemblyId id = t.assembly(assembly);
  py::gil_scoped_release release;
  evaluate(id, out);
  return out;
}

}  // namespace

void bind_twins(py::module_& module) {
  py::class_<NativeTwin>(
      module, "Twin",
      "A twin compiled into twincal: case 'body' or 'door' (the open FEM sheet-metal twin of "
      "the paper's car body, 12 locators, and car door, 19) or 'analytic' (an RMS-quadratic "
      "twin of `dimension` locators A, B, C, ...), restricted to `locators` ('A', 'B', 'C', "
      "'ABC' for the three significant ones, 'all', or names or indices joined by commas) with "
      "the others held at u0(x), as `twincal run` does. `seed` is the twin seed. It has a Python "
      "twin's methods, and a controller given it calls it without Python in the loop. An "
      "assembly is an (upper, lower) pair or an index into `assemblies`.")
      .def(py::init(&make_native_twin), py::arg("case"), py::kw_only(), py::arg("locators") = "all",
           py::arg("dimension") = ExperimentConfig{}.analytic_dimension,
           py::arg("seed") = ExperimentConfig{}.twin_seed)
      .def_property_readonly(
          "control_dimension", [](const NativeTwin& t) { return t.twin->control_dimension(); },
          "d: the number of controlled locators.")
      .def_property_readonly(
          "locator_names", [](const NativeTwin& t) { return t.twin->locator_names(); },
          "The controlled locators' names.")
      .def_property_readonly(
          "lower_bounds", [](const NativeTwin& t) { return t.twin->lower_bounds(); },
          "The controlled locators' lower bounds (d values).")
      .def_property_readonly(
          "upper_bounds", [](const NativeTwin& t) { return t.twin->upper_bounds(); },
          "The controlled locators' upper bounds (d values).")
      .def_property_readonly(
          "assemblies",
          [](const NativeTwin& t) {
            py::list out;
            for (const AssemblyId& a : t.twin->assemblies())
              out.append(py::make_tuple(a.upper, a.lower));
            return out;
          },
          "Every assembly, as (upper, lower) part indices, in the twin's order.")
      .def(
          "quality_batch",
          [](const NativeTwin& t, const py::handle& assembly,
             const Eigen::Ref<const MatrixX>& controls) {
            return evaluate_released(t, assembly, VectorX(controls.cols()),
                                     [&](const AssemblyId& id, VectorX& out) {
                                       t.twin->quality_batch(id, controls, out);
                                     });
          },
          py::arg("assembly"), py::arg("controls"),
          "Q(x, u) for every column u of `controls` (d x k): k qualities, one batch.")
      .def_property_readonly(
          "key_point_count", [](const NativeTwin& t) { return t.twin->key_point_count(); },
          "m: the key points whose deviations deviations_batch answers (the FEM twins); 0 for "
          "a twin that answers only Q (the analytic one).")
      .def(
          "deviations_batch",
          [](const NativeTwin& t, const py::handle& assembly,
             const Eigen::Ref<const MatrixX>& controls) {
            return evaluate_released(t, assembly,
                                     MatrixX(t.twin->key_point_count(), controls.cols()),
                                     [&](const AssemblyId& id, MatrixX& out) {
                                       t.twin->deviations_batch(id, controls, out);
                                     });
          },
          py::arg("assembly"), py::arg("controls"),
          "r(x, u) of the m key points for every column u of `controls` (d x k): an m x k "
          "array, Q = |r| / sqrt(m). Raises InvalidArgumentError for a twin that answers only Q.")
      .def(
          "quality",
          [](const NativeTwin& t, const py::handle& assembly,
             const Eigen::Ref<const VectorX>& control) {
            return evaluate_released(t, assembly, 0.0, [&](const AssemblyId& id, double& out) {
              out = t.twin->quality(id, control);
            });
          },
          py::arg("assembly"), py::arg("control"), "Q(x, u) for one control u (d values).")
      .def(
          "optimum",
          [](const NativeTwin& t, const py::handle& assembly) {
            return t.twin->optimum(t.assembly(assembly));
          },
          py::arg("assembly"), "u0(x) = argmin_u Q(x, u) (eq. (3)), d values.")
      .def(
          "optimal_quality",
          [](const NativeTwin& t, const py::handle& assembly) {
            return t.twin->optimal_quality(t.assembly(assembly));
          },
          py::arg("assembly"), "z*(x) = Q(x, u0(x)).")
      .def("__repr__", [](const NativeTwin& t) {
        return fmt::format("twincal.Twin(d={}, locators=[{}])", t.twin->control_dimension(),
                           fmt::join(t.twin->locator_names(), ", "));
      });
}

}  // namespace twincal::python
