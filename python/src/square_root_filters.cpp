// SquareRootKalmanFilter: the square-root form of the sigma-point filter (any scheme) behind the
// same Python class as SigmaPointKalmanFilter (python_filter.hpp). Its own translation unit:
// the five square-root instantiations compile in parallel with the standard ones.
#include <optional>
#include <string>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "python_filter.hpp"
#include "schemes.hpp"
#include "twincal/filters/square_root_sigma_point_filter.hpp"

namespace py = pybind11;

namespace twincal::python {
namespace {

SquareRootFilterOptions parse_options(const std::string& refresh, const std::string& update) {
  SquareRootFilterOptions options;
  options.refresh = parse_refresh(refresh);
  if (update == "joseph") {
    options.update = SquareRootUpdate::joseph;
  } else if (update == "downdate") {
    options.update = SquareRootUpdate::downdate;
  } else {
    throw InvalidArgumentError(
        "update",
        fmt::format("update: value is '{}'; rule: must be 'joseph' or 'downdate'", update));
  }
  return options;
}

}  // namespace

void bind_square_root_filters(py::module_& module) {
  bind_filter_class<SquareRootFilterObject>(
      module, "SquareRootKalmanFilter",
      "The square-root form of SigmaPointKalmanFilter: it propagates a Cholesky factor of P "
      "(QR of the weighted points), so P stays positive definite where the standard form's "
      "P - K S K^T can lose it. Same attributes; P is formed from the factor when read.")
      .def(py::init([](Index dim_x, py::object hx, py::object points,
                       const std::optional<VectorX>& x, const std::optional<MatrixX>& P,
                       const std::optional<MatrixX>& Q, double R, const std::string& refresh,
                       const std::string& update) {
             const SquareRootFilterOptions options = parse_options(refresh, update);
             return visit_points(points, [&](const auto& p) {
               using Scheme = std::decay_t<decltype(p.scheme)>;
               using Filter =
                   SquareRootSigmaPointFilter<PythonRandomWalk, PythonMeasurement, Scheme>;
               return make_python_filter<SquareRootFilterObject, Filter>(dim_x, std::move(hx), p, x,
                                                                         P, Q, R, options);
             });
           }),
           py::arg("dim_x"), py::arg("hx"), py::arg("points"), py::kw_only(),
           py::arg("x") = py::none(), py::arg("P") = py::none(), py::arg("Q") = py::none(),
           py::arg("R") = 1.0, py::arg("refresh") = "redraw", py::arg("update") = "joseph",
           "x defaults to zeros, P and Q to the identity, R to 1. update: 'joseph' (QR of the "
           "Joseph form, always positive definite) or 'downdate' (rank-one Cholesky downdate).");
}

}  // namespace twincal::python
