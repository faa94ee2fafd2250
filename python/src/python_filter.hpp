#pragma once
/// @file
/// The Python face of twincal's sigma-point filters, with filterpy's vocabulary:
/// - `PythonMeasurement`: z = hx(points, **hx_args) + v, a Python function that receives every
///   sigma point in one call (an n × m array, one point per column) and returns m values;
/// - `PythonRandomWalk`: x_{t+1} = x_t + w, w ~ N(0, Q) (the paper's eq. (5c));
/// - `FilterHandle`: one filter behind a virtual interface, so one Python class serves every
///   scheme; `FilterAdapter<Filter>` implements it for SigmaPointFilter and
///   SquareRootSigmaPointFilter;
/// - `bind_filter_class`: the Python class itself (x, P, Q, R, predict, update, x_prior, …).
///
/// Threads: the filter runs without the GIL; the measurement function re-acquires it.
/// Q and R live in a block shared by the models and the Python object, so assigning `f.Q` or
/// `f.R` takes effect at the next predict or update, as in filterpy.

#include <memory>
#include <optional>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "schemes.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/sigma_point_filter.hpp"

namespace twincal::python {

/// "redraw" or "reuse_propagated" (SigmaPointRefresh).
/// @throws InvalidArgumentError for any other name.
inline SigmaPointRefresh parse_refresh(const std::string& refresh) {
  if (refresh == "redraw") return SigmaPointRefresh::redraw;
  if (refresh == "reuse_propagated") return SigmaPointRefresh::reuse_propagated;
  throw InvalidArgumentError(
      "refresh", fmt::format("refresh: value is '{}'; rule: must be 'redraw' (filterpy's current "
                             "UKF) or 'reuse_propagated' (filterpy 1.4.5's UKF, its CKF)",
                             refresh));
}

/// Q and R, shared by the models and the Python object.
struct NoiseSettings {
  MatrixX process_noise;
  double measurement_variance = 1.0;
};

class PythonRandomWalk {
 public:
  static constexpr int dimension_at_compile_time = Dynamic;
  explicit PythonRandomWalk(std::shared_ptr<const NoiseSettings> noise)
      : noise_(std::move(noise)) {}
  [[nodiscard]] Index dimension() const noexcept { return noise_->process_noise.rows(); }
  [[nodiscard]] const VectorX& propagate(const VectorX& state) const noexcept { return state; }
  [[nodiscard]] const MatrixX& process_noise() const noexcept { return noise_->process_noise; }

 private:
  std::shared_ptr<const NoiseSettings> noise_;
};

/// The keyword arguments of one update, borrowed from the Python call (no reference counting:
/// the filter copies inputs while the GIL is released).
struct PythonMeasurementInputs {
  PyObject* keywords = nullptr;
};

class PythonMeasurement {
 public:
  static constexpr int dimension_at_compile_time = Dynamic;
  using Inputs = PythonMeasurementInputs;

  /// `function` is held through a shared pointer: copies of the model never touch Python
  /// reference counts (they may happen without the GIL).
  PythonMeasurement(std::shared_ptr<pybind11::object> function,
                    std::shared_ptr<const NoiseSettings> noise)
      : function_(std::move(function)), noise_(std::move(noise)) {}

  [[nodiscard]] double noise_variance() const noexcept { return noise_->measurement_variance; }

  [[nodiscard]] double measure(const VectorX& state, const Inputs& inputs) const {
    double value = 0.0;
    measure_batch(state, inputs, Eigen::Map<VectorX>(&value, 1));
    return value;
  }

  /// out(i) = hx(states)[i]: one Python call for all columns. A Python exception raised by hx
  /// propagates as itself (pybind11::error_already_set) before the filter changes.
  /// @throws DimensionMismatchError when hx returns other than one value per column.
  void measure_batch(const Eigen::Ref<const MatrixX>& states, const Inputs& inputs,
                     Eigen::Ref<VectorX> out) const {
    namespace py = pybind11;
    py::gil_scoped_acquire gil;
    // A copy: hx may keep the array, and the filter's points change at the next step.
    py::array_t<double, py::array::f_style> points({states.rows(), states.cols()});
    Eigen::Map<MatrixX>(points.mutable_data(), states.rows(), states.cols()) = states;
    py::object result =
        inputs.keywords != nullptr
            ? (*function_)(points, **py::reinterpret_borrow<py::dict>(inputs.keywords))
            : (*function_)(points);
    const auto values =
        py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(result);
    if (!values) {
      throw InvalidArgumentError(
          "hx",
          fmt::format("hx: returned a {}; rule: must return an array of {} numbers, one "
                      "per sigma point (column)",
                      std::string(py::str(py::type::of(result).attr("__name__"))), states.cols()));
    }
    if (values.size() != states.cols()) {
      throw DimensionMismatchError(
          "hx",
          fmt::format("hx: returned {} values for {} sigma points; rule: one value per column of "
                      "the n × m points array",
                      values.size(), states.cols()),
          values.size(), states.cols());
    }
    out = Eigen::Map<const VectorX>(values.data(), states.cols());
  }

 private:
  std::shared_ptr<pybind11::object> function_;
  std::shared_ptr<const NoiseSettings> noise_;
};

/// One filter, whatever its scheme and form.
class FilterHandle {
 public:
  virtual ~FilterHandle() = default;
  virtual void predict() = 0;
  virtual void update(double z, const PythonMeasurementInputs& inputs) = 0;
  /// Restarts from N(x, P) (the filter's constructor checks them; on error nothing changes).
  virtual void reset(const VectorX& x, const MatrixX& covariance) = 0;
  [[nodiscard]] virtual VectorX state() const = 0;
  [[nodiscard]] virtual MatrixX covariance() const = 0;
  [[nodiscard]] virtual MatrixX sigma_points() const = 0;
  [[nodiscard]] virtual VectorX mean_weights() const = 0;
  [[nodiscard]] virtual VectorX covariance_weights() const = 0;
  [[nodiscard]] virtual const UpdateRecord<Dynamic>& last_update() const = 0;
};

/// FilterHandle for `Filter`, rebuilt by `make(x, P)` on reset (the filters keep their state
/// private: a new one from N(x, P) is exactly a restart).
template <typename Filter, typename Make>
class FilterAdapter final : public FilterHandle {
 public:
  FilterAdapter(Make make, const VectorX& x, const MatrixX& covariance)
      : make_(std::move(make)), filter_(make_(x, covariance)) {}

  void predict() override { filter_->predict(); }
  void update(double z, const PythonMeasurementInputs& inputs) override {
    filter_->update(z, inputs);
  }
  void reset(const VectorX& x, const MatrixX& covariance) override {
    filter_ = make_(x, covariance);
  }
  [[nodiscard]] VectorX state() const override { return filter_->state(); }
  [[nodiscard]] MatrixX covariance() const override { return filter_->covariance(); }
  [[nodiscard]] MatrixX sigma_points() const override { return filter_->sigma_points(); }
  [[nodiscard]] VectorX mean_weights() const override { return filter_->mean_weights(); }
  [[nodiscard]] VectorX covariance_weights() const override {
    return filter_->covariance_weights();
  }
  [[nodiscard]] const UpdateRecord<Dynamic>& last_update() const override {
    return filter_->last_update();
  }

 private:
  Make make_;
  std::unique_ptr<Filter> filter_;
};

/// The Python object: the filter, its shared Q and R, and filterpy's copies of the prior and
/// posterior.
struct PythonFilter {
  std::shared_ptr<NoiseSettings> noise;
  std::unique_ptr<FilterHandle> filter;
  Index dimension = 0;
  VectorX x_prior;
  MatrixX P_prior;
  VectorX x_post;
  MatrixX P_post;
};

/// The two Python classes' C++ types (pybind11 binds each C++ type to one class).
struct StandardFilterObject : PythonFilter {};
struct SquareRootFilterObject : PythonFilter {};

/// Builds the Python object `Object` for `Filter` (a SigmaPointFilter or SquareRootSigmaPointFilter
/// over the Python models) with `points`' scheme: x defaults to zeros, P and Q to the identity
/// (filterpy's defaults).
template <typename Object, typename Filter, typename Scheme, typename Options>
Object make_python_filter(Index dim_x, pybind11::object hx, const Points<Scheme>& points,
                          const std::optional<VectorX>& x, const std::optional<MatrixX>& P,
                          const std::optional<MatrixX>& Q, double R, const Options& options) {
  if (dim_x < 1) {
    throw InvalidArgumentError("dim_x",
                               fmt::format("dim_x: value is {}; rule: must be >= 1", dim_x));
  }
  require_dimension("points.n", points.n, dim_x);
  if (!PyCallable_Check(hx.ptr())) {
    throw InvalidArgumentError("hx", "hx: rule: must be callable as hx(points, **hx_args)");
  }
  const MatrixX process_noise = Q ? *Q : MatrixX::Identity(dim_x, dim_x);
  require_shape("Q", process_noise, dim_x, dim_x);
  require_symmetric("Q", process_noise);
  require_finite("R", R);
  require_positive("R", R);
  auto noise = std::make_shared<NoiseSettings>(NoiseSettings{process_noise, R});
  auto make = [walk = PythonRandomWalk(noise),
               measurement =
                   PythonMeasurement(std::make_shared<pybind11::object>(std::move(hx)), noise),
               scheme = points.scheme, options](const VectorX& mean, const MatrixX& covariance) {
    return std::make_unique<Filter>(walk, measurement, scheme, mean, covariance, options);
  };
  Object out;
  out.filter = std::make_unique<FilterAdapter<Filter, decltype(make)>>(
      std::move(make), x ? *x : VectorX::Zero(dim_x), P ? *P : MatrixX::Identity(dim_x, dim_x));
  out.noise = std::move(noise);
  out.dimension = dim_x;
  out.x_prior = out.x_post = out.filter->state();
  out.P_prior = out.P_post = out.filter->covariance();
  return out;
}

/// The Python class `name` over `Object` (a PythonFilter; constructors are added by the
/// caller). Instantiated for StandardFilterObject and SquareRootFilterObject in filters.cpp.
template <typename Object>
pybind11::class_<Object> bind_filter_class(pybind11::module_& module, const char* name,
                                           const char* doc);

}  // namespace twincal::python
