// PythonTwin: calls into a twin written in Python (python_twin.hpp).
#include "python_twin.hpp"

#include <string>
#include <utility>

#include <fmt/format.h>
#include <pybind11/numpy.h>

#include "bindings.hpp"
#include "native_twin.hpp"
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
                          "numbers each) and quality_batch(assembly, controls)",
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

bool has_method(const py::object& twin, const char* name) {
  return py::hasattr(twin, name) && PyCallable_Check(twin.attr(name).ptr()) != 0;
}

// twin.<method>(arguments…) (the GIL held). A twincal.TwinError the twin raises becomes the C++
// TwinError, a failure the controllers' policies handle; any other exception propagates as
// itself and stops the controller.
template <typename... Arguments>
py::object call_twin(const py::object& twin, const char* method, Arguments&&... arguments) {
  try {
    return twin.attr(method)(std::forward<Arguments>(arguments)...);
  } catch (py::error_already_set& raised) {
    if (!raised.matches(twin_error_type())) throw;
    throw TwinError(fmt::format("twin.{}", method),
                    fmt::format("twin.{} raised {}", method, raised.what()));
  }
}

// twin.<method>(assembly, controls) with the controls as a d × k array (the GIL held).
py::object call_batch(const py::object& twin, const char* method, PyObject* assembly,
                      const Eigen::Ref<const MatrixX>& controls) {
  py::array_t<double, py::array::f_style> batch({controls.rows(), controls.cols()});
  Eigen::Map<MatrixX>(batch.mutable_data(), controls.rows(), controls.cols()) = controls;
  return call_twin(twin, method, py::handle(assembly), std::move(batch));
}

// m of a twin with deviations_batch: its key_point_count (an int, or a method returning one).
Index read_key_point_count(const py::object& twin) {
  const char* rule =
      "rule: a twin with deviations_batch has key_point_count, an int m >= 1 (the rows of its "
      "m × k deviations)";
  if (!py::hasattr(twin, "key_point_count")) {
    throw InvalidArgumentError("key_point_count",
                               fmt::format("twin.key_point_count: missing; {}", rule));
  }
  py::object value = twin.attr("key_point_count");
  if (PyCallable_Check(value.ptr())) value = value();
  if (!py::isinstance<py::int_>(value) || py::isinstance<py::bool_>(value)) {
    throw InvalidArgumentError("key_point_count",
                               fmt::format("twin.key_point_count: {} is not an int; {}",
                                           py::repr(value).cast<std::string>(), rule));
  }
  const auto m = value.cast<long long>();
  if (m < 1) {
    throw InvalidArgumentError("key_point_count",
                               fmt::format("twin.key_point_count: value is {}; {}", m, rule));
  }
  return static_cast<Index>(m);
}

}  // namespace

PythonTwin::PythonTwin(py::object twin) {
  if (py::isinstance<NativeTwin>(twin)) {
    native_ = twin.cast<const NativeTwin&>().twin;
    lower_ = native_->lower_bounds();
    upper_ = native_->upper_bounds();
    names_ = native_->locator_names();
    key_points_ = native_->key_point_count();
    twin_ = std::make_unique<py::object>(std::move(twin));
    return;
  }
  if (!has_method(twin, "quality_batch")) {
    throw InvalidArgumentError("quality_batch",
                               "twin.quality_batch: missing or not callable; rule: a twin has "
                               "quality_batch(assembly, controls) (d × k controls, k qualities)");
  }
  has_optimum_ = has_method(twin, "optimum");
  has_optimal_quality_ = has_optimum_ && has_method(twin, "optimal_quality");
  if (has_method(twin, "deviations_batch")) key_points_ = read_key_point_count(twin);
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

PythonAssembly PythonTwin::borrow(py::handle assembly) const {
  searched_.reset();
  PythonAssembly out{assembly.ptr(), {}};
  if (native_) out.native = py::cast<const NativeTwin&>(*twin_).assembly(assembly);
  return out;
}

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
  if (native_) {
    native_->quality_batch(assembly.native, controls, out);
    return;
  }
  py::gil_scoped_acquire gil;
  const auto values = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(
      call_batch(*twin_, "quality_batch", assembly.object, controls));
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

void PythonTwin::deviations_batch(const Assembly& assembly,
                                  const Eigen::Ref<const MatrixX>& controls,
                                  Eigen::Ref<MatrixX> out) const {
  if (key_points_ == 0) {
    throw InvalidArgumentError("deviations",
                               "twin.deviations_batch: the twin answers only Q; rule: a twin "
                               "answers its deviations when it has deviations_batch and "
                               "key_point_count");
  }
  require_deviations_batch(controls, out, control_dimension(), key_points_);
  if (native_) {
    native_->deviations_batch(assembly.native, controls, out);
    return;
  }
  py::gil_scoped_acquire gil;
  const auto values = py::array_t<double, py::array::f_style | py::array::forcecast>::ensure(
      call_batch(*twin_, "deviations_batch", assembly.object, controls));
  const bool matrix = values && values.ndim() == 2;
  const bool rows_right = matrix && values.shape(0) == key_points_;
  if (!rows_right || values.shape(1) != controls.cols()) {
    const std::string shape = matrix
                                  ? fmt::format("a {} × {} array", values.shape(0), values.shape(1))
                              : values ? fmt::format("an array of {} dimensions", values.ndim())
                                       : std::string("no array");
    // The mismatch named: the rows if they are wrong, else the columns.
    const Index actual = !matrix ? 0 : rows_right ? values.shape(1) : values.shape(0);
    throw DimensionMismatchError(
        "deviations_batch",
        fmt::format("twin.deviations_batch: returned {} for {} controls; rule: m × k = {} × {} "
                    "(one column of key-point deviations per control)",
                    shape, controls.cols(), key_points_, controls.cols()),
        actual, rows_right ? controls.cols() : key_points_);
  }
  out = Eigen::Map<const MatrixX>(values.data(), key_points_, controls.cols());
}

VectorX PythonTwin::optimum(const Assembly& assembly) const {
  if (native_) return native_->optimum(assembly.native);
  if (!has_optimum_) return searched_optimum(assembly).control;
  py::gil_scoped_acquire gil;
  const py::object result = call_twin(*twin_, "optimum", py::handle(assembly.object));
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
  if (native_) return native_->optimal_quality(assembly.native);
  if (!has_optimum_) return searched_optimum(assembly).quality;
  if (!has_optimal_quality_) return quality(assembly, optimum(assembly));
  py::gil_scoped_acquire gil;
  const double z = py::float_(call_twin(*twin_, "optimal_quality", py::handle(assembly.object)));
  require_finite("twin.optimal_quality", z);
  return z;
}

const IndividualControl& PythonTwin::searched_optimum(const Assembly& assembly) const {
  if (!searched_ || searched_->assembly != assembly.object) {
    const VectorX centre = 0.5 * (lower_ + upper_);
    searched_ = SearchedOptimum{assembly.object,
                                IndividualOptimum<PythonTwin>(*this).optimize(assembly, centre)};
  }
  return searched_->result;
}

}  // namespace twincal::python
