#pragma once
/// @file
/// fmt formatters for Eigen vectors, matrices and expressions.
///
/// A format spec applies to every element: `fmt::format("{:.3f}", v)` gives "[1.000, 2.000]".
/// Vectors (one row or one column) print as "[a, b, c]"; matrices as rows,
/// "[[a, b], [c, d]]". Expressions are evaluated first, so `fmt::format("{}", a - b)` works.

#include <type_traits>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <Eigen/Core>

namespace twincal::detail {

template <typename T>
inline constexpr bool is_eigen_dense_v = std::is_base_of_v<Eigen::DenseBase<T>, T>;

}  // namespace twincal::detail

template <typename T, typename Char>
struct fmt::formatter<T, Char, std::enable_if_t<twincal::detail::is_eigen_dense_v<T>>> {
  using Scalar = typename T::Scalar;

  constexpr auto parse(fmt::basic_format_parse_context<Char>& ctx) { return element_.parse(ctx); }

  template <typename FormatContext>
  auto format(const T& value, FormatContext& ctx) const -> decltype(ctx.out()) {
    // A plain copy gives every expression (products included) cheap coefficient access;
    // formatting is never on a hot path.
    const typename T::PlainObject plain(value);
    auto out = ctx.out();
    const bool is_vector = plain.rows() == 1 || plain.cols() == 1;
    if (is_vector) return write_row(plain.reshaped(), ctx, out);
    *out++ = '[';
    for (Eigen::Index r = 0; r < plain.rows(); ++r) {
      if (r > 0) out = fmt::format_to(out, ", ");
      ctx.advance_to(out);
      out = write_row(plain.row(r), ctx, out);
    }
    *out++ = ']';
    return out;
  }

 private:
  template <typename Row, typename FormatContext, typename Out>
  auto write_row(const Row& row, FormatContext& ctx, Out out) const -> Out {
    *out++ = '[';
    for (Eigen::Index i = 0; i < row.size(); ++i) {
      if (i > 0) out = fmt::format_to(out, ", ");
      ctx.advance_to(out);
      out = element_.format(row(i), ctx);
    }
    *out++ = ']';
    return out;
  }

  fmt::formatter<Scalar, Char> element_;
};

// Eigen vectors have begin()/end(); keep fmt/ranges.h from claiming them (and vector
// expressions) as ranges, which would make the formatter above ambiguous.
template <typename T, typename Char>
struct fmt::range_format_kind<T, Char, std::enable_if_t<twincal::detail::is_eigen_dense_v<T>>>
    : std::integral_constant<fmt::range_format, fmt::range_format::disabled> {};
