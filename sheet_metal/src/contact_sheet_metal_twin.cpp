#include "twincal/sheet_metal/contact_sheet_metal_twin.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/sheet_metal/plate_mesh.hpp"
#include "twincal/sheet_metal/release_stage.hpp"
#include "twincal/sheet_metal/sheet_metal_process.hpp"

namespace twincal {

std::optional<std::string> ContactSheetMetalTwinOptions::validate() const {
  return first_problem({rule::check(std::isfinite(nominal_gap) && nominal_gap >= 0.0, "nominal_gap",
                                    nominal_gap, "must be finite and >= 0 (mm)"),
                        rule::nested("solver", solver)});
}

struct ContactSheetMetalTwin::Precomputed {
  SheetMetalTwin linear;
  ContactSheetMetalTwinOptions options;
  std::vector<ContactPair> pairs;
  std::shared_ptr<const ReleaseStage> release;
  MatrixX compliance;
  MatrixX key_response;
  MatrixX gap_influence;
  MatrixX deviation;
  MatrixX gap;

  static Precomputed compute(SheetMetalTwin linear, const ContactSheetMetalTwinOptions& options);
};

struct ContactSheetMetalTwin::Scratch {
  Scratch(Index m, Index p) : deviation(m), unloaded_gap(p), force(p), gap(p), workspace(p) {}
  VectorX deviation;     // y
  VectorX unloaded_gap;  // g⁰
  VectorX force;         // f
  VectorX gap;           // g
  ContactSolver::Workspace workspace;
  ContactSolverSummary summary;
};

namespace {

// Stacked dofs of w at each pair's upper and lower node, and at the key points.
struct PairDofs {
  std::vector<Index> upper;
  std::vector<Index> lower;
};

PairDofs pair_dofs(const SheetMetalProcess& process, const std::vector<ContactPair>& pairs) {
  PairDofs dofs;
  for (const ContactPair& pair : pairs) {
    dofs.upper.push_back(
        process.global_dof(SheetMetalPart::upper, PlateMesh::dof(pair.upper_node, 0)));
    dofs.lower.push_back(
        process.global_dof(SheetMetalPart::lower, PlateMesh::dof(pair.lower_node, 0)));
  }
  return dofs;
}

// (w_U − w_L) at every pair for the elastic state e over the free shapes (f_U, f_L).
VectorX relative_normal(const std::vector<ContactPair>& pairs, const PairDofs& dofs,
                        const VectorX& elastic, const VectorX& upper_free,
                        const VectorX& lower_free) {
  VectorX difference(static_cast<Index>(pairs.size()));
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const double upper =
        upper_free(PlateMesh::dof(pairs[k].upper_node, 0)) + elastic(dofs.upper[k]);
    const double lower =
        lower_free(PlateMesh::dof(pairs[k].lower_node, 0)) + elastic(dofs.lower[k]);
    difference(static_cast<Index>(k)) = upper - lower;
  }
  return difference;
}

}  // namespace

ContactSheetMetalTwin::Precomputed ContactSheetMetalTwin::Precomputed::compute(
    SheetMetalTwin linear, const ContactSheetMetalTwinOptions& options) {
  require_valid("options", options);
  const SheetMetalProcess& process = linear.process();
  auto release = std::make_shared<const ReleaseStage>(process);
  std::vector<ContactPair> pairs = flange_contact_pairs(process.layout());
  // A pair whose two nodes are both held by final supports cannot move: it has no compliance
  // and would make the contact problem unsolvable whenever its gap is negative.
  std::erase_if(pairs, [&](const ContactPair& pair) {
    return release->prescribed(
               process.global_dof(SheetMetalPart::upper, PlateMesh::dof(pair.upper_node, 0))) &&
           release->prescribed(
               process.global_dof(SheetMetalPart::lower, PlateMesh::dof(pair.lower_node, 0)));
  });
  if (pairs.empty()) {
    throw InvalidArgumentError(
        "layout", fmt::format("layout: '{}' has no contact pairs; rule: the parts' overlap must "
                              "have nodes other than the welds",
                              process.layout().name));
  }
  const auto p = static_cast<Index>(pairs.size());
  const Index m = process.key_point_count();
  const Index d = process.control_dimension();
  const PairDofs dofs = pair_dofs(process, pairs);
  std::vector<Index> key_dofs;
  for (std::size_t i = 0; i < process.key_nodes().size(); ++i) {
    key_dofs.push_back(process.global_dof(process.layout().key_points[i].part,
                                          PlateMesh::dof(process.key_nodes()[i], 0)));
  }

  // C and K: one release solve per unit pair force (+1 on the upper node, −1 on the lower).
  MatrixX compliance(p, p);
  MatrixX key_response(m, p);
  VectorX load = VectorX::Zero(release->dof_count());
  for (Index l = 0; l < p; ++l) {
    const auto pl = static_cast<std::size_t>(l);
    load(dofs.upper[pl]) = 1.0;
    load(dofs.lower[pl]) = -1.0;
    const VectorX response = release->response(load);
    load(dofs.upper[pl]) = 0.0;
    load(dofs.lower[pl]) = 0.0;
    for (Index k = 0; k < p; ++k) {
      const auto pk = static_cast<std::size_t>(k);
      compliance(k, l) = response(dofs.upper[pk]) - response(dofs.lower[pk]);
    }
    for (Index i = 0; i < m; ++i)
      key_response(i, l) = response(key_dofs[static_cast<std::size_t>(i)]);
  }
  // Maxwell–Betti makes C symmetric; the separate solves leave round-off asymmetry.
  MatrixX symmetric = 0.5 * (compliance + compliance.transpose());

  // The gap maps: each part alone (the other nominal), each locator alone.
  const VectorX upper_nominal = VectorX::Zero(process.dof_count(SheetMetalPart::upper));
  const VectorX lower_nominal = VectorX::Zero(process.dof_count(SheetMetalPart::lower));
  const VectorX zero_control = VectorX::Zero(d);
  // The released gaps of the upper shape `upper` on the lower shape `lower`, at u = 0.
  const auto gaps = [&](const VectorX& upper, const VectorX& lower) -> VectorX {
    return relative_normal(pairs, dofs, process.released_state(upper, lower, zero_control), upper,
                           lower);
  };
  MatrixX upper_gap(p, linear.upper_part_count());
  for (Index i = 0; i < linear.upper_part_count(); ++i) {
    upper_gap.col(i) = gaps(linear.upper_part(i), lower_nominal);
  }
  MatrixX lower_gap(p, linear.lower_part_count());
  for (Index j = 0; j < linear.lower_part_count(); ++j) {
    lower_gap.col(j) = gaps(upper_nominal, linear.lower_part(j));
  }
  MatrixX gap_influence(p, d);
  for (Index k = 0; k < d; ++k) {
    gap_influence.col(k) = relative_normal(
        pairs, dofs, process.released_state(upper_nominal, lower_nominal, VectorX::Unit(d, k)),
        upper_nominal, lower_nominal);
  }

  const Index n = linear.upper_part_count() * linear.lower_part_count();
  MatrixX deviation(m, n);
  MatrixX gap(p, n);
  for (Index i = 0; i < linear.upper_part_count(); ++i) {
    for (Index j = 0; j < linear.lower_part_count(); ++j) {
      const Index c = i * linear.lower_part_count() + j;
      deviation.col(c) = linear.key_deviation({i, j}, zero_control);
      gap.col(c) = upper_gap.col(i) + lower_gap.col(j);
      gap.col(c).array() += options.nominal_gap;
    }
  }
  return {std::move(linear),
          options,
          std::move(pairs),
          std::move(release),
          std::move(symmetric),
          std::move(key_response),
          std::move(gap_influence),
          std::move(deviation),
          std::move(gap)};
}

ContactSheetMetalTwin::ContactSheetMetalTwin(SheetMetalTwin linear,
                                             const ContactSheetMetalTwinOptions& options)
    : ContactSheetMetalTwin(Precomputed::compute(std::move(linear), options)) {}

ContactSheetMetalTwin::ContactSheetMetalTwin(Precomputed&& precomputed)
    : linear_(std::move(precomputed.linear)),
      options_(precomputed.options),
      pairs_(std::move(precomputed.pairs)),
      release_(std::move(precomputed.release)),
      solver_(std::move(precomputed.compliance), precomputed.options.solver),
      key_response_(std::move(precomputed.key_response)),
      gap_influence_(std::move(precomputed.gap_influence)),
      deviation_(std::move(precomputed.deviation)),
      gap_(std::move(precomputed.gap)) {}

ContactSheetMetalTwin ContactSheetMetalTwin::make(SheetMetalCase which, std::uint64_t seed) {
  return ContactSheetMetalTwin(SheetMetalTwin::make(which, seed));
}

ContactSheetMetalTwin ContactSheetMetalTwin::body(std::uint64_t seed) {
  return make(SheetMetalCase::body, seed);
}

ContactSheetMetalTwin ContactSheetMetalTwin::door(std::uint64_t seed) {
  return make(SheetMetalCase::door, seed);
}

Index ContactSheetMetalTwin::column(const AssemblyId& assembly) const {
  const Index uppers = linear_.upper_part_count();
  const Index lowers = linear_.lower_part_count();
  if (assembly.upper < 0 || assembly.upper >= uppers || assembly.lower < 0 ||
      assembly.lower >= lowers) {
    throw InvalidArgumentError(
        "assembly", fmt::format("assembly: value is {}; rule: upper must lie in [0, {}) and "
                                "lower in [0, {})",
                                assembly, uppers, lowers));
  }
  return assembly.upper * lowers + assembly.lower;
}

double ContactSheetMetalTwin::evaluate(Index c, const Eigen::Ref<const VectorX>& control,
                                       Scratch& scratch) const {
  scratch.deviation = deviation_.col(c);
  scratch.deviation.noalias() += linear_.influence() * control;
  scratch.unloaded_gap = gap_.col(c);
  scratch.unloaded_gap.noalias() += gap_influence_ * control;
  scratch.summary =
      solver_.solve(scratch.unloaded_gap, scratch.force, scratch.gap, scratch.workspace);
  for (Index k = 0; k < pair_count(); ++k) {
    if (scratch.force(k) != 0.0) scratch.deviation += key_response_.col(k) * scratch.force(k);
  }
  return std::sqrt(scratch.deviation.squaredNorm() / static_cast<double>(scratch.deviation.size()));
}

double ContactSheetMetalTwin::quality(const AssemblyId& assembly,
                                      const Eigen::Ref<const VectorX>& control) const {
  require_control(control, control_dimension());
  require_finite("control", control);
  const Index c = column(assembly);
  // One scratch per thread, rebuilt only when a twin of another size runs on the thread: single
  // calls (an optimizer's) then allocate nothing.
  thread_local std::unique_ptr<Scratch> scratch;
  const Index m = key_response_.rows();
  if (!scratch || scratch->deviation.size() != m || scratch->force.size() != pair_count()) {
    scratch = std::make_unique<Scratch>(m, pair_count());
  }
  return evaluate(c, control, *scratch);
}

void ContactSheetMetalTwin::quality_batch(const AssemblyId& assembly,
                                          const Eigen::Ref<const MatrixX>& controls,
                                          Eigen::Ref<VectorX> out) const {
  require_control_batch(controls, out, control_dimension());
  require_finite("controls", controls);
  const Index c = column(assembly);
  Scratch scratch(key_response_.rows(), pair_count());
  for (Index j = 0; j < controls.cols(); ++j) out(j) = evaluate(c, controls.col(j), scratch);
}

void ContactSheetMetalTwin::deviations_batch(const AssemblyId& assembly,
                                             const Eigen::Ref<const MatrixX>& controls,
                                             Eigen::Ref<MatrixX> out) const {
  require_deviations_batch(controls, out, control_dimension(), key_point_count());
  require_finite("controls", controls);
  const Index c = column(assembly);
  Scratch scratch(key_response_.rows(), pair_count());
  for (Index j = 0; j < controls.cols(); ++j) {
    (void)evaluate(c, controls.col(j), scratch);
    out.col(j) = scratch.deviation;
  }
}

SheetMetalContactState ContactSheetMetalTwin::contact_state(
    const AssemblyId& assembly, const Eigen::Ref<const VectorX>& control) const {
  require_control(control, control_dimension());
  require_finite("control", control);
  const Index c = column(assembly);
  Scratch scratch(key_response_.rows(), pair_count());
  (void)evaluate(c, control, scratch);
  return {std::move(scratch.deviation), std::move(scratch.force), std::move(scratch.gap),
          scratch.summary};
}

VectorX ContactSheetMetalTwin::key_deviation(const AssemblyId& assembly,
                                             const Eigen::Ref<const VectorX>& control) const {
  return contact_state(assembly, control).deviation;
}

VectorX ContactSheetMetalTwin::unloaded_gap(const AssemblyId& assembly,
                                            const Eigen::Ref<const VectorX>& control) const {
  require_control(control, control_dimension());
  require_finite("control", control);
  VectorX gap = gap_.col(column(assembly));
  gap.noalias() += gap_influence_ * control;
  return gap;
}

VectorX ContactSheetMetalTwin::released_state(const AssemblyId& assembly,
                                              const Eigen::Ref<const VectorX>& control) const {
  const SheetMetalContactState state = contact_state(assembly, control);
  const SheetMetalProcess& process = linear_.process();
  // The contact-free state from the process itself, plus the release stage's response to the
  // contact forces (by linearity, one solve for all of them).
  VectorX elastic = process.released_state(linear_.upper_part(assembly.upper),
                                           linear_.lower_part(assembly.lower), control);
  VectorX load = VectorX::Zero(release_->dof_count());
  for (Index k = 0; k < pair_count(); ++k) {
    const ContactPair& pair = pairs_[static_cast<std::size_t>(k)];
    load(process.global_dof(SheetMetalPart::upper, PlateMesh::dof(pair.upper_node, 0))) +=
        state.force(k);
    load(process.global_dof(SheetMetalPart::lower, PlateMesh::dof(pair.lower_node, 0))) -=
        state.force(k);
  }
  elastic += release_->response(load);
  return elastic;
}

}  // namespace twincal
