#pragma once
/// @file
/// `ContactSheetMetalTwin`: the FEM sheet-metal twin with sheet-to-sheet contact in the flange,
/// the method of influence coefficients with contact modelling of Dahlström & Lindkvist (2007).
///
/// The linear twin (`SheetMetalTwin`) lets the sheets pass through each other between the
/// welds. Here every pair of facing flange nodes (contact_pairs.hpp: the overlap's grid points
/// except the welds) has a normal gap, from the linear (contact-free) released state,
///   g⁰_k(x, u) = g_nom + (w_U − w_L)_k = g_nom + G_x x + G u     (affine, precomputed),
/// and contact forces f ≥ 0, equal and opposite on the two nodes, act on the released assembly
/// (release_stage.hpp) so that it does not penetrate:
///   f ≥ 0,  g = g⁰ + C f ≥ 0,  fᵀg = 0      (the LCP, contact_solver.hpp)
/// with C (p × p) the contact compliance: the change of every gap under a unit pair force, one
/// release-stage solve per pair, once per twin (the factorization does not depend on x or u).
/// The key deviations become
///   y(x, u) = y_lin(x, u) + K f(x, u),   Q = ‖y‖ / √m,
/// with K (m × p) the key points' response to the same unit pair forces. f(x, u) is piecewise
/// affine in u (one affine piece per set of closed contacts), so Q² is piecewise quadratic in u,
/// continuous, with kinks where a contact opens or closes.
///
/// A class of its own, not an option of SheetMetalTwin: (1) SheetMetalTwin is a
/// `TwinWithOptimum` — its optimum is the exact bounded least-squares solution — while here the
/// optimum is not known in closed form (minimizing Q² over u is a program with complementarity
/// constraints, one convex piece per active set), so this class deliberately does not offer
/// optimum()/optimal_quality(): the concept check then tells callers the truth at compile time,
/// and the experiments search u0 with NLopt (controllers/searched_optimum_twin.hpp), starting
/// from `search_start(x)`, the linear twin's optimum; (2) an evaluation needs an LCP solve and
/// scratch space, a different cost model from the linear twin's d × d quadratic form; (3) it is
/// built *from* a linear twin, which it keeps: y_lin, the locator names and bounds, and the
/// significant locators A, B, C are the linear twin's, so a contact case and its linear case
/// differ only by the contact.
///
/// Const calls are thread-safe: every evaluation works in scratch of its own (per batch, or per
/// thread for single calls), and the LCP solver starts cold, so Q is a deterministic function
/// of (x, u) whichever thread or batch computes it.
///
/// Modelling limits (docs/sheet_metal.md, "Contact"): contact acts in the release stage only
/// (the clamped, welded state is taken from the linear model, as the welding guns and clamps
/// hold the flange), frictionless, node to node, one uniform nominal gap, no sheet thickness
/// offset.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/twin.hpp"
#include "twincal/sheet_metal/contact_pairs.hpp"
#include "twincal/sheet_metal/contact_solver.hpp"
#include "twincal/sheet_metal/sheet_metal_twin.hpp"

namespace twincal {

class ReleaseStage;

struct ContactSheetMetalTwinOptions {
  /// g_nom: the nominal clearance between the facing flange nodes (mm), the same at every pair.
  /// Small and positive, so that contacts open and close within the locator box ±1 mm of both
  /// cases (docs/sheet_metal.md, "Contact": 0.02 mm leaves most pairs open, closes a few at u0
  /// and more at the box corners). 0 is nominal touching; a huge gap turns contact off.
  double nominal_gap = 0.02;
  ContactSolverOptions solver;

  [[nodiscard]] std::optional<std::string> validate() const;
};

/// One evaluation in full: the key deviations, the contact forces and gaps, the solver summary.
struct SheetMetalContactState {
  VectorX deviation;  ///< y (m, mm)
  VectorX force;      ///< f (p, N), >= 0
  VectorX gap;        ///< g = g⁰ + C f (p, mm), >= 0 up to the solver's tolerance
  ContactSolverSummary summary;
};

class ContactSheetMetalTwin {
 public:
  using Assembly = AssemblyId;

  /// Adds flange contact to `linear`: finds the pairs, solves the release stage once per pair
  /// (C and K) and once per part and locator (the gap maps).
  /// @throws InvalidArgumentError for invalid options or a layout without contact pairs;
  ///         the FEM's errors.
  explicit ContactSheetMetalTwin(SheetMetalTwin linear,
                                 const ContactSheetMetalTwinOptions& options = {});

  /// The 'body' / 'door' case with contact: SheetMetalTwin::make(which, seed) (the same parts
  /// and locators as the linear case) and default contact options.
  [[nodiscard]] static ContactSheetMetalTwin make(SheetMetalCase which, std::uint64_t seed);
  [[nodiscard]] static ContactSheetMetalTwin body(std::uint64_t seed = 2023);
  [[nodiscard]] static ContactSheetMetalTwin door(std::uint64_t seed = 2023);

  // The Twin concept.
  [[nodiscard]] Index control_dimension() const noexcept { return linear_.control_dimension(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept {
    return linear_.locator_names();
  }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return linear_.lower_bounds(); }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return linear_.upper_bounds(); }
  /// Q(x, u) = ‖y_lin + K f‖ / √m with f the LCP solution (mm). Allocates nothing once the
  /// calling thread has evaluated a twin of this size.
  /// @throws InvalidArgumentError for an unknown assembly, DimensionMismatchError for a control
  ///         of the wrong size, NonFiniteError for a non-finite control, ContactSolverError
  ///         when the contact solve fails (never observed on the cases).
  [[nodiscard]] double quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const;
  /// out(j) = Q(x, controls.col(j)); one scratch per batch, no allocation per column.
  void quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const;

  /// All assemblies, upper-major, as the linear twin's.
  [[nodiscard]] std::vector<AssemblyId> assemblies() const { return linear_.assemblies(); }
  /// Locators A, B, C: the linear twin's (contact-free effects), so that the contact case
  /// adjusts the same locators as its linear case.
  [[nodiscard]] std::array<Index, 3> significant_locators() const {
    return linear_.significant_locators();
  }
  /// Where a search for u0(x) starts: the linear twin's optimum (exact without contact).
  [[nodiscard]] VectorX search_start(const AssemblyId& assembly) const {
    return linear_.optimum(assembly);
  }

  /// y, f, g and the solver's summary at (x, u).
  [[nodiscard]] SheetMetalContactState contact_state(
      const AssemblyId& assembly, const Eigen::Ref<const VectorX>& control) const;
  /// m, the key points (TwinWithDeviations).
  [[nodiscard]] Index key_point_count() const noexcept { return linear_.key_point_count(); }
  /// out.col(j) = y(x, controls.col(j)) with contact (m × k; TwinWithDeviations): Q = ‖y‖ / √m.
  /// One scratch per batch. @throws as quality_batch, and DimensionMismatchError for out.
  void deviations_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const;
  /// y(x, u) with contact (m, mm).
  [[nodiscard]] VectorX key_deviation(const AssemblyId& assembly,
                                      const Eigen::Ref<const VectorX>& control) const;
  /// g⁰(x, u): the gaps of the contact-free released state (p, mm).
  [[nodiscard]] VectorX unloaded_gap(const AssemblyId& assembly,
                                     const Eigen::Ref<const VectorX>& control) const;
  /// The full released state with the contact forces applied (stacked dofs, elastic part e; the
  /// total shape adds the free shapes): an independent FEM solve, for checks and pictures.
  [[nodiscard]] VectorX released_state(const AssemblyId& assembly,
                                       const Eigen::Ref<const VectorX>& control) const;

  [[nodiscard]] const SheetMetalTwin& linear() const noexcept { return linear_; }
  [[nodiscard]] const ContactSheetMetalTwinOptions& options() const noexcept { return options_; }
  [[nodiscard]] const std::vector<ContactPair>& pairs() const noexcept { return pairs_; }
  [[nodiscard]] Index pair_count() const noexcept { return static_cast<Index>(pairs_.size()); }
  /// C (p × p, mm/N).
  [[nodiscard]] const MatrixX& compliance() const noexcept { return solver_.compliance(); }
  /// K (m × p, mm/N).
  [[nodiscard]] const MatrixX& key_response() const noexcept { return key_response_; }
  /// G = ∂g⁰/∂u (p × d).
  [[nodiscard]] const MatrixX& gap_influence() const noexcept { return gap_influence_; }
  [[nodiscard]] const ContactSolver& solver() const noexcept { return solver_; }

 private:
  struct Precomputed;
  struct Scratch;
  explicit ContactSheetMetalTwin(Precomputed&& precomputed);
  [[nodiscard]] Index column(const AssemblyId& assembly) const;
  // Writes y, f, g into the scratch for assembly column c; returns Q.
  double evaluate(Index c, const Eigen::Ref<const VectorX>& control, Scratch& scratch) const;

  SheetMetalTwin linear_;
  ContactSheetMetalTwinOptions options_;
  std::vector<ContactPair> pairs_;
  std::shared_ptr<const ReleaseStage> release_;  // shared: copies of the twin share one factor
  ContactSolver solver_;
  MatrixX key_response_;   // K, m × p
  MatrixX gap_influence_;  // G, p × d
  MatrixX deviation_;      // y_lin(x, 0) per assembly, m × n
  MatrixX gap_;            // g⁰(x, 0) per assembly (nominal gap included), p × n
};

static_assert(Twin<ContactSheetMetalTwin>);
static_assert(!TwinWithOptimum<ContactSheetMetalTwin>);

}  // namespace twincal
