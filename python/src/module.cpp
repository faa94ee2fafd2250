// twincal._twincal: the compiled half of the `twincal` Python package (python/twincal/).
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(_twincal, module) {
  module.doc() =
      "twincal's C++ core: sigma-point Kalman filters over Python measurement functions, "
      "sigma-point schemes, quasi-random samplers, the FEM and analytic twins, controllers over "
      "them and over Python twins, and the paper's experiments. Import it as "
      "`twincal`.";
  twincal::python::bind_errors(module);
  twincal::python::bind_schemes(module);
  twincal::python::bind_filters(module);
  twincal::python::bind_square_root_filters(module);
  twincal::python::bind_samplers(module);
  twincal::python::bind_twins(module);
  twincal::python::bind_optimum(module);
  twincal::python::bind_controllers(module);
  twincal::python::bind_experiments(module);
}
