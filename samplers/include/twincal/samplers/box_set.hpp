#pragma once
/// @file
/// `BoxSet<N>`: the paper's admissible control set U_t = {u : |u_i − c_i| ≤ h_i, i = 1…d}
/// (Sec. 3, the set in eq. (14), with c = û*_t and h_i = 0.1 mm). Candidates outside it are
/// "disregarded" (Sec. 2.3.2): keep_inside() compacts the surviving columns.

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {

/// An axis-aligned box given by its centre and half widths.
template <int N>
class BoxSet {
 public:
  using Points = Matrix<N, Dynamic>;
  static constexpr int dimension_at_compile_time = N;

  /// Throws NonFiniteError (centre or half widths), DimensionMismatchError (sizes) or
  /// InvalidArgumentError (a negative half width).
  BoxSet(const Vector<N>& center, const Vector<N>& half_width)
      : center_(center), half_width_(half_width) {
    require_finite("center", center);
    require_finite("half_width", half_width);
    require_dimension("half_width", half_width.size(), center.size());
    for (Index i = 0; i < half_width.size(); ++i) {
      require_non_negative(fmt::format("half_width({})", i), half_width(i));
    }
  }

  /// The cube of half width `h` around `center` (the paper's h = 0.1).
  [[nodiscard]] static BoxSet cube(const Vector<N>& center, double h) {
    return BoxSet(center, Vector<N>::Constant(center.size(), h));
  }

  [[nodiscard]] Index dimension() const noexcept { return center_.size(); }
  [[nodiscard]] const Vector<N>& center() const noexcept { return center_; }
  [[nodiscard]] const Vector<N>& half_width() const noexcept { return half_width_; }

  /// |u_i − c_i| ≤ h_i for every i (false for NaN).
  [[nodiscard]] bool contains(const Eigen::Ref<const Vector<N>>& u) const {
    require_dimension("u", u.size(), dimension());
    return inside(u);
  }

  /// Moves the columns of `points` inside the box to the front, in their order, and returns
  /// how many there are; the remaining columns are unspecified.
  [[nodiscard]] Index keep_inside(Eigen::Ref<Points> points) const {
    require_dimension("points", points.rows(), dimension(), "rows");
    Index kept = 0;
    for (Index c = 0; c < points.cols(); ++c) {
      if (!inside(points.col(c))) continue;
      if (kept != c) points.col(kept) = points.col(c);
      ++kept;
    }
    return kept;
  }

 private:
  template <typename Derived>
  [[nodiscard]] bool inside(const Eigen::MatrixBase<Derived>& u) const {
    return ((u - center_).cwiseAbs().array() <= half_width_.array()).all();
  }

  Vector<N> center_;
  Vector<N> half_width_;
};

}  // namespace twincal
