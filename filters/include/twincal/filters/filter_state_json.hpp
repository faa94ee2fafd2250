#pragma once
/// @file
/// JSON encoding of filter states (save/restore). Numbers are written by nlohmann-json with the
/// shortest representation that reads back to the same double, so a save/restore round trip is
/// bit-exact. Reading validates shape and finiteness and throws twincal's typed errors naming
/// the JSON field; malformed JSON (a missing field, a string for a number) becomes an
/// InvalidArgumentError as well.

#include <cstdint>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"

namespace twincal::json_state {

/// A vector as a JSON array.
template <typename Derived>
[[nodiscard]] nlohmann::json vector_to_json(const Eigen::MatrixBase<Derived>& v) {
  nlohmann::json out = nlohmann::json::array();
  for (Index i = 0; i < v.size(); ++i) out.push_back(v(i));
  return out;
}

/// A matrix as a JSON array of its columns (each an array), so a point set reads as its points.
template <typename Derived>
[[nodiscard]] nlohmann::json columns_to_json(const Eigen::MatrixBase<Derived>& m) {
  nlohmann::json out = nlohmann::json::array();
  for (Index c = 0; c < m.cols(); ++c) out.push_back(vector_to_json(m.col(c)));
  return out;
}

/// The field `name` of `object`. @throws InvalidArgumentError when it is missing.
[[nodiscard]] inline const nlohmann::json& field(const nlohmann::json& object,
                                                 std::string_view name) {
  if (!object.is_object() || !object.contains(name)) {
    throw InvalidArgumentError(std::string(name),
                               fmt::format("{}: field is missing; rule: a saved state has every "
                                           "field its save() writes (a filter's: format, "
                                           "dimension, updates, state, covariance and "
                                           "sigma_points)",
                                           name));
  }
  return object.at(std::string(name));
}

/// A finite number. @throws InvalidArgumentError (not a number), NonFiniteError.
[[nodiscard]] inline double read_number(const nlohmann::json& value, std::string_view name) {
  if (!value.is_number()) {
    throw InvalidArgumentError(
        std::string(name), fmt::format("{}: is {} ({}); rule: must be a number", name, value.dump(),
                                       value.type_name()));
  }
  const double x = value.get<double>();
  require_finite(name, x);
  return x;
}

/// A JSON array of `size` finite numbers into `out` (already sized).
template <typename Derived>
void read_vector(const nlohmann::json& value, std::string_view name,
                 Eigen::MatrixBase<Derived>& out) {
  if (!value.is_array()) {
    throw InvalidArgumentError(
        std::string(name),
        fmt::format("{}: is a {}; rule: must be an array of numbers", name, value.type_name()));
  }
  require_dimension(name, static_cast<Index>(value.size()), out.size());
  for (Index i = 0; i < out.size(); ++i) {
    out(i) = read_number(value[static_cast<std::size_t>(i)], fmt::format("{}[{}]", name, i));
  }
}

/// A JSON array of columns into the `rows` × `cols` matrix `out` (already sized).
template <typename Derived>
void read_columns(const nlohmann::json& value, std::string_view name,
                  Eigen::MatrixBase<Derived>& out) {
  if (!value.is_array()) {
    throw InvalidArgumentError(
        std::string(name),
        fmt::format("{}: is a {}; rule: must be an array of columns", name, value.type_name()));
  }
  require_dimension(name, static_cast<Index>(value.size()), out.cols(), "number of columns");
  for (Index c = 0; c < out.cols(); ++c) {
    auto column = out.col(c);
    read_vector(value[static_cast<std::size_t>(c)], fmt::format("{}[{}]", name, c), column);
  }
}

/// Checks the `format` tag and `dimension` of a saved state.
inline void require_header(const nlohmann::json& saved, std::string_view format, Index dimension) {
  const nlohmann::json& tag = field(saved, "format");
  if (!tag.is_string() || tag.get<std::string>() != format) {
    throw InvalidArgumentError(
        "format", fmt::format("format: is {}; rule: must be \"{}\"", tag.dump(), format));
  }
  const nlohmann::json& dim = field(saved, "dimension");
  if (!dim.is_number_integer()) {
    throw InvalidArgumentError("dimension", fmt::format("dimension: is {}; rule: must be an "
                                                        "integer",
                                                        dim.dump()));
  }
  require_dimension("dimension", dim.get<Index>(), dimension);
}

/// The non-negative integer field `name`.
[[nodiscard]] inline std::uint64_t read_count(const nlohmann::json& saved, std::string_view name) {
  const nlohmann::json& value = field(saved, name);
  if (!value.is_number_integer() ||
      (!value.is_number_unsigned() && value.get<std::int64_t>() < 0)) {
    throw InvalidArgumentError(
        std::string(name),
        fmt::format("{}: is {}; rule: must be a non-negative integer", name, value.dump()));
  }
  return value.get<std::uint64_t>();
}

}  // namespace twincal::json_state
