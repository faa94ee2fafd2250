#include "twincal/sheet_metal/contact_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Cholesky>

#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

namespace {

// The compliance comes from separate FEM solves per contact; its asymmetry is solver round-off,
// far below this.
constexpr double symmetry_tolerance = 1e-10;

MatrixX validated(MatrixX compliance, const ContactSolverOptions& options) {
  require_valid("options", options);
  require_square("compliance", compliance);
  require_finite("compliance", compliance);
  if (compliance.size() == 0) return compliance;  // no contacts: nothing to check
  require_positive_definite("compliance", compliance, /*allow_semidefinite=*/true,
                            symmetry_tolerance);
  return compliance;
}

}  // namespace

std::optional<std::string> ContactSolverOptions::validate() const {
  return first_problem({rule::in_open("tolerance", tolerance, 0.0, 1.0),
                        rule::check(max_iterations >= 0, "max_iterations", max_iterations,
                                    "must be >= 0 (0: 4 (p + 1))")});
}

ContactSolver::Workspace::Workspace(Index size)
    : factor_((require_non_negative("size", static_cast<double>(size)), size), size),
      columns_(size, size),
      inverse_diagonal_(size),
      solution_(size),
      is_closed_(Eigen::Matrix<unsigned char, Eigen::Dynamic, 1>::Zero(size)) {
  closed_.reserve(static_cast<std::size_t>(size));
  order_.reserve(static_cast<std::size_t>(size));
}

ContactSolver::ContactSolver(MatrixX compliance, const ContactSolverOptions& options)
    : compliance_(validated(std::move(compliance), options)),
      diagonal_(compliance_.diagonal()),
      options_(options),
      iteration_limit_(options.max_iterations > 0 ? options.max_iterations
                                                  : 4 * (compliance_.rows() + 1)) {}

bool ContactSolver::append(Index j, Workspace& workspace) const {
  const auto n = static_cast<Index>(workspace.closed_.size());
  MatrixX& factor = workspace.factor_;
  // Column n of U: u = U⁻ᵀ C_Pj by forward substitution on U's contiguous columns (a plain
  // loop: at these sizes a library triangular solve costs more in dispatch than in flops),
  // pivot² = C_jj − uᵀu.
  for (Index i = 0; i < n; ++i) {
    const double entry = compliance_(workspace.closed_[static_cast<std::size_t>(i)], j);
    factor(i, n) =
        (entry - factor.col(i).head(i).dot(factor.col(n).head(i))) * workspace.inverse_diagonal_(i);
  }
  const double pivot = diagonal_(j) - factor.col(n).head(n).squaredNorm();
  // A pivot at round-off level of C_jj means contact j's compliance is (numerically) a
  // combination of the closed ones: C_PP + j is singular.
  const double round_off =
      16.0 * static_cast<double>(n + 1) * std::numeric_limits<double>::epsilon() * diagonal_(j);
  if (!(pivot > round_off)) return false;
  factor(n, n) = std::sqrt(pivot);
  // The substitutions multiply by 1/U_ii: a division on their serial dependency chain costs
  // several times a multiplication.
  workspace.inverse_diagonal_(n) = 1.0 / factor(n, n);
  workspace.columns_.col(n) = compliance_.col(j);
  workspace.closed_.push_back(j);
  workspace.is_closed_(j) = 1;
  return true;
}

bool ContactSolver::factorize(Workspace& workspace) const {
  const auto n = static_cast<Index>(workspace.order_.size());
  MatrixX& factor = workspace.factor_;
  for (Index j = 0; j < n; ++j) {
    const Index column = workspace.order_[static_cast<std::size_t>(j)];
    workspace.columns_.col(j) = compliance_.col(column);
    for (Index i = 0; i <= j; ++i) {
      factor(i, j) = workspace.columns_(workspace.order_[static_cast<std::size_t>(i)], j);
    }
  }
  // Eigen's blocked Cholesky in place on the upper triangle (U with C_PP = UᵀU, the layout
  // append() extends): one pass at throughput, where appending column by column waits on each
  // substitution's serial chain.
  Eigen::Ref<MatrixX> block = factor.topLeftCorner(n, n);
  const Eigen::LLT<Eigen::Ref<MatrixX>, Eigen::Upper> cholesky(block);
  if (cholesky.info() != Eigen::Success) return false;
  for (Index j = 0; j < n; ++j) {
    const double round_off = 16.0 * static_cast<double>(j + 1) *
                             std::numeric_limits<double>::epsilon() *
                             diagonal_(workspace.order_[static_cast<std::size_t>(j)]);
    if (!(factor(j, j) * factor(j, j) > round_off)) return false;
    workspace.inverse_diagonal_(j) = 1.0 / factor(j, j);
  }
  workspace.closed_.assign(workspace.order_.begin(), workspace.order_.end());
  return true;
}

bool ContactSolver::refactor(Workspace& workspace) const {
  // Re-append the closed contacts in their order; both vectors keep their capacity (p), so
  // nothing is allocated.
  workspace.order_.assign(workspace.closed_.begin(), workspace.closed_.end());
  for (const Index k : workspace.order_) workspace.is_closed_(k) = 0;
  workspace.closed_.clear();
  for (const Index k : workspace.order_) {
    if (!append(k, workspace)) return false;
  }
  return true;
}

ContactSolverSummary ContactSolver::summarize(const Eigen::Ref<const VectorX>& force,
                                              const Eigen::Ref<const VectorX>& gap,
                                              Index iterations) const {
  ContactSolverSummary summary;
  summary.iterations = iterations;
  double residual = 0.0;
  double product = 0.0;
  for (Index k = 0; k < size(); ++k) {
    summary.closed += force(k) > 0.0 ? 1 : 0;
    residual = std::max(residual, std::abs(std::min(diagonal_(k) * force(k), gap(k))));
    product += force(k) * gap(k);
  }
  summary.residual = residual;
  summary.complementarity = std::abs(product);
  return summary;
}

void ContactSolver::fail(ContactSolverStatus status, const Eigen::Ref<const VectorX>& force,
                         const Eigen::Ref<const VectorX>& gap, Index iterations,
                         const Workspace& workspace, Index contact) const {
  ContactSolverSummary summary = summarize(force, gap, iterations);
  summary.closed = static_cast<Index>(workspace.closed_.size());
  summary.status = status;
  if (status == ContactSolverStatus::iteration_limit) {
    throw ContactSolverError(
        "contact",
        fmt::format("contact: {} subproblem solves reached with {} contacts closed and natural "
                    "residual {:.3g} mm; rule: must solve within the iteration limit {} "
                    "(ContactSolverOptions::max_iterations)",
                    iterations, summary.closed, summary.residual, iteration_limit_),
        summary);
  }
  throw ContactSolverError(
      "compliance",
      fmt::format("compliance: closing contact {} (gap {:.6g} mm) with {} contacts closed makes "
                  "the closed contacts' compliance singular; rule: the contact problem must have "
                  "a solution (a contact that cannot move must not be pressed into penetration)",
                  contact, gap(contact), summary.closed),
      summary);
}

void ContactSolver::solve_closed(const Eigen::Ref<const VectorX>& unloaded_gap,
                                 Workspace& workspace) const {
  const auto n = static_cast<Index>(workspace.closed_.size());
  const MatrixX& factor = workspace.factor_;
  VectorX& z = workspace.solution_;
  // C_PP z = −g⁰_P as Uᵀ y = −g⁰_P (forward, dot products down U's columns), then U z = y
  // (backward, one column update per step): both touch U only by contiguous columns.
  for (Index i = 0; i < n; ++i) {
    const double rhs = -unloaded_gap(workspace.closed_[static_cast<std::size_t>(i)]);
    z(i) = (rhs - factor.col(i).head(i).dot(z.head(i))) * workspace.inverse_diagonal_(i);
  }
  for (Index i = n - 1; i >= 0; --i) {
    z(i) *= workspace.inverse_diagonal_(i);
    z.head(i) -= z(i) * factor.col(i).head(i);
  }
}

bool ContactSolver::block_pivoting(const Eigen::Ref<const VectorX>& unloaded_gap,
                                   Eigen::Ref<VectorX> force, Eigen::Ref<VectorX> gap,
                                   Workspace& workspace, double threshold,
                                   Index& iterations) const {
  const Index p = size();
  VectorX& z = workspace.solution_;
  // Start with the contacts that penetrate without forces closed.
  for (Index k = 0; k < p; ++k) workspace.is_closed_(k) = unloaded_gap(k) < threshold ? 1 : 0;
  Index fewest = p + 1;  // the smallest infeasible count so far
  int backups = 3;       // full swaps allowed without progress (Júdice & Pires)
  workspace.closed_.clear();
  for (Index round = 0; round <= p; ++round) {
    // The new closed set, ascending. U's column i depends only on the first i + 1 closed
    // contacts, so the columns of the prefix the new set shares with the old one stay valid:
    // only the rest is appended again.
    workspace.order_.clear();
    for (Index k = 0; k < p; ++k) {
      if (workspace.is_closed_(k) != 0) workspace.order_.push_back(k);
    }
    std::size_t common = 0;
    while (common < workspace.closed_.size() && common < workspace.order_.size() &&
           workspace.closed_[common] == workspace.order_[common]) {
      ++common;
    }
    workspace.closed_.resize(common);
    const auto n = static_cast<Index>(workspace.order_.size());
    gap = unloaded_gap;
    if (n > 0) {
      if (iterations >= iteration_limit_) return false;
      // A fresh set in one blocked factorization, a changed tail by appending.
      if (common == 0) {
        if (!factorize(workspace)) return false;
      } else {
        for (std::size_t i = common; i < workspace.order_.size(); ++i) {
          if (!append(workspace.order_[i], workspace)) return false;
        }
      }
      ++iterations;
      solve_closed(unloaded_gap, workspace);
      gap.noalias() += workspace.columns_.leftCols(n) * z.head(n);
    }
    // The infeasible contacts: closed with a pulling force, open with a penetration (forces
    // scaled by C_kk to a length, so one threshold serves both).
    Index infeasible = 0;
    Index last = -1;
    std::size_t position = 0;
    for (Index k = 0; k < p; ++k) {
      const bool closed = workspace.is_closed_(k) != 0;
      const bool bad =
          closed ? diagonal_(k) * z(static_cast<Index>(position)) < threshold : gap(k) < threshold;
      position += closed ? 1 : 0;
      if (bad) {
        ++infeasible;
        last = k;
      }
    }
    if (infeasible == 0) {
      // Forces within the tolerance below 0 become 0; the gaps follow them.
      bool clamped = false;
      force.setZero();
      for (Index i = 0; i < n; ++i) {
        clamped = clamped || z(i) < 0.0;
        z(i) = std::max(z(i), 0.0);
        force(workspace.closed_[static_cast<std::size_t>(i)]) = z(i);
      }
      if (clamped) {
        gap = unloaded_gap;
        gap.noalias() += workspace.columns_.leftCols(n) * z.head(n);
      }
      return true;
    }
    // Swap every infeasible contact while that makes progress (or for three more tries), else
    // only the last one (Murty's rule, which cannot cycle).
    const bool swap_all = infeasible < fewest || backups > 0;
    if (infeasible < fewest) {
      fewest = infeasible;
      backups = 3;
    } else if (backups > 0) {
      --backups;
    }
    position = 0;
    for (Index k = 0; k < p; ++k) {
      const bool closed = workspace.is_closed_(k) != 0;
      const bool bad =
          closed ? diagonal_(k) * z(static_cast<Index>(position)) < threshold : gap(k) < threshold;
      position += closed ? 1 : 0;
      if (bad && (swap_all || k == last)) workspace.is_closed_(k) = closed ? 0 : 1;
    }
  }
  return false;
}

void ContactSolver::active_set(const Eigen::Ref<const VectorX>& unloaded_gap,
                               Eigen::Ref<VectorX> force, Eigen::Ref<VectorX> gap,
                               Workspace& workspace, double threshold, Index& iterations) const {
  const Index p = size();
  force.setZero();
  gap = unloaded_gap;
  workspace.closed_.clear();
  workspace.is_closed_.setZero();
  VectorX& z = workspace.solution_;
  while (true) {
    // Step 2: the most penetrated open contact, or stop.
    Index entering = -1;
    double most = threshold;
    for (Index k = 0; k < p; ++k) {
      if (workspace.is_closed_(k) == 0 && gap(k) < most) {
        most = gap(k);
        entering = k;
      }
    }
    if (entering < 0) return;
    if (!append(entering, workspace)) {
      fail(ContactSolverStatus::singular, force, gap, iterations, workspace, entering);
    }

    // Step 3: the subproblem on the closed set, stepping back while a force would turn negative.
    bool first_pass = true;
    while (true) {
      if (iterations >= iteration_limit_) {
        fail(ContactSolverStatus::iteration_limit, force, gap, iterations, workspace, entering);
      }
      ++iterations;
      const auto n = static_cast<Index>(workspace.closed_.size());
      solve_closed(unloaded_gap, workspace);
      if (z.head(n).minCoeff() > 0.0) {
        for (Index i = 0; i < n; ++i) force(workspace.closed_[static_cast<std::size_t>(i)]) = z(i);
        break;
      }
      // The contact just closed must carry a positive force (its gap was negative and C_PP is
      // positive definite); z_j <= 0 on the first pass means round-off decided: stop rather than
      // cycle.
      if (first_pass && z(n - 1) <= 0.0) {
        fail(ContactSolverStatus::singular, force, gap, iterations, workspace, entering);
      }
      first_pass = false;
      // The largest step α ∈ [0, 1) from f towards z that keeps every force >= 0; every closed
      // force is > 0 here, so α > 0 and the objective falls.
      double alpha = 1.0;
      Index blocking = -1;
      for (Index i = 0; i < n; ++i) {
        if (z(i) <= 0.0) {
          const double f = force(workspace.closed_[static_cast<std::size_t>(i)]);
          const double step = f / (f - z(i));
          if (step < alpha) {
            alpha = step;
            blocking = i;
          }
        }
      }
      std::size_t kept = 0;
      for (Index i = 0; i < n; ++i) {
        const Index k = workspace.closed_[static_cast<std::size_t>(i)];
        const double f = force(k) + alpha * (z(i) - force(k));
        // The blocking contact lands on 0 (exactly, not up to round-off); others that reach 0
        // in the same step open with it.
        if (i == blocking || f <= 0.0) {
          force(k) = 0.0;
          workspace.is_closed_(k) = 0;
        } else {
          force(k) = f;
          workspace.closed_[kept++] = k;
        }
      }
      workspace.closed_.resize(kept);
      if (!refactor(workspace)) {
        fail(ContactSolverStatus::singular, force, gap, iterations, workspace, entering);
      }
      if (kept == 0) break;
    }
    // g = g⁰ + C_P f_P, one matrix-vector product (z holds f_P in the order of the columns
    // after a successful solve; nothing is closed otherwise).
    const auto n = static_cast<Index>(workspace.closed_.size());
    gap = unloaded_gap;
    if (n > 0) gap.noalias() += workspace.columns_.leftCols(n) * z.head(n);
  }
}

ContactSolverSummary ContactSolver::solve(const Eigen::Ref<const VectorX>& unloaded_gap,
                                          Eigen::Ref<VectorX> force, Eigen::Ref<VectorX> gap,
                                          Workspace& workspace) const {
  const Index p = size();
  require_dimension("unloaded_gap", unloaded_gap.size(), p);
  require_dimension("force", force.size(), p);
  require_dimension("gap", gap.size(), p);
  require_dimension("workspace", workspace.size(), p);
  require_finite("unloaded_gap", unloaded_gap);

  const double scale = p > 0 ? unloaded_gap.cwiseAbs().maxCoeff() : 0.0;
  const double threshold = -options_.tolerance * scale;
  Index iterations = 0;
  const bool solved = options_.method == ContactSolverMethod::block_pivoting &&
                      block_pivoting(unloaded_gap, force, gap, workspace, threshold, iterations);
  if (!solved) active_set(unloaded_gap, force, gap, workspace, threshold, iterations);
  return summarize(force, gap, iterations);
}

ContactSolverSummary ContactSolver::solve(const Eigen::Ref<const VectorX>& unloaded_gap,
                                          Eigen::Ref<VectorX> force,
                                          Eigen::Ref<VectorX> gap) const {
  Workspace workspace(size());
  return solve(unloaded_gap, force, gap, workspace);
}

}  // namespace twincal
