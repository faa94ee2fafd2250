// SigmaPointKalmanFilter (the standard form, any scheme) and the Python class shared with the
// square-root form (python_filter.hpp).
#include <optional>
#include <string>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "python_filter.hpp"
#include "schemes.hpp"
#include "twincal/filters/sigma_point_filter.hpp"

namespace py = pybind11;

namespace twincal::python {
template <typename Object>
py::class_<Object> bind_filter_class(py::module_& module, const char* name, const char* doc) {
  py::class_<Object> cls(module, name, doc);
  cls.def_property_readonly(
         "dim_x", [](const Object& f) { return f.dimension; }, "State dimension n.")
      .def_property(
          "x", [](const Object& f) { return f.filter->state(); },
          [](Object& f, const VectorX& x) { f.filter->reset(x, f.filter->covariance()); },
          "State estimate. Assigning it restarts the filter from N(x, P) (new sigma points).")
      .def_property(
          "P", [](const Object& f) { return f.filter->covariance(); },
          [](Object& f, const MatrixX& p) { f.filter->reset(f.filter->state(), p); },
          "State covariance. Assigning it restarts the filter from N(x, P); it must be "
          "symmetric positive definite (NotPositiveDefiniteError otherwise, state unchanged).")
      .def_property(
          "Q", [](const Object& f) { return f.noise->process_noise; },
          [](Object& f, const MatrixX& q) {
            require_shape("Q", q, f.dimension, f.dimension);
            require_symmetric("Q", q);
            f.noise->process_noise = q;
          },
          "Process noise of the random walk x_{t+1} = x_t + w, w ~ N(0, Q) (eq. (5c)); used "
          "from the next predict().")
      .def_property(
          "R", [](const Object& f) { return f.noise->measurement_variance; },
          [](Object& f, double r) {
            require_finite("R", r);
            require_positive("R", r);
            f.noise->measurement_variance = r;
          },
          "Measurement noise variance (scalar z); used from the next update().")
      .def_property_readonly(
          "x_prior", [](const Object& f) { return f.x_prior; }, "x after the last predict().")
      .def_property_readonly(
          "P_prior", [](const Object& f) { return f.P_prior; }, "P after the last predict().")
      .def_property_readonly(
          "x_post", [](const Object& f) { return f.x_post; }, "x after the last update().")
      .def_property_readonly(
          "P_post", [](const Object& f) { return f.P_post; }, "P after the last update().")
      .def_property_readonly(
          "K", [](const Object& f) { return VectorX(f.filter->last_update().gain); },
          "Kalman gain of the last update (n values; zero before the first).")
      .def_property_readonly(
          "S", [](const Object& f) { return f.filter->last_update().innovation_variance; },
          "Innovation variance of the last update.")
      .def_property_readonly(
          "y", [](const Object& f) { return f.filter->last_update().innovation; },
          "Innovation z - z_hat of the last update.")
      .def_property_readonly(
          "log_likelihood",
          [](const Object& f) { return f.filter->last_update().log_likelihood(); },
          "log N(y; 0, S) of the last update (0 before the first).")
      .def_property_readonly(
          "sigma_points", [](const Object& f) { return f.filter->sigma_points(); },
          "The sigma points the next update evaluates, one per column (n x m), as hx receives "
          "them.")
      .def_property_readonly(
          "Wm", [](const Object& f) { return f.filter->mean_weights(); }, "Mean weights.")
      .def_property_readonly(
          "Wc", [](const Object& f) { return f.filter->covariance_weights(); },
          "Covariance weights.")
      .def(
          "predict",
          [](Object& f) {
            {
              py::gil_scoped_release release;
              f.filter->predict();
            }
            f.x_prior = f.filter->state();
            f.P_prior = f.filter->covariance();
          },
          "Time update of the random walk: x stays, P += Q. Sets x_prior and P_prior.")
      .def(
          "update",
          [](Object& f, const std::optional<double>& z, const py::kwargs& hx_args) {
            if (z) {
              const PythonMeasurementInputs inputs{hx_args.ptr()};
              py::gil_scoped_release release;
              f.filter->update(*z, inputs);
            }
            f.x_post = f.filter->state();
            f.P_post = f.filter->covariance();
          },
          py::arg("z"),
          "Measurement update with the scalar z; hx(points, **hx_args) is called once with "
          "every sigma point. z=None skips the update (filterpy's convention). A non-finite z "
          "raises NonFiniteError; an exception in hx propagates as itself; either way the "
          "filter is unchanged.");
  return cls;
}

template py::class_<StandardFilterObject> bind_filter_class(py::module_&, const char*, const char*);
template py::class_<SquareRootFilterObject> bind_filter_class(py::module_&, const char*,
                                                              const char*);

void bind_filters(py::module_& module) {
  bind_filter_class<StandardFilterObject>(
      module, "SigmaPointKalmanFilter",
      "A sigma-point Kalman filter for the random-walk state x_{t+1} = x_t + w, w ~ N(0, Q) and "
      "a scalar measurement z = hx(x; **hx_args) + v, v ~ N(0, R) (the paper's eqs. (5b)-(5c)). "
      "The scheme object `points` makes it a UKF (MerweScaledSigmaPoints, JulierSigmaPoints, "
      "SimplexSigmaPoints), a CKF (SphericalRadialSigmaPoints) or a fifth-degree filter "
      "(FifthDegreeCubaturePoints). hx receives every sigma point in one call, as an n x m "
      "array (one point per column), and returns m values.")
      .def(py::init([](Index dim_x, py::object hx, py::object points,
                       const std::optional<VectorX>& x, const std::optional<MatrixX>& P,
                       const std::optional<MatrixX>& Q, double R, const std::string& refresh,
                       bool symmetrize, bool joseph_form) {
             SigmaPointFilterOptions options;
             options.refresh = parse_refresh(refresh);
             options.symmetrize = symmetrize;
             options.joseph_form = joseph_form;
             return visit_points(points, [&](const auto& p) {
               using Scheme = std::decay_t<decltype(p.scheme)>;
               using Filter = SigmaPointFilter<PythonRandomWalk, PythonMeasurement, Scheme>;
               return make_python_filter<StandardFilterObject, Filter>(dim_x, std::move(hx), p, x,
                                                                       P, Q, R, options);
             });
           }),
           py::arg("dim_x"), py::arg("hx"), py::arg("points"), py::kw_only(),
           py::arg("x") = py::none(), py::arg("P") = py::none(), py::arg("Q") = py::none(),
           py::arg("R") = 1.0, py::arg("refresh") = "redraw", py::arg("symmetrize") = true,
           py::arg("joseph_form") = false,
           "x defaults to zeros, P and Q to the identity, R to 1 (filterpy's defaults). "
           "refresh: 'redraw' draws the update's points from the prior (filterpy's current UKF), "
           "'reuse_propagated' reuses the propagated points (filterpy 1.4.5's UKF and its CKF). "
           "symmetrize=False and joseph_form=False are filterpy's covariance update.");
}

}  // namespace twincal::python
