#pragma once
/// @file
/// `ContactSolver`: the linear complementarity problem (LCP) of frictionless node-to-node contact
/// in the method of influence coefficients (Dahlström & Lindkvist 2007): given the gaps g⁰ the
/// assembly would have without contact and the contact compliance C (C_kl = the change of gap k
/// under a unit pair force at contact l, symmetric positive semi-definite by Maxwell–Betti),
/// find the contact forces f with
///
///   f ≥ 0,   g = g⁰ + C f ≥ 0,   fᵀ g = 0
///
/// (a contact either carries a compressive force and is closed, or is open and force-free). For
/// symmetric positive semi-definite C this is the optimality system of the convex quadratic
/// program  min ½ fᵀCf + g⁰ᵀf  over f ≥ 0. Two active-set methods, both exact (each iteration
/// solves the closed contacts' equations C_PP f_P = −g⁰_P by Cholesky):
///
/// - `block_pivoting` (default): block principal pivoting (Júdice & Pires 1994; Kim & Park's
///   NNLS form). Close the contacts that penetrate without forces; solve; swap every infeasible
///   contact (closed with f_k < 0, or open with g_k < 0) between the sets while the number of
///   infeasible contacts falls (or for three more tries), otherwise swap only the last one
///   (Murty's rule, finite for positive definite C). Few iterations, however many contacts
///   close. If a closed set's block is not positive definite or p + 1 rounds pass, it hands
///   over to the active-set method (cold).
/// - `active_set`: the primal active-set method of Lawson & Hanson (1974, ch. 23, NNLS) for the
///   program. Start with every contact open; close the most penetrated one; solve (the factor
///   grows by one row); if a force would turn negative, step back to where the first reaches 0,
///   open it, refactor, solve again; repeat until no open contact penetrates. The objective
///   falls strictly from one closed set to the next, so no set repeats and it ends; each closed
///   block stays positive definite whenever the LCP has a solution, also for semi-definite C
///   (Lawson & Hanson's Lemma 23.17), so a breakdown means no solution (status `singular`).
///
/// Stopping rule (both): with τ = tolerance · max_k |g⁰_k|, every open contact has g_k ≥ −τ and
/// every closed one C_kk f_k ≥ −τ (forces scaled to a length); closed forces in [−τ/C_kk, 0) are
/// set to 0 and the gaps recomputed, so f ≥ 0 exactly. For positive definite C the solution is
/// unique; for semi-definite C the gaps g and the displacements C f are (forces may differ by a
/// null vector of C).
///
/// Both start cold on every call and their arithmetic depends only on (g⁰, C): the forces are a
/// deterministic function of the input, whichever thread, batch or call order computes them.
/// `solve` allocates nothing when given a `Workspace`.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/sheet_metal/contact_solver_error.hpp"

namespace twincal {

/// Which active-set method solves the LCP (see the file comment).
enum class ContactSolverMethod {
  block_pivoting,  ///< block principal pivoting, handing over to active_set when it stalls
  active_set,      ///< Lawson–Hanson primal active set only
};

struct ContactSolverOptions {
  ContactSolverMethod method = ContactSolverMethod::block_pivoting;
  /// The stopping rule's τ relative to the largest unloaded gap, τ = tolerance · max_k |g⁰_k|
  /// (so the rule does not depend on the unit of length).
  double tolerance = 1e-10;
  /// Most subproblem solves (both methods together) before ContactSolverError with status
  /// iteration_limit; 0 means 4 (p + 1) for p contacts (p + 1 rounds of block pivoting, then
  /// Lawson & Hanson's 3 (p + 1): one solve per closed contact and a few per reopened one).
  Index max_iterations = 0;

  [[nodiscard]] std::optional<std::string> validate() const;
};

class ContactSolver {
 public:
  /// Scratch for `solve`: the Cholesky factor of the closed contacts' compliance, their columns
  /// of C and the closed set, sized for p contacts (2p² + 4p numbers).
  class Workspace {
   public:
    explicit Workspace(Index size);
    [[nodiscard]] Index size() const noexcept { return is_closed_.size(); }

   private:
    friend class ContactSolver;
    MatrixX factor_;             // U, upper triangle: C_PP = UᵀU in the order of closed_
    MatrixX columns_;            // C_{:,P} in the order of closed_: the gaps are one product
    VectorX inverse_diagonal_;   // 1 / U_ii
    VectorX solution_;           // z, the subproblem's forces in the order of closed_
    std::vector<Index> closed_;  // P, in the order the contacts closed
    std::vector<Index> order_;   // P while the factor is rebuilt
    Eigen::Matrix<unsigned char, Eigen::Dynamic, 1> is_closed_;
  };

  /// Takes the contact compliance C (p × p, mm/N).
  /// @throws InvalidArgumentError for invalid options or a non-symmetric C (relative asymmetry
  ///         above 1e-10); DimensionMismatchError for a non-square C; NonFiniteError for a
  ///         non-finite entry; NotPositiveDefiniteError when C has a negative eigenvalue beyond
  ///         round-off.
  explicit ContactSolver(MatrixX compliance, const ContactSolverOptions& options = {});

  [[nodiscard]] Index size() const noexcept { return compliance_.rows(); }
  [[nodiscard]] const MatrixX& compliance() const noexcept { return compliance_; }
  [[nodiscard]] const ContactSolverOptions& options() const noexcept { return options_; }
  /// The subproblem-solve limit in force (max_iterations, or 4 (p + 1) when that is 0).
  [[nodiscard]] Index iteration_limit() const noexcept { return iteration_limit_; }

  /// Solves the LCP for the unloaded gaps g⁰: writes the forces f (N) and the gaps g = g⁰ + C f
  /// (mm). No allocation. The iteration count is the number of subproblem solves.
  /// @throws DimensionMismatchError for sizes other than p (the workspace too); NonFiniteError
  ///         for a non-finite gap; ContactSolverError (status iteration_limit or singular,
  ///         with the summary) when the method fails; `force` and `gap` are then unspecified.
  ContactSolverSummary solve(const Eigen::Ref<const VectorX>& unloaded_gap,
                             Eigen::Ref<VectorX> force, Eigen::Ref<VectorX> gap,
                             Workspace& workspace) const;
  /// The same with a workspace of its own.
  ContactSolverSummary solve(const Eigen::Ref<const VectorX>& unloaded_gap,
                             Eigen::Ref<VectorX> force, Eigen::Ref<VectorX> gap) const;

 private:
  // The two methods; `iterations` counts subproblem solves across both. block_pivoting returns
  // false when it hands over; active_set throws when it fails.
  bool block_pivoting(const Eigen::Ref<const VectorX>& unloaded_gap, Eigen::Ref<VectorX> force,
                      Eigen::Ref<VectorX> gap, Workspace& workspace, double threshold,
                      Index& iterations) const;
  void active_set(const Eigen::Ref<const VectorX>& unloaded_gap, Eigen::Ref<VectorX> force,
                  Eigen::Ref<VectorX> gap, Workspace& workspace, double threshold,
                  Index& iterations) const;
  // z.head(n) = C_PP⁻¹ (−g⁰_P) with the factor of the closed set.
  void solve_closed(const Eigen::Ref<const VectorX>& unloaded_gap, Workspace& workspace) const;
  // Factorizes the closed set order_ from scratch (blocked, in place); false when C_PP is not
  // positive definite to round-off.
  bool factorize(Workspace& workspace) const;
  // Adds contact j as the last column of the factor; false when the new pivot is not positive
  // (C_PP + j singular to round-off).
  bool append(Index j, Workspace& workspace) const;
  // Rebuilds the factor of the closed set in its current order; false as for append.
  bool refactor(Workspace& workspace) const;
  [[noreturn]] void fail(ContactSolverStatus status, const Eigen::Ref<const VectorX>& force,
                         const Eigen::Ref<const VectorX>& gap, Index iterations,
                         const Workspace& workspace, Index contact) const;
  [[nodiscard]] ContactSolverSummary summarize(const Eigen::Ref<const VectorX>& force,
                                               const Eigen::Ref<const VectorX>& gap,
                                               Index iterations) const;

  MatrixX compliance_;
  VectorX diagonal_;  // C_kk, read in every scan (a strided walk through C otherwise)
  ContactSolverOptions options_;
  Index iteration_limit_;
};

}  // namespace twincal
