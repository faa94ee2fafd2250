#pragma once
/// @file
/// Ids of scanned assemblies. A twin's own assemblies are pairs of part indices (AssemblyId);
/// a twin that also takes assemblies given by their scanned parts (ExternalCaseTwin, through
/// AnyTwin::add_scanned) numbers them k = 0, 1, … in registration order, with the id {k, −1}:
/// a lower part no pair has, so the two kinds never collide. A history that recorded a scanned
/// assembly's optimum registers it again with that ScannedOptimum instead of a new search.

#include <optional>

#include "twincal/core/eigen.hpp"
#include "twincal/models/assembly_id.hpp"

namespace twincal {

/// u0(x) of the full twin and z*(x) of a scanned assembly, as searched when it first arrived.
struct ScannedOptimum {
  VectorX control;
  double quality = 0.0;
};

/// The id of the k-th scanned assembly (k ≥ 0).
[[nodiscard]] constexpr AssemblyId scanned_assembly(Index k) noexcept { return {k, -1}; }

/// k for the id of scanned_assembly(k); nothing for a pair of part indices.
[[nodiscard]] constexpr std::optional<Index> scanned_index(const AssemblyId& id) noexcept {
  if (id.lower == -1 && id.upper >= 0) return id.upper;
  return std::nullopt;
}

}  // namespace twincal
