#pragma once
/// @file
/// `SheetMetalTwin`: the open stand-in for the paper's RD&T twin (Sec. 5): two spot-welded
/// compliant sheet-metal parts in a fixture with adjustable locators, simulated with linear FEM
/// (ACM Kirchhoff plates) and the method of influence coefficients (`SheetMetalProcess`).
///
/// Everything in the staged process is linear in the parts' free shapes x = (f_U, f_L) and the
/// locator adjustment u, so the key-point deviations are the affine map
///   y(x, u) = A x + B u + c,   c = 0 (nominal parts give the nominal assembly),
/// precomputed once per case: B (m × d) from d unit-u staged solves, and y0(x) = A x for the
/// 10 + 10 parts from one staged solve per part (A acts additively on the two parts). The
/// quality of eq. (1)–(2) is the RMS deviation
///   Q(x, u) = ‖y0(x) + B u‖ / √m = sqrt(q(x) + 2 g(x)ᵀu + uᵀ H u),
///   H = BᵀB/m, g(x) = Bᵀy0(x)/m, q(x) = y0(x)ᵀy0(x)/m,
/// one d × d quadratic form per evaluation. The optimum of eq. (3) is the least-squares solution
/// u0(x) = argmin_u ‖y0(x) + B u‖ (unbounded by default, box-bounded as an option) and
/// z*(x) = Q(x, u0(x)).

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "twincal/core/eigen.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/twin.hpp"
#include "twincal/sheet_metal/part_field.hpp"
#include "twincal/sheet_metal/plate_section.hpp"
#include "twincal/sheet_metal/sheet_metal_layout.hpp"

namespace twincal {

class SheetMetalProcess;

/// The two cases of the paper: 'car body' (sensitive to u) and 'car door' (insensitive).
enum class SheetMetalCase { body, door };

struct SheetMetalTwinOptions {
  PlateSection section;    ///< steel, t = 0.8 mm
  PartFieldOptions field;  ///< free-shape deviations of the synthetic parts
  Index upper_parts = 10;  ///< synthetic parts per side (10 × 10 = 100 assemblies)
  Index lower_parts = 10;
  double locator_bound = 1.0;  ///< the control box is [−bound, bound]^d (mm)
  /// u0(x) in the box (active-set least squares); false: the minimum-norm unbounded solution.
  bool bounded_optimum = true;

  [[nodiscard]] std::optional<std::string> validate() const;
};

class SheetMetalTwin {
 public:
  using Assembly = AssemblyId;

  /// A twin over given parts (e.g. scans read with `PartDeviationFile`): `upper_parts[i]` and
  /// `lower_parts[j]` are nodal free shapes (w, θx, θy) on the layout's upper and lower meshes.
  /// @throws InvalidArgumentError for invalid options or layout, empty part lists;
  ///         DimensionMismatchError for parts of the wrong size; NonFiniteError for NaN parts;
  ///         Error("optimum") if the active-set optimum fails to converge (never observed).
  SheetMetalTwin(SheetMetalLayout layout, const SheetMetalTwinOptions& options,
                 std::vector<VectorX> upper_parts, std::vector<VectorX> lower_parts);

  /// A twin with `options.upper_parts` × `options.lower_parts` synthetic parts drawn from
  /// RandomStream(seed).substream("upper"/"lower").substream(i).
  [[nodiscard]] static SheetMetalTwin generate(SheetMetalLayout layout,
                                               const SheetMetalTwinOptions& options,
                                               std::uint64_t seed);
  /// The 'car body' case: 12 locators, sensitive.
  [[nodiscard]] static SheetMetalTwin body(std::uint64_t seed = 2023);
  /// The 'car door' case: 19 locators, insensitive.
  [[nodiscard]] static SheetMetalTwin door(std::uint64_t seed = 2023);
  /// The case by enum, default options.
  [[nodiscard]] static SheetMetalTwin make(SheetMetalCase which, std::uint64_t seed);
  /// The case by enum with explicit options.
  [[nodiscard]] static SheetMetalTwin make(SheetMetalCase which, std::uint64_t seed,
                                           const SheetMetalTwinOptions& options);
  /// The layout of a case.
  [[nodiscard]] static SheetMetalLayout layout_of(SheetMetalCase which);

  [[nodiscard]] Index control_dimension() const noexcept { return influence_.cols(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept {
    return locator_names_;
  }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return lower_bounds_; }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return upper_bounds_; }

  /// Q(x, u) = sqrt(q + 2gᵀu + uᵀHu), the RMS key-point deviation (mm).
  /// @throws InvalidArgumentError for an unknown assembly, DimensionMismatchError for a control
  ///         of the wrong size.
  [[nodiscard]] double quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const;
  /// out(j) = Q(x, controls.col(j)).
  void quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const;
  /// u0(x) (eq. 3).
  [[nodiscard]] VectorX optimum(const AssemblyId& assembly) const;
  /// z*(x) = Q(x, u0(x)).
  [[nodiscard]] double optimal_quality(const AssemblyId& assembly) const;
  /// All assemblies, upper-major: (0, 0), (0, 1), …
  [[nodiscard]] std::vector<AssemblyId> assemblies() const;
  /// Locators A, B, C: the three largest `locator_effects()`, largest first.
  [[nodiscard]] std::array<Index, 3> significant_locators() const;
  /// Per locator k: the mean over assemblies of Q(x, 0) − min_{u_k in bounds} Q(x, u_k e_k),
  /// the RMS reduction that adjusting locator k alone from nominal can achieve.
  [[nodiscard]] VectorX locator_effects() const;
  /// η = 1 − mean z*(x) / mean Q(x, 0): the share of the nominal deviation the locators can
  /// remove.
  [[nodiscard]] double achievable_gain() const;

  /// m, the key points (TwinWithDeviations).
  [[nodiscard]] Index key_point_count() const noexcept { return influence_.rows(); }
  /// out.col(j) = y(x, controls.col(j)) (m × k; TwinWithDeviations): Q = ‖y‖ / √m.
  /// @throws InvalidArgumentError for an unknown assembly, DimensionMismatchError for controls or
  ///         out of the wrong shape.
  void deviations_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const;
  /// y(x, u) = y0(x) + B u, the key-point deviations (m, mm).
  [[nodiscard]] VectorX key_deviation(const AssemblyId& assembly,
                                      const Eigen::Ref<const VectorX>& control) const;
  /// B (m × d).
  [[nodiscard]] const MatrixX& influence() const noexcept { return influence_; }
  [[nodiscard]] const SheetMetalProcess& process() const noexcept { return *process_; }
  [[nodiscard]] const SheetMetalTwinOptions& options() const noexcept { return options_; }
  [[nodiscard]] Index upper_part_count() const noexcept {
    return static_cast<Index>(upper_parts_.size());
  }
  [[nodiscard]] Index lower_part_count() const noexcept {
    return static_cast<Index>(lower_parts_.size());
  }
  /// The free shape of upper part i / lower part j.
  /// @throws InvalidArgumentError for an index out of range.
  [[nodiscard]] const VectorX& upper_part(Index i) const;
  [[nodiscard]] const VectorX& lower_part(Index j) const;

 private:
  [[nodiscard]] Index column(const AssemblyId& assembly) const;
  [[nodiscard]] double evaluate(Index column, const Eigen::Ref<const VectorX>& control) const;
  [[nodiscard]] VectorX solve_optimum(const VectorX& y0) const;

  std::shared_ptr<const SheetMetalProcess> process_;
  SheetMetalTwinOptions options_;
  std::vector<VectorX> upper_parts_;
  std::vector<VectorX> lower_parts_;
  std::vector<std::string> locator_names_;
  VectorX lower_bounds_;
  VectorX upper_bounds_;
  MatrixX influence_;       // B, m × d
  MatrixX upper_response_;  // y0 contribution of each upper part, m × n_upper
  MatrixX lower_response_;  // y0 contribution of each lower part, m × n_lower
  MatrixX curvature_;       // H = BᵀB/m
  MatrixX linear_;          // g(x) per assembly, d × n
  VectorX constant_;        // q(x) per assembly
  MatrixX optimum_;         // u0(x) per assembly, d × n
  VectorX optimal_quality_;
};

static_assert(TwinWithOptimum<SheetMetalTwin>);

}  // namespace twincal
