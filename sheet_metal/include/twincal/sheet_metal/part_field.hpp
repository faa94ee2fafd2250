#pragma once
/// @file
/// `PartField`: seeded smooth random free-shape deviations of a sheet-metal part, the open
/// stand-in for the paper's scanned parts.
///
/// The normal deviation is a zero-mean Gaussian field with squared-exponential covariance
///   cov(w(p), w(p')) = σ² exp(−|p − p'|² / (2ℓ²)),
/// sampled by random Fourier features (Rahimi & Recht 2007): w(p) = σ √(2/N) Σ_k cos(ω_k·p + φ_k)
/// with ω_k ~ N(0, I/ℓ²) and φ_k ~ U[0, 2π), whose covariance converges to the kernel as N grows.
/// A bow (quadratic in x and in y) and a twist (xy) with N(0, σ_bow²) and N(0, σ_twist²) peak
/// amplitudes are added. Every term is a closed-form function, so the nodal slopes
/// θx = ∂w/∂y, θy = −∂w/∂x are the exact derivatives of the sampled w.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/sheet_metal/plate_mesh.hpp"

namespace twincal {

struct PartFieldOptions {
  double standard_deviation = 0.25;   ///< σ of the correlated field (mm)
  double correlation_length = 150.0;  ///< ℓ (mm)
  Index features = 256;               ///< N, random Fourier features
  double bow = 0.1;                   ///< σ_bow, standard deviation of the bow amplitude (mm)
  double twist = 0.1;                 ///< σ_twist, standard deviation of the twist amplitude (mm)

  [[nodiscard]] std::optional<std::string> validate() const;
};

class PartField {
 public:
  /// @throws InvalidArgumentError when the options are inconsistent.
  explicit PartField(const PartFieldOptions& options);

  [[nodiscard]] const PartFieldOptions& options() const noexcept { return options_; }

  /// One part's nodal deviations (w, θx, θy per node of `mesh`), drawn from `stream`.
  [[nodiscard]] VectorX sample(const PlateMesh& mesh, RandomStream& stream) const;

  /// `count` parts of one side of an assembly: part i from `root.substream(side).substream(i)`,
  /// so part i is the same whatever the count (the sheet-metal twins draw theirs this way).
  [[nodiscard]] std::vector<VectorX> sample_parts(const PlateMesh& mesh, const RandomStream& root,
                                                  std::string_view side, Index count) const;

 private:
  PartFieldOptions options_;
};

}  // namespace twincal
