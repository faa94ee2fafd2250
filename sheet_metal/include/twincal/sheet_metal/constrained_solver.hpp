#pragma once
/// @file
/// `ConstrainedSolver`: minimizes ½ eᵀ K e − eᵀ F subject to linear constraints of the two kinds
/// a fixture and a weld impose, by eliminating one "slave" dof per constraint:
///   - prescribed:  e[slave] = value                (a locator, clamp, support, gun)
///   - tie:         e[slave] − e[master] = value    (a weld joining two parts' dofs)
/// so e = T r + t(values) with r the free dofs, and Tᵀ K T r = Tᵀ (F − K t) is symmetric positive
/// definite once the constraints remove every zero-energy mode. The factorization (sparse
/// Cholesky, SimplicialLDLT) depends on which dofs are constrained, not on the values, so one
/// factorization serves every right-hand side (the method of influence coefficients).

#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "twincal/core/eigen.hpp"

namespace twincal {

/// One constraint: e[slave] − (master >= 0 ? e[master] : 0) = value.
struct LinearConstraint {
  Index slave = 0;
  Index master = -1;  ///< −1: prescribed value; otherwise the tied dof
};

class ConstrainedSolver {
 public:
  using SparseMatrix = Eigen::SparseMatrix<double>;

  /// Factorizes the reduced system.
  /// @throws DimensionMismatchError when K is not square; InvalidArgumentError when a dof is out
  ///         of range, a dof is the slave of two constraints, a master is itself a slave, or the
  ///         constrained system keeps a zero-energy mode ("constraints: leave a mechanism").
  ConstrainedSolver(const SparseMatrix& stiffness, std::vector<LinearConstraint> constraints);

  [[nodiscard]] Index dof_count() const noexcept { return dof_count_; }
  [[nodiscard]] Index constraint_count() const noexcept {
    return static_cast<Index>(constraints_.size());
  }
  [[nodiscard]] const std::vector<LinearConstraint>& constraints() const noexcept {
    return constraints_;
  }

  /// The minimizer e for constraint values `values` (one per constraint) and no load.
  /// @throws DimensionMismatchError for a wrong size.
  [[nodiscard]] VectorX solve(const Eigen::Ref<const VectorX>& values) const;
  /// The minimizer e for constraint values `values` and nodal loads `load`.
  [[nodiscard]] VectorX solve(const Eigen::Ref<const VectorX>& values,
                              const Eigen::Ref<const VectorX>& load) const;

 private:
  Index dof_count_;
  std::vector<LinearConstraint> constraints_;
  std::vector<Index> reduced_index_;  // dof → free index, or −1 for a slave
  SparseMatrix stiffness_;            // K, kept for the right-hand side −Tᵀ K t
  SparseMatrix transform_;            // T: full = T r + t
  Eigen::SimplicialLDLT<SparseMatrix> factorization_;
};

}  // namespace twincal
