// twincal's C++ error types as Python exceptions. Each is also a subclass of the built-in a
// Python user would catch for it (ValueError for invalid arguments, ArithmeticError for
// numerical failures), so generic code keeps working; the message is the C++ one, which names
// the argument, the value and the rule.
#include <exception>

#include <Python.h>

#include "bindings.hpp"
#include "twincal/core/error.hpp"

namespace py = pybind11;

namespace twincal::python {
namespace {

// New exception class `twincal.<name>` deriving from `bases` (a tuple), added to the module.
PyObject* add_exception(py::module_& module, const char* name, const py::tuple& bases,
                        const char* doc) {
  const std::string qualified = std::string("twincal.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), /*dict=*/nullptr);
  if (type == nullptr) throw py::error_already_set();
  module.add_object(name, py::handle(type));  // the module owns the reference
  return type;
}

// twincal.TwinError, once bind_errors made it (the module owns it for as long as it lives).
PyObject* twin_error = nullptr;

}  // namespace

PyObject* twin_error_type() noexcept { return twin_error; }

void bind_errors(py::module_& module) {
  // Types live as long as the module: plain pointers are enough for the translator.
  static PyObject* error = nullptr;
  static PyObject* invalid_argument = nullptr;
  static PyObject* dimension_mismatch = nullptr;
  static PyObject* non_finite = nullptr;
  static PyObject* not_positive_definite = nullptr;

  error = add_exception(module, "Error", py::make_tuple(py::handle(PyExc_RuntimeError)),
                        "Base of every error twincal raises; the message names the argument at "
                        "fault, its value and the rule it broke.");
  invalid_argument = add_exception(
      module, "InvalidArgumentError",
      py::make_tuple(py::handle(error), py::handle(PyExc_ValueError)),
      "A value broke a documented rule (range, sign, option consistency). Also a ValueError.");
  dimension_mismatch =
      add_exception(module, "DimensionMismatchError", py::make_tuple(py::handle(invalid_argument)),
                    "Sizes of arrays do not agree. Also a ValueError.");
  non_finite = add_exception(
      module, "NonFiniteError",
      py::make_tuple(py::handle(error), py::handle(PyExc_ArithmeticError)),
      "A NaN or infinity where only finite numbers are allowed (input, model output, filter "
      "state). Also an ArithmeticError.");
  twin_error = add_exception(
      module, "TwinError", py::make_tuple(py::handle(error)),
      "A twin could not answer at the controls it was asked (its solver did not converge, its "
      "program failed). Raised by a twin written in Python, it is a twin failure to the "
      "controllers: a proposal falls back to the default control, a measurement the estimate "
      "cannot be updated with is dropped, and last_proposal says why; any other exception a "
      "twin raises stops the controller.");
  not_positive_definite = add_exception(
      module, "NotPositiveDefiniteError",
      py::make_tuple(py::handle(error), py::handle(PyExc_ArithmeticError)),
      "A matrix that must be symmetric positive definite is not (a covariance, its factor). Also "
      "an ArithmeticError.");

  // Most derived first. A Python exception raised in a callback (a measurement function, a
  // twin) arrives as pybind11's error_already_set, which pybind11 itself restores unchanged;
  // PythonTwin turns a twincal.TwinError into the C++ TwinError, and this turns it back.
  py::register_exception_translator([](std::exception_ptr thrown) {
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const DimensionMismatchError& e) {
      PyErr_SetString(dimension_mismatch, e.what());
    } catch (const InvalidArgumentError& e) {
      PyErr_SetString(invalid_argument, e.what());
    } catch (const NonFiniteError& e) {
      PyErr_SetString(non_finite, e.what());
    } catch (const NotPositiveDefiniteError& e) {
      PyErr_SetString(not_positive_definite, e.what());
    } catch (const TwinError& e) {
      PyErr_SetString(twin_error, e.what());
    } catch (const Error& e) {
      PyErr_SetString(error, e.what());
    }
  });
}

}  // namespace twincal::python
