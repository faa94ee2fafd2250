#pragma once
/// @file
/// JSON encoding of controller states (save/restore, `SnapshotController` in controller.hpp),
/// extending the filters' helpers (filters' filter_state_json.hpp). Every double reads back bit
/// for bit: a finite one is nlohmann's shortest round-trip number, NaN is null and ±∞ are the
/// strings "inf" and "-inf" (JSON has no non-finite numbers; a report holds NaN legitimately,
/// e.g. the losses of a default-control fallback). Readers check types, sizes and, where a
/// quantity must be finite, finiteness, and throw twincal's typed errors naming the field;
/// `within` prefixes a nested part's names ("filter.state").

#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <locale>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/controllers/active/quadratic_model.hpp"
#include "twincal/controllers/proposal_report.hpp"
#include "twincal/core/cholesky.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/filters/filter_state_json.hpp"
#include "twincal/filters/measurement_preview.hpp"
#include "twincal/models/assembly_id.hpp"

namespace twincal::json_state {

/// Whether a quantity read back must be finite (a state) or may be NaN or ±∞ (a report).
enum class Values { finite, any };

// --- numbers ----------------------------------------------------------------------------------

/// A double as JSON: the number, null for NaN, "inf" / "-inf" for ±∞.
[[nodiscard]] inline nlohmann::json number_to_json(double x) {
  if (std::isnan(x)) return nullptr;
  if (std::isinf(x)) return x > 0.0 ? "inf" : "-inf";
  return x;
}

/// The inverse of number_to_json. @throws InvalidArgumentError (another type or string),
/// NonFiniteError (a non-finite value where `values` is finite).
[[nodiscard]] inline double read_double(const nlohmann::json& value, std::string_view name,
                                        Values values = Values::finite) {
  double x = 0.0;
  if (value.is_number()) {
    x = value.get<double>();
  } else if (value.is_null()) {
    x = std::numeric_limits<double>::quiet_NaN();
  } else if (value.is_string() && value.get<std::string>() == "inf") {
    x = std::numeric_limits<double>::infinity();
  } else if (value.is_string() && value.get<std::string>() == "-inf") {
    x = -std::numeric_limits<double>::infinity();
  } else {
    throw InvalidArgumentError(
        std::string(name),
        fmt::format("{}: is {}; rule: must be a number (null for NaN, \"inf\" or \"-inf\")", name,
                    value.dump()));
  }
  if (values == Values::finite) require_finite(name, x);
  return x;
}

/// The field `name` of `saved` as a double.
[[nodiscard]] inline double read_double_field(const nlohmann::json& saved, std::string_view name,
                                              Values values = Values::finite) {
  return read_double(field(saved, name), name, values);
}

/// A boolean `value` named `name`.
[[nodiscard]] inline bool read_boolean(const nlohmann::json& value, std::string_view name) {
  if (!value.is_boolean()) {
    throw InvalidArgumentError(
        std::string(name),
        fmt::format("{}: is {}; rule: must be true or false", name, value.dump()));
  }
  return value.get<bool>();
}

/// The boolean field `name`.
[[nodiscard]] inline bool read_bool(const nlohmann::json& saved, std::string_view name) {
  return read_boolean(field(saved, name), name);
}

/// An integer in [low, high].
[[nodiscard]] inline Index read_integer(const nlohmann::json& value, std::string_view name,
                                        Index low = std::numeric_limits<Index>::min(),
                                        Index high = std::numeric_limits<Index>::max()) {
  if (!value.is_number_integer() ||
      (value.is_number_unsigned() &&
       value.get<std::uint64_t>() >
           static_cast<std::uint64_t>(std::numeric_limits<Index>::max()))) {
    throw InvalidArgumentError(
        std::string(name), fmt::format("{}: is {}; rule: must be an integer", name, value.dump()));
  }
  const auto x = value.get<Index>();
  if (x < low || x > high) {
    throw InvalidArgumentError(
        std::string(name),
        fmt::format("{}: is {}; rule: must lie in [{}, {}]", name, x, low, high));
  }
  return x;
}

/// The integer field `name`, in [low, high].
[[nodiscard]] inline Index read_integer_field(const nlohmann::json& saved, std::string_view name,
                                              Index low = std::numeric_limits<Index>::min(),
                                              Index high = std::numeric_limits<Index>::max()) {
  return read_integer(field(saved, name), name, low, high);
}

/// The string field `name`.
[[nodiscard]] inline std::string read_string(const nlohmann::json& saved, std::string_view name) {
  const nlohmann::json& value = field(saved, name);
  if (!value.is_string()) {
    throw InvalidArgumentError(
        std::string(name), fmt::format("{}: is {}; rule: must be a string", name, value.dump()));
  }
  return value.get<std::string>();
}

/// `value` as a JSON array of `size` entries (any size when `size` < 0).
inline const nlohmann::json& require_array(const nlohmann::json& value, std::string_view name,
                                           Index size = -1) {
  if (!value.is_array()) {
    throw InvalidArgumentError(std::string(name), fmt::format("{}: is a {}; rule: must be an array",
                                                              name, value.type_name()));
  }
  if (size >= 0) require_dimension(name, static_cast<Index>(value.size()), size);
  return value;
}

// --- vectors and matrices ---------------------------------------------------------------------

/// A vector (or a sequence of doubles) as an array of number_to_json.
template <typename Derived>
[[nodiscard]] nlohmann::json doubles_to_json(const Eigen::DenseBase<Derived>& v) {
  nlohmann::json out = nlohmann::json::array();
  for (Index i = 0; i < v.size(); ++i) out.push_back(number_to_json(v(i)));
  return out;
}
[[nodiscard]] inline nlohmann::json doubles_to_json(const std::vector<double>& v) {
  nlohmann::json out = nlohmann::json::array();
  for (const double x : v) out.push_back(number_to_json(x));
  return out;
}

/// A matrix as an array of its columns, each doubles_to_json.
template <typename Derived>
[[nodiscard]] nlohmann::json matrix_to_json(const Eigen::DenseBase<Derived>& m) {
  nlohmann::json out = nlohmann::json::array();
  for (Index c = 0; c < m.cols(); ++c) out.push_back(doubles_to_json(m.col(c)));
  return out;
}

/// An array of out.size() doubles into `out` (already sized).
template <typename Derived>
void read_doubles(const nlohmann::json& value, std::string_view name,
                  Eigen::DenseBase<Derived>& out, Values values = Values::finite) {
  require_array(value, name, out.size());
  for (Index i = 0; i < out.size(); ++i) {
    out(i) =
        read_double(value[static_cast<std::size_t>(i)], fmt::format("{}[{}]", name, i), values);
  }
}
inline void read_doubles(const nlohmann::json& value, std::string_view name,
                         std::vector<double>& out, Values values = Values::finite) {
  require_array(value, name, std::ssize(out));
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = read_double(value[i], fmt::format("{}[{}]", name, i), values);
  }
}

/// An array of out.size() booleans into `out` (already sized).
inline void read_bools(const nlohmann::json& value, std::string_view name, std::vector<bool>& out) {
  require_array(value, name, std::ssize(out));
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = read_boolean(value[i], fmt::format("{}[{}]", name, i));
  }
}

/// An array of out.cols() columns of out.rows() doubles into `out` (already sized).
template <typename Derived>
void read_matrix(const nlohmann::json& value, std::string_view name, Eigen::DenseBase<Derived>& out,
                 Values values = Values::finite) {
  require_array(value, name, out.cols());
  for (Index c = 0; c < out.cols(); ++c) {
    auto column = out.col(c);
    read_doubles(value[static_cast<std::size_t>(c)], fmt::format("{}[{}]", name, c), column,
                 values);
  }
}

/// A vector of `size` doubles, or an empty one when the array is empty and V is
/// dynamic-size (a report or model not filled yet).
template <typename V>
[[nodiscard]] V read_vector(const nlohmann::json& value, std::string_view name, Index size,
                            Values values = Values::finite) {
  require_array(value, name);
  V out;
  if constexpr (V::SizeAtCompileTime == Dynamic) {
    if (value.empty()) return out;
  }
  out.resize(size);
  read_doubles(value, name, out, values);
  return out;
}

/// A rows × cols matrix, or an empty one when the array is empty and M is dynamic-size.
template <typename M>
[[nodiscard]] M read_matrix_of(const nlohmann::json& value, std::string_view name, Index rows,
                               Index cols, Values values = Values::finite) {
  require_array(value, name);
  M out;
  if constexpr (M::SizeAtCompileTime == Dynamic) {
    if (value.empty()) return out;
  }
  out.resize(rows, cols);
  read_matrix(value, name, out, values);
  return out;
}

// --- nested parts -----------------------------------------------------------------------------

/// Runs `read` (which restores or reads the part saved under `part`) and prefixes the field
/// named by any of twincal's argument errors with "part.", keeping the error's type.
template <typename Read>
decltype(auto) within(std::string_view part, Read&& read) {
  const auto prefixed = [part](std::string_view inner) {
    return fmt::format("{}.{}", part, inner);
  };
  try {
    return std::forward<Read>(read)();
  } catch (const DimensionMismatchError& e) {
    throw DimensionMismatchError(prefixed(e.argument()), prefixed(e.what()), e.actual(),
                                 e.expected());
  } catch (const NotPositiveDefiniteError& e) {
    throw NotPositiveDefiniteError(prefixed(e.argument()), prefixed(e.what()),
                                   e.smallest_eigenvalue());
  } catch (const NonFiniteError& e) {
    throw NonFiniteError(prefixed(e.argument()), prefixed(e.what()));
  } catch (const InvalidArgumentError& e) {
    throw InvalidArgumentError(prefixed(e.argument()), prefixed(e.what()));
  }
}

/// Checks the `format` tag of a saved state without a dimension (filter_state_json's
/// require_header checks both).
inline void require_format(const nlohmann::json& saved, std::string_view format) {
  const nlohmann::json& tag = field(saved, "format");
  if (!tag.is_string() || tag.get<std::string>() != format) {
    throw InvalidArgumentError(
        "format", fmt::format("format: is {}; rule: must be \"{}\"", tag.dump(), format));
  }
}

// --- random streams -----------------------------------------------------------------------------

/// A RandomStream: its seed and its engine's state in the standard's text form of
/// std::mt19937_64 (written and read in the classic locale), so the draws go on exactly.
[[nodiscard]] inline nlohmann::json random_stream_to_json(const RandomStream& stream) {
  std::ostringstream text;
  text.imbue(std::locale::classic());
  text << stream.engine();
  return {{"seed", stream.seed()}, {"engine", text.str()}};
}

/// The inverse of random_stream_to_json. @throws InvalidArgumentError naming the field.
[[nodiscard]] inline RandomStream read_random_stream(const nlohmann::json& value,
                                                     std::string_view name) {
  return within(name, [&value] {
    RandomStream stream(read_count(value, "seed"));
    std::istringstream text(read_string(value, "engine"));
    text.imbue(std::locale::classic());
    text >> stream.engine();
    bool read = !text.fail();
    if (read && !text.eof()) {  // nothing but blanks may follow
      text >> std::ws;
      read = text.eof();
    }
    if (!read) {
      throw InvalidArgumentError("engine",
                                 "engine: is not the state of a std::mt19937_64; rule: the text "
                                 "its operator<< writes (312 words and the position)");
    }
    return stream;
  });
}

// --- controller parts -------------------------------------------------------------------------

/// A ProposalReport (its vectors may be empty before the first proposal; NaN where unset).
[[nodiscard]] inline nlohmann::json report_to_json(const ProposalReport& report) {
  return {{"individual_control", doubles_to_json(report.individual_control)},
          {"optimal_quality", number_to_json(report.optimal_quality)},
          {"default_control", doubles_to_json(report.default_control)},
          {"control", doubles_to_json(report.control)},
          {"candidates_requested", report.candidates_requested},
          {"candidates_drawn", report.candidates_drawn},
          {"candidates_survived", report.candidates_survived},
          {"candidates_scored", report.candidates_scored},
          {"chosen", report.chosen},
          {"exploitation", number_to_json(report.exploitation)},
          {"exploration", number_to_json(report.exploration)},
          {"loss", number_to_json(report.loss)},
          {"quality_evaluations", report.quality_evaluations},
          {"optimizer_evaluations", report.optimizer_evaluations},
          {"fallback", report.fallback},
          {"dropped_measurement", report.dropped_measurement}};
}

/// The inverse of report_to_json for a controller of `d` locators (vectors of d or no entries).
[[nodiscard]] inline ProposalReport read_report(const nlohmann::json& saved, Index d) {
  ProposalReport report;
  const auto vector = [&saved, d](std::string_view name) {
    return read_vector<VectorX>(field(saved, name), name, d, Values::any);
  };
  report.individual_control = vector("individual_control");
  report.optimal_quality = read_double_field(saved, "optimal_quality", Values::any);
  report.default_control = vector("default_control");
  report.control = vector("control");
  report.candidates_requested = read_integer_field(saved, "candidates_requested", 0);
  report.candidates_drawn = read_integer_field(saved, "candidates_drawn", 0);
  report.candidates_survived = read_integer_field(saved, "candidates_survived", 0);
  report.candidates_scored = read_integer_field(saved, "candidates_scored", 0);
  report.chosen = read_integer_field(saved, "chosen", -1);
  report.exploitation = read_double_field(saved, "exploitation", Values::any);
  report.exploration = read_double_field(saved, "exploration", Values::any);
  report.loss = read_double_field(saved, "loss", Values::any);
  report.quality_evaluations = read_count(saved, "quality_evaluations");
  report.optimizer_evaluations = read_count(saved, "optimizer_evaluations");
  report.fallback = read_string(saved, "fallback");
  report.dropped_measurement = read_string(saved, "dropped_measurement");
  return report;
}

/// A QuadraticModel (empty at dynamic size before its first fit; its doubles as they are,
/// non-finite ones included: a model is read back as it was, not judged).
template <int N>
[[nodiscard]] nlohmann::json model_to_json(const QuadraticModel<N>& model) {
  return {{"center", doubles_to_json(model.center)},
          {"value", number_to_json(model.value)},
          {"half_gradient", doubles_to_json(model.half_gradient)},
          {"hessian", matrix_to_json(model.hessian)}};
}

/// The inverse of model_to_json for `d` locators.
template <int N>
[[nodiscard]] QuadraticModel<N> read_model(const nlohmann::json& saved, Index d) {
  QuadraticModel<N> model;
  model.center = read_vector<Vector<N>>(field(saved, "center"), "center", d, Values::any);
  model.value = read_double_field(saved, "value", Values::any);
  model.half_gradient =
      read_vector<Vector<N>>(field(saved, "half_gradient"), "half_gradient", d, Values::any);
  model.hessian =
      read_matrix_of<SquareMatrix<N>>(field(saved, "hessian"), "hessian", d, d, Values::any);
  return model;
}

/// What `commit(preview, z)` of a sigma-point filter reads of a MeasurementPreview (ẑ, S, Pzz,
/// Pxz, K, P⁺, L⁺) and its factorization report; not the measurements γ_i, which commit does
/// not read.
template <int N, int M>
[[nodiscard]] nlohmann::json preview_to_json(const MeasurementPreview<N, M>& preview) {
  return {{"predicted_measurement", number_to_json(preview.predicted_measurement)},
          {"measurement_variance", number_to_json(preview.measurement_variance)},
          {"innovation_variance", number_to_json(preview.innovation_variance)},
          {"cross_covariance", doubles_to_json(preview.cross_covariance)},
          {"gain", doubles_to_json(preview.gain)},
          {"posterior_covariance", matrix_to_json(preview.posterior_covariance)},
          {"posterior_factor", matrix_to_json(preview.posterior_factor)},
          {"repair", static_cast<int>(preview.factorization.applied)},
          {"jitter", number_to_json(preview.factorization.jitter)},
          {"clipped_eigenvalues", preview.factorization.clipped_eigenvalues},
          {"smallest_eigenvalue", number_to_json(preview.factorization.smallest_eigenvalue)}};
}

/// The inverse of preview_to_json for `d` states into a MeasurementPreview<N, M> (without
/// measurements; the revision is the caller's to set).
template <typename Preview>
[[nodiscard]] Preview read_preview(const nlohmann::json& saved, Index d) {
  Preview preview;
  preview.predicted_measurement = read_double_field(saved, "predicted_measurement");
  preview.measurement_variance = read_double_field(saved, "measurement_variance");
  preview.innovation_variance = read_double_field(saved, "innovation_variance");
  preview.cross_covariance.resize(d);
  read_doubles(field(saved, "cross_covariance"), "cross_covariance", preview.cross_covariance);
  preview.gain.resize(d);
  read_doubles(field(saved, "gain"), "gain", preview.gain);
  preview.posterior_covariance.resize(d, d);
  read_matrix(field(saved, "posterior_covariance"), "posterior_covariance",
              preview.posterior_covariance);
  preview.posterior_factor.resize(d, d);
  read_matrix(field(saved, "posterior_factor"), "posterior_factor", preview.posterior_factor);
  preview.factorization.applied = static_cast<CovarianceRepair>(
      read_integer_field(saved, "repair", 0, static_cast<Index>(CovarianceRepair::nearest_pd)));
  preview.factorization.jitter = read_double_field(saved, "jitter");
  preview.factorization.clipped_eigenvalues = read_integer_field(saved, "clipped_eigenvalues", 0);
  preview.factorization.smallest_eigenvalue =
      read_double_field(saved, "smallest_eigenvalue", Values::any);
  return preview;
}

// --- assemblies -------------------------------------------------------------------------------

/// An AssemblyId as [upper, lower].
[[nodiscard]] inline nlohmann::json assembly_to_json(const AssemblyId& assembly) {
  return nlohmann::json::array({assembly.upper, assembly.lower});
}

/// The inverse of assembly_to_json: [upper, lower], upper >= 0 and lower >= −1 (−1: the id of
/// an assembly given by its scanned parts, AssemblyId's doc).
inline void read_assembly(const nlohmann::json& value, std::string_view name, AssemblyId& out) {
  require_array(value, name, 2);
  const Index upper = read_integer(value[0], fmt::format("{}[0]", name), 0);
  const Index lower = read_integer(value[1], fmt::format("{}[1]", name), -1);
  out = {upper, lower};
}

/// Any other assembly type that nlohmann-json converts (e.g. an external twin's JSON assembly).
template <typename A>
requires std::constructible_from<nlohmann::json, const A&>
[[nodiscard]] nlohmann::json assembly_to_json(const A& assembly) {
  return nlohmann::json(assembly);
}

template <typename A>
requires std::constructible_from<nlohmann::json, const A&>
void read_assembly(const nlohmann::json& value, std::string_view name, A& out) {
  try {
    out = value.get<A>();
  } catch (const nlohmann::json::exception& error) {
    throw InvalidArgumentError(
        std::string(name),
        fmt::format("{}: is {}; rule: must be an assembly ({})", name, value.dump(), error.what()));
  }
}

}  // namespace twincal::json_state
