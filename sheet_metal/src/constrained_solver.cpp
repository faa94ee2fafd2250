#include "twincal/sheet_metal/constrained_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

ConstrainedSolver::ConstrainedSolver(const SparseMatrix& stiffness,
                                     std::vector<LinearConstraint> constraints)
    : dof_count_(stiffness.rows()), constraints_(std::move(constraints)) {
  require_square("stiffness", stiffness);
  const auto n = static_cast<std::size_t>(dof_count_);
  std::vector<Index> master_of(n, -2);  // −2: free, −1: prescribed, >= 0: tied to that dof
  for (std::size_t k = 0; k < constraints_.size(); ++k) {
    const LinearConstraint& c = constraints_[k];
    if (c.slave < 0 || c.slave >= dof_count_ || c.master < -1 || c.master >= dof_count_) {
      throw InvalidArgumentError(
          "constraints", fmt::format("constraints: entry {} has slave {} and master {}; rule: "
                                     "dofs must lie in [0, {}) (master −1 = prescribed)",
                                     k, c.slave, c.master, dof_count_));
    }
    if (master_of[static_cast<std::size_t>(c.slave)] != -2) {
      throw InvalidArgumentError("constraints",
                                 fmt::format("constraints: dof {} is the slave of two constraints "
                                             "(entry {}); rule: each dof may be constrained once",
                                             c.slave, k));
    }
    master_of[static_cast<std::size_t>(c.slave)] = c.master;
  }
  for (std::size_t k = 0; k < constraints_.size(); ++k) {
    const LinearConstraint& c = constraints_[k];
    if (c.master >= 0 && master_of[static_cast<std::size_t>(c.master)] != -2) {
      throw InvalidArgumentError(
          "constraints",
          fmt::format("constraints: entry {} ties dof {} to dof {}, which is constrained "
                      "itself; rule: a master must be a free dof",
                      k, c.slave, c.master));
    }
  }

  reduced_index_.assign(n, -1);
  Index free_count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (master_of[i] == -2) reduced_index_[i] = free_count++;
  }
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto row = static_cast<Index>(i);
    if (master_of[i] == -2) {
      triplets.emplace_back(row, reduced_index_[i], 1.0);
    } else if (master_of[i] >= 0) {
      triplets.emplace_back(row, reduced_index_[static_cast<std::size_t>(master_of[i])], 1.0);
    }
  }
  transform_.resize(dof_count_, free_count);
  transform_.setFromTriplets(triplets.begin(), triplets.end());
  stiffness_ = stiffness;

  const SparseMatrix reduced = transform_.transpose() * stiffness_ * transform_;
  factorization_.compute(reduced);
  // Scalar loop: GCC 12 warns (null dereference) on Eigen reductions of a possibly empty vector.
  const VectorX pivots = factorization_.vectorD();
  double largest = 0.0;
  double smallest = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < pivots.size(); ++i) {
    largest = std::max(largest, std::abs(pivots(i)));
    smallest = std::min(smallest, pivots(i));
  }
  if (factorization_.info() != Eigen::Success || !(smallest > 1e-9 * largest)) {
    throw InvalidArgumentError(
        "constraints",
        fmt::format("constraints: leave a mechanism (smallest/largest pivot {:.3g}); rule: must "
                    "remove every zero-energy mode of the structure",
                    smallest / largest));
  }
}

VectorX ConstrainedSolver::solve(const Eigen::Ref<const VectorX>& values) const {
  return solve(values, VectorX::Zero(dof_count_));
}

VectorX ConstrainedSolver::solve(const Eigen::Ref<const VectorX>& values,
                                 const Eigen::Ref<const VectorX>& load) const {
  require_dimension("values", values.size(), constraint_count());
  require_dimension("load", load.size(), dof_count_);
  // t: the constrained part of e, with every free dof (and every master) at zero.
  VectorX offset = VectorX::Zero(dof_count_);
  for (std::size_t k = 0; k < constraints_.size(); ++k) {
    offset(constraints_[k].slave) = values(static_cast<Index>(k));
  }
  const VectorX rhs = transform_.transpose() * (load - stiffness_ * offset);
  const VectorX reduced = factorization_.solve(rhs);
  VectorX full = transform_ * reduced;
  full += offset;
  return full;
}

}  // namespace twincal
