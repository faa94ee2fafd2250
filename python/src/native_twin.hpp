#pragma once
/// @file
/// `NativeTwin`: a twin compiled into twincal — the open FEM sheet-metal twin (the paper's car
/// body and door) or the analytic RMS-quadratic twin — restricted to a locator set exactly as
/// `twincal run` restricts it (experiments' CaseTwin), bound to Python as `twincal.Twin`.
/// Python code calls it like any twin (quality_batch, optimum, bounds); a controller handed one
/// calls it directly, without Python in the loop (python_twin.hpp's fast path).
///
/// Assemblies are the twin's: an (upper, lower) pair of part indices, or an int indexing
/// `twin.assemblies`.

#include <memory>

#include <pybind11/pybind11.h>

#include "twincal/experiments/case_twin.hpp"
#include "twincal/models/assembly_id.hpp"

namespace twincal::python {

struct NativeTwin {
  std::shared_ptr<const CaseTwin> twin;

  /// The AssemblyId that `assembly` spells (with the GIL held).
  /// @throws InvalidArgumentError naming the value and the accepted forms.
  [[nodiscard]] AssemblyId assembly(pybind11::handle assembly) const;
};

}  // namespace twincal::python
