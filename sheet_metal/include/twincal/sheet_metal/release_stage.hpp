#pragma once
/// @file
/// `ReleaseStage`: stage 3 of `SheetMetalProcess` (the welded assembly released from clamps and
/// guns onto its final supports) as a solver that also takes nodal loads — what contact needs.
/// In the method of influence coefficients with contact (Dahlström & Lindkvist 2007) the contact
/// forces act on the released assembly: its state is e3 + Σ_k f_k r_k, with r_k the response of
/// the welded, supported assembly to a unit pair of opposite forces at contact k (zero constraint
/// values: the welds keep what they were formed with, the supports stay). One solve per contact,
/// once per twin, gives the contact compliance and the key points' response.
///
/// The process keeps its own stage-3 factorization private, so this class factorizes the same
/// constraint set again (weld ties of the layout's `WeldTie` components, then the final supports
/// per `FinalSupport`, the order SheetMetalProcess uses). The test pins the two together:
/// released_state() here equals SheetMetalProcess::released_state().

#include <vector>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/sheet_metal/constrained_solver.hpp"
#include "twincal/sheet_metal/sheet_metal_process.hpp"

namespace twincal {

class ReleaseStage {
 public:
  /// Builds and factorizes the release constraints of `process` (which must outlive this object
  /// only for released_state(); response() needs nothing from it).
  explicit ReleaseStage(const SheetMetalProcess& process);

  /// Stacked dofs (upper part first).
  [[nodiscard]] Index dof_count() const noexcept { return solver_.dof_count(); }
  /// The elastic displacement change under nodal `load` (stacked dofs, N and N mm) with the welds
  /// and supports held: the release stage's influence of a load.
  /// @throws DimensionMismatchError for a wrong size.
  [[nodiscard]] VectorX response(const Eigen::Ref<const VectorX>& load) const;
  /// Whether stacked dof `dof` is prescribed in this stage (a final support or, on adjusted
  /// locators, a locator): a load there goes into the support's reaction.
  [[nodiscard]] bool prescribed(Index dof) const;
  /// e3 of `process` computed with this stage's factorization (for the consistency check and
  /// for full fields with contact forces added).
  /// @throws DimensionMismatchError for wrong sizes.
  [[nodiscard]] VectorX released_state(const SheetMetalProcess& process,
                                       const Eigen::Ref<const VectorX>& upper_free,
                                       const Eigen::Ref<const VectorX>& lower_free,
                                       const Eigen::Ref<const VectorX>& control) const;

 private:
  ConstrainedSolver solver_;
  std::vector<Index> tied_components_;
  std::vector<bool> prescribed_;
};

}  // namespace twincal
