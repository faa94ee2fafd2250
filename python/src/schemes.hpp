#pragma once
/// @file
/// `Points<Scheme>`: a sigma-point scheme bound to a dimension n, the object filterpy users pass
/// as `points` (MerweScaledSigmaPoints(n, alpha, beta, kappa), …), and `visit_points`, which
/// calls a function with the concrete scheme behind such a Python object.

#include <string>
#include <utility>

#include <fmt/format.h>
#include <pybind11/pybind11.h>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/filters/fifth_degree_cubature_sigma_points.hpp"
#include "twincal/filters/julier_sigma_points.hpp"
#include "twincal/filters/merwe_scaled_sigma_points.hpp"
#include "twincal/filters/simplex_sigma_points.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"

namespace twincal::python {

template <typename Scheme>
struct Points {
  Index n;
  Scheme scheme;
};

/// Calls `f(points)` with the Points<Scheme> behind the Python object `points`.
/// @throws InvalidArgumentError when `points` is not one of twincal's sigma-point objects.
template <typename F>
decltype(auto) visit_points(pybind11::handle points, F&& f) {
  namespace py = pybind11;
  if (py::isinstance<Points<MerweScaledSigmaPoints>>(points)) {
    return std::forward<F>(f)(points.cast<const Points<MerweScaledSigmaPoints>&>());
  }
  if (py::isinstance<Points<JulierSigmaPoints>>(points)) {
    return std::forward<F>(f)(points.cast<const Points<JulierSigmaPoints>&>());
  }
  if (py::isinstance<Points<SimplexSigmaPoints>>(points)) {
    return std::forward<F>(f)(points.cast<const Points<SimplexSigmaPoints>&>());
  }
  if (py::isinstance<Points<SphericalRadialSigmaPoints>>(points)) {
    return std::forward<F>(f)(points.cast<const Points<SphericalRadialSigmaPoints>&>());
  }
  if (py::isinstance<Points<FifthDegreeCubatureSigmaPoints>>(points)) {
    return std::forward<F>(f)(points.cast<const Points<FifthDegreeCubatureSigmaPoints>&>());
  }
  throw InvalidArgumentError(
      "points", fmt::format("points: value is a {}; rule: must be MerweScaledSigmaPoints, "
                            "JulierSigmaPoints, SimplexSigmaPoints, SphericalRadialSigmaPoints or "
                            "FifthDegreeCubaturePoints",
                            std::string(py::str(py::type::of(points).attr("__name__")))));
}

}  // namespace twincal::python
