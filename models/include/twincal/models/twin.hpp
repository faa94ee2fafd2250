#pragma once
/// @file
/// `Twin`: the digital twin as a black box, Q(x, u; θ0) of the paper's eq. (1)–(4).
///
/// A twin maps an assembly x (its type is the twin's own: part indices, scanned part shapes, a
/// file name understood by an external program) and a clamp locator adjustment u ∈ R^d to a
/// scalar quality (smaller is better). It names its d locators and their bounds. Controls come as
/// `Eigen::Ref`, so fixed-size vectors (Vector<3>) and dynamic ones pass without copies, and a
/// batch is a d × k matrix with one control per column: one `quality_batch` call is the unit of
/// work that an evaluator times, counts, checks and spreads over threads.
///
/// Twins are used through const references and may be called from several threads at once by a
/// parallel evaluator; a twin with internal state (an external process) serializes itself.

#include <concepts>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

/// A black-box quality model Q(x, u).
///
/// - `typename T::Assembly`: what x is.
/// - `control_dimension()`: d.
/// - `locator_names()`: d names (the paper's locators A, B, C, …).
/// - `lower_bounds()`, `upper_bounds()`: the box of admissible controls (d each).
/// - `quality(x, u)`: Q(x, u) for one control.
/// - `quality_batch(x, U, out)`: out(j) = Q(x, U.col(j)) for the d × k matrix U.
template <typename T>
concept Twin = requires(const T& twin, const typename T::Assembly& assembly,
                        const Eigen::Ref<const VectorX>& control,
                        const Eigen::Ref<const MatrixX>& controls, Eigen::Ref<VectorX> out) {
  typename T::Assembly;
  { twin.control_dimension() } -> std::convertible_to<Index>;
  { twin.locator_names() } -> std::convertible_to<const std::vector<std::string>&>;
  { twin.lower_bounds() } -> std::convertible_to<const VectorX&>;
  { twin.upper_bounds() } -> std::convertible_to<const VectorX&>;
  { twin.quality(assembly, control) } -> std::convertible_to<double>;
  twin.quality_batch(assembly, controls, out);
};

/// A twin whose optimum is known: u0(x) = argmin_u Q(x, u) (eq. 3) and z*(x) = Q(x, u0(x)).
/// Analytic twins know them exactly; an FEM twin would get them from an individualized
/// optimizer run once per assembly.
template <typename T>
concept TwinWithOptimum = Twin<T> && requires(const T& twin, const typename T::Assembly& assembly) {
  { twin.optimum(assembly) } -> std::convertible_to<VectorX>;
  { twin.optimal_quality(assembly) } -> std::convertible_to<double>;
};

/// A twin that also answers what its quality is made of: the deviations r(x, u) of its m key
/// points, with Q(x, u) = ‖r(x, u)‖ / √m (the RMS deviation, as an FEM variation simulation
/// computes it). A search of eq. (3) can then treat u0(x) as a least-squares problem in r, whose
/// Jacobian sees where each contact or active set changes, where Q² alone shows only a kink
/// (controllers' LeastSquaresSearch).
///
/// - `key_point_count()`: m.
/// - `deviations_batch(x, U, out)`: out.col(j) = r(x, U.col(j)) for the d × k matrix U, into the
///   m × k matrix `out`.
template <typename T>
concept TwinWithDeviations = Twin<T> &&
    requires(const T& twin, const typename T::Assembly& assembly,
             const Eigen::Ref<const MatrixX>& controls, Eigen::Ref<MatrixX> out) {
  { twin.key_point_count() } -> std::convertible_to<Index>;
  twin.deviations_batch(assembly, controls, out);
};

/// Checks a deviations batch: `controls` is d × k and `out` is m × k.
/// @throws DimensionMismatchError naming "controls" or "out".
inline void require_deviations_batch(const Eigen::Ref<const MatrixX>& controls,
                                     const Eigen::Ref<const MatrixX>& out, Index dimension,
                                     Index key_points) {
  require_dimension("controls", controls.rows(), dimension, "rows");
  require_dimension("out", out.rows(), key_points, "rows");
  require_dimension("out", out.cols(), controls.cols(), "columns");
}

/// Checks a single control for a twin of `dimension` locators.
/// @throws DimensionMismatchError "control: size is …; rule: must equal d".
inline void require_control(const Eigen::Ref<const VectorX>& control, Index dimension) {
  require_dimension("control", control.size(), dimension);
}

/// Checks a batch: `controls` is d × k and `out` has k entries.
/// @throws DimensionMismatchError naming "controls" or "out".
inline void require_control_batch(const Eigen::Ref<const MatrixX>& controls,
                                  const Eigen::Ref<const VectorX>& out, Index dimension) {
  require_dimension("controls", controls.rows(), dimension, "rows");
  require_dimension("out", out.size(), controls.cols());
}

/// Q(x, u) for one control through `twin.quality_batch`, as a batch of one: the `quality` of a
/// twin whose batch is its only way to evaluate.
/// @throws DimensionMismatchError for a control of the wrong size; what quality_batch throws.
template <typename T>
[[nodiscard]] double quality_of_one(const T& twin, const typename T::Assembly& assembly,
                                    const Eigen::Ref<const VectorX>& control) {
  require_control(control, twin.control_dimension());
  double value = 0.0;
  Eigen::Map<VectorX> out(&value, 1);
  twin.quality_batch(assembly, control, out);
  return value;
}

}  // namespace twincal
