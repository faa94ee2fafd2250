#pragma once
/// @file
/// `AssemblyId`: an assembly joined from one "upper" and one "lower" part, the way the paper's
/// episodes are built (10 upper × 10 lower parts give 100 assemblies).

#include <compare>
#include <cstddef>
#include <functional>

#include <fmt/format.h>

#include "twincal/core/eigen.hpp"

namespace twincal {

/// A twin's own assemblies are pairs of part indices >= 0. A twin that also takes assemblies
/// given by their scanned parts (the experiments' external case) numbers those k = 0, 1, … and
/// gives them the id {k, −1} (experiments/scanned_assembly.hpp), so saved controller states
/// accept lower = −1 too.
struct AssemblyId {
  Index upper = 0;  ///< index of the upper part
  Index lower = 0;  ///< index of the lower part (−1: a scanned assembly's number is `upper`)

  friend constexpr auto operator<=>(const AssemblyId&, const AssemblyId&) = default;
};

}  // namespace twincal

template <>
struct std::hash<twincal::AssemblyId> {
  std::size_t operator()(const twincal::AssemblyId& id) const noexcept {
    const std::size_t h = std::hash<twincal::Index>{}(id.upper);
    return h ^
           (std::hash<twincal::Index>{}(id.lower) + 0x9e3779b97f4a7c15ULL + (h << 6U) + (h >> 2U));
  }
};

template <>
struct fmt::formatter<twincal::AssemblyId> : fmt::formatter<fmt::string_view> {
  template <typename FormatContext>
  auto format(const twincal::AssemblyId& id, FormatContext& ctx) const -> decltype(ctx.out()) {
    return fmt::format_to(ctx.out(), "(upper {}, lower {})", id.upper, id.lower);
  }
};
