#pragma once
/// @file
/// The pieces of the `twincal._twincal` extension module, one function per source file, called
/// in order by module.cpp (the error types first: the others' docstrings name them).

#include <pybind11/pybind11.h>

namespace twincal::python {

/// twincal.Error and its subclasses, and the translator from the C++ error types (errors.cpp).
void bind_errors(pybind11::module_& module);
/// twincal.TwinError's class (nullptr before bind_errors): a twin written in Python raises it for
/// a failure the controllers' failure policy handles (python_twin.cpp).
PyObject* twin_error_type() noexcept;
/// The sigma-point schemes, with filterpy's names and methods (schemes.cpp).
void bind_schemes(pybind11::module_& module);
/// SigmaPointKalmanFilter and SquareRootKalmanFilter over a Python measurement function
/// (filters.cpp, square_root_filters.cpp).
void bind_filters(pybind11::module_& module);
void bind_square_root_filters(pybind11::module_& module);
/// Sobol and Halton with SciPy's qmc vocabulary (samplers.cpp).
void bind_samplers(pybind11::module_& module);
/// twincal.Twin: the FEM and analytic twins (twins.cpp, native_twin.hpp).
void bind_twins(pybind11::module_& module);
/// IndividualizedController, DefaultController, PaperController, PerComponentController and
/// ActiveController over a twin written in Python or a twincal.Twin (controllers.cpp,
/// python_twin.hpp).
void bind_controllers(pybind11::module_& module);
/// BudgetedOptimum: u0 of a twin written in Python searched within a budget (optimum.cpp).
void bind_optimum(pybind11::module_& module);
/// `_run_experiment`, behind twincal.run_experiment (experiments.cpp).
void bind_experiments(pybind11::module_& module);

}  // namespace twincal::python
