// PythonTwin: calls into a twin written in Python (python_twin.hpp).
#include "python_twin.hpp"

#include <string>

#include <fmt/format.h>
#include <pybind11/numpy.h>

#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"

namespace py = pybind11;

namespace twincal::python {
namespace {

// The attribute `name` of `twin` as d finite numbers (d = expected, or any when < 0).
VectorX read_vector(const py::object& twin, const char* name, Index expected) {
  if (!py::hasattr(twin, name)) {
    throw InvalidArgumentError(
        name, fmt::format("twin.{}: missing; rule: a twin has lower_bounds and upper_bounds (d "
                          "numbers each), quality_batch(assembly, controls) and "
                          "optimum(assembly)",
                          name));
  }
  py::object value = twin.attr(name);
  if (PyCallable_Check(value.ptr())) value = value();
  const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!array || array.ndim() != 1) {
    throw InvalidArgumentError(
        name, fmt::format("twin.{}: rule: must be a one-dimensional array of numbers", name));
  }
  VectorX out = Eigen::Map<const VectorX>(array.data(), array.size());
  if (expected >= 0) require_dimension(std::string("twin.") + name, out.size(), expected);
  require_finite(std::string("twin.") + name, out);
  return out;
}

void require_method(const py::object& twin, const char* name) {
  if (!py::hasattr(twin, name) || !PyCallable_Check(twin.attr(name).ptr())) {
    throw InvalidArgumentError(
        name, fmt::format("twin.{}: missing or not callable; rule: a twin has "
                          "quality_batch(assembly, controls) and optimum(assembly)",
                          name));
  }
}

}  // namespace

PythonTwin::PythonTwin(py::object twin) {
  require_method(twin, "quality_batch");
  require_method(twin, "optimum");
  lower_ = read_vector(twin, "lower_bounds", -1);
  if (lower_.size() < 1) {
    throw InvalidArgumentError("lower_bounds", "twin.lower_bounds: rule: must have d >= 1 entries");
  }
  upper_ = read_vector(twin, "upper_bounds", lower_.size());
  for (Index i = 0; i < lower_.size(); ++i) {
    if (!(lower_(i) < upper_(i))) {
      throw InvalidArgumentError(
          "upper_bounds", fmt::format("twin bounds: locator {} has [{}, {}]; rule: lower < upper",
                                      i, lower_(i), upper_(i)));
    }
  }
  if (py::hasattr(twin, "locator_names")) {
    for (const py::handle name : twin.attr("locator_names")) names_.push_back(py::str(name));
    require_dimension("twin.locator_names", static_cast<Index>(names_.size()), lower_.size());
  } else {
    for (Index i = 0; i < lower_.size(); ++i) names_.push_back(fmt::format("u{}", i));
  }
  twin_ = std::make_unique<py::object>(std::move(twin));
}

PythonTwin::~PythonTwin() {
  py::gil_scoped_acquire gil;
  twin_.reset();
}

py::object PythonTwin::object() const { return *twin_; }

double PythonTwin::quality(const Assembly& assembly,
                           const Eigen::Ref<const VectorX>& control) const {
  double value = 0.0;
  quality_batch(assembly, control, Eigen::Map<VectorX>(&value, 1));
  return value;
}

void PythonTwin::quality_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                               Eigen::Ref<VectorX> out) const {
  require_dimension("controls", controls.rows(), control_dimension(), "rows");
  require_dimension("out", out.size(), controls.cols());
  py::gil_scoped_acquire gil;
  py::array_t<double, py::array::f_style> batch({controls.rows(), controls.cols()});
  Eigen::Map<MatrixX>(batch.mutable_data(), controls.rows(), controls.cols()) = controls;
  const py::object result =
      twin_->attr("quality_batch")(py::handle(assembly.object), std::move(batch));
  const auto values =
      py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(result);
  if (!values || values.size() != controls.cols()) {
    throw DimensionMismatchError(
        "quality_batch",
        fmt::format("twin.quality_batch: returned {} values for {} controls; rule: one quality "
                    "per column of the d × k controls",
                    values ? values.size() : 0, controls.cols()),
        values ? values.size() : 0, controls.cols());
  }
  out = Eigen::Map<const VectorX>(values.data(), controls.cols());
}

VectorX PythonTwin::optimum(const Assembly& assembly) const {
  py::gil_scoped_acquire gil;
  const py::object result = twin_->attr("optimum")(py::handle(assembly.object));
  const auto values =
      py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(result);
  if (!values || values.size() != control_dimension()) {
    throw DimensionMismatchError(
        "optimum",
        fmt::format("twin.optimum: returned {} values; rule: d = {} (u0 of the assembly)",
                    values ? values.size() : 0, control_dimension()),
        values ? values.size() : 0, control_dimension());
  }
  VectorX u0 = Eigen::Map<const VectorX>(values.data(), values.size());
  require_finite("twin.optimum", u0);
  return u0;
}

double PythonTwin::optimal_quality(const Assembly& assembly) const {
  const VectorX u0 = optimum(assembly);
  return quality(assembly, u0);
}

}  // namespace twincal::python
