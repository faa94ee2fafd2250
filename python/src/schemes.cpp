// The sigma-point schemes with filterpy's constructors, `sigma_points(x, P)` (one point per row,
// as filterpy returns them), `num_sigmas()`, `Wm` and `Wc`.
#include <string>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "schemes.hpp"
#include "twincal/core/cholesky.hpp"
#include "twincal/core/validate.hpp"

namespace py = pybind11;

namespace twincal::python {
namespace {

template <typename Scheme>
VectorX weights(const Points<Scheme>& p, bool mean) {
  const Index m = p.scheme.num_points(p.n);
  VectorX mean_weights(m);
  VectorX covariance_weights(m);
  p.scheme.weights(p.n, mean_weights, covariance_weights);
  return mean ? mean_weights : covariance_weights;
}

template <typename Scheme>
MatrixX sigma_points(const Points<Scheme>& p, const VectorX& x, const MatrixX& covariance) {
  require_dimension("x", x.size(), p.n);
  require_finite("x", x);
  require_shape("P", covariance, p.n, p.n);
  require_symmetric("P", covariance);
  const CholeskyResult<Dynamic> factor = cholesky(covariance, {}, "P");
  MatrixX points(p.n, p.scheme.num_points(p.n));
  p.scheme.generate(x, factor.factor.lower(), points);
  MatrixX rows = points.transpose();  // filterpy's layout: one point per row
  return rows;
}

// The members every scheme class shares; `repr` describes its parameters.
template <typename Scheme, typename Repr>
py::class_<Points<Scheme>> bind_scheme(py::module_& module, const char* name, const char* doc,
                                       Repr repr) {
  py::class_<Points<Scheme>> cls(module, name, doc);
  cls.def_property_readonly(
         "n", [](const Points<Scheme>& p) { return p.n; }, "State dimension n.")
      .def(
          "num_sigmas", [](const Points<Scheme>& p) { return p.scheme.num_points(p.n); },
          "Number of sigma points.")
      .def_property_readonly(
          "Wm", [](const Points<Scheme>& p) { return weights(p, true); }, "Mean weights.")
      .def_property_readonly(
          "Wc", [](const Points<Scheme>& p) { return weights(p, false); }, "Covariance weights.")
      .def("sigma_points", &sigma_points<Scheme>, py::arg("x"), py::arg("P"),
           "The sigma points of N(x, P), one per row (filterpy's layout), from the Cholesky "
           "factor of P.")
      .def("__repr__", repr);
  return cls;
}

template <typename Scheme>
Points<Scheme> make_points(Index n, Scheme scheme) {
  if (n < 1) {
    throw InvalidArgumentError("n", fmt::format("n: value is {}; rule: must be >= 1", n));
  }
  return Points<Scheme>{n, std::move(scheme)};
}

}  // namespace

void bind_schemes(py::module_& module) {
  bind_scheme<MerweScaledSigmaPoints>(
      module, "MerweScaledSigmaPoints",
      "Van der Merwe's scaled sigma points (the paper's eq. (11)): 2n + 1 points, "
      "lambda = alpha^2 (n + kappa) - n, filterpy's weights.",
      [](const Points<MerweScaledSigmaPoints>& p) {
        return fmt::format("MerweScaledSigmaPoints(n={}, alpha={}, beta={}, kappa={})", p.n,
                           p.scheme.alpha(), p.scheme.beta(), p.scheme.kappa());
      })
      .def(py::init([](Index n, double alpha, double beta, double kappa) {
             return make_points(n, MerweScaledSigmaPoints(alpha, beta, kappa));
           }),
           py::arg("n"), py::arg("alpha"), py::arg("beta"), py::arg("kappa"));
  bind_scheme<JulierSigmaPoints>(
      module, "JulierSigmaPoints", "Julier's sigma points: 2n + 1 points with parameter kappa.",
      [](const Points<JulierSigmaPoints>& p) {
        return fmt::format("JulierSigmaPoints(n={}, kappa={})", p.n, p.scheme.kappa());
      })
      .def(py::init([](Index n, double kappa) { return make_points(n, JulierSigmaPoints(kappa)); }),
           py::arg("n"), py::arg("kappa") = 0.0);
  bind_scheme<SimplexSigmaPoints>(module, "SimplexSigmaPoints",
                                  "Simplex sigma points: n + 1 points, equal weights.",
                                  [](const Points<SimplexSigmaPoints>& p) {
                                    return fmt::format("SimplexSigmaPoints(n={})", p.n);
                                  })
      .def(py::init([](Index n) { return make_points(n, SimplexSigmaPoints{}); }), py::arg("n"));
  bind_scheme<SphericalRadialSigmaPoints>(
      module, "SphericalRadialSigmaPoints",
      "The cubature Kalman filter's third-degree spherical-radial rule: 2n points x +- sqrt(n) "
      "L e_k, equal weights.",
      [](const Points<SphericalRadialSigmaPoints>& p) {
        return fmt::format("SphericalRadialSigmaPoints(n={})", p.n);
      })
      .def(py::init([](Index n) { return make_points(n, SphericalRadialSigmaPoints{}); }),
           py::arg("n"));
  bind_scheme<FifthDegreeCubatureSigmaPoints>(
      module, "FifthDegreeCubaturePoints",
      "A fifth-degree cubature rule: 2n^2 + 1 points, exact for polynomials up to degree 5.",
      [](const Points<FifthDegreeCubatureSigmaPoints>& p) {
        return fmt::format("FifthDegreeCubaturePoints(n={})", p.n);
      })
      .def(py::init([](Index n) { return make_points(n, FifthDegreeCubatureSigmaPoints{}); }),
           py::arg("n"));
}

}  // namespace twincal::python
