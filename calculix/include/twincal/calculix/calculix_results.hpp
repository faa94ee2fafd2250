#pragma once
/// @file
/// Reading CalculiX's text results: the *NODE PRINT blocks of a .dat file.

#include <string_view>
#include <vector>

#include "twincal/core/eigen.hpp"

namespace twincal {

/// One *NODE PRINT block of displacements: the total time it was written at and, per node, its
/// displacement (vx, vy, vz) in mm.
struct NodePrint {
  double time = 0.0;
  std::vector<Index> nodes;
  std::vector<Vector<3>> displacements;
};

/// Every "displacements (vx,vy,vz) for set … and time …" block of `dat`, in file order (a
/// nonlinear step prints once per increment).
/// @throws CalculixError{unreadable_results} for a block line that is not "node vx vy vz".
[[nodiscard]] std::vector<NodePrint> read_displacement_prints(std::string_view dat);

/// The blocks written at the end of each release step — total time 2, 4, 6, … — in order,
/// stopping at the first release without one.
[[nodiscard]] std::vector<NodePrint> release_prints(const std::vector<NodePrint>& prints);

}  // namespace twincal
