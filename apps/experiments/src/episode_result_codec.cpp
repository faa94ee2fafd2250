#include "twincal/experiments/episode_result_codec.hpp"

#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

using nlohmann::json;

// A matrix as {"rows", "cols", "data"} with its first `columns` columns, column-major.
json matrix_json(const MatrixX& matrix, Index columns) {
  json data = json::array();
  for (Index j = 0; j < columns; ++j) {
    for (Index i = 0; i < matrix.rows(); ++i) data.push_back(matrix(i, j));
  }
  return json{{"rows", matrix.rows()}, {"cols", columns}, {"data", std::move(data)}};
}

json vector_json(const VectorX& vector, Index entries) {
  return json(std::vector<double>(vector.data(), vector.data() + entries));
}

MatrixX matrix_from(const json& value) {
  const Index rows = value.at("rows").get<Index>();
  const Index cols = value.at("cols").get<Index>();
  const json& data = value.at("data");
  if (rows < 0 || cols < 0 || std::ssize(data) != rows * cols) {
    throw json::other_error::create(501, "a matrix's data does not match its size", &value);
  }
  MatrixX matrix(rows, cols);
  for (Index j = 0; j < cols; ++j) {
    for (Index i = 0; i < rows; ++i) matrix(i, j) = data[static_cast<std::size_t>(j * rows + i)];
  }
  return matrix;
}

VectorX vector_from(const json& value, Index entries) {
  const std::vector<double> data = value.get<std::vector<double>>();
  if (std::ssize(data) != entries) {
    throw json::other_error::create(501, "a trace column does not have `steps` entries", &value);
  }
  return Eigen::Map<const VectorX>(data.data(), entries);
}

}  // namespace

std::vector<std::uint8_t> encode_episode_result(const EpisodeResult& result) {
  const Index steps = result.steps;
  json assemblies = json::array();
  for (Index t = 0; t < steps; ++t) {
    const AssemblyId& x = result.assemblies[static_cast<std::size_t>(t)];
    assemblies.push_back(json::array({x.upper, x.lower}));
  }
  const json value{{"group", result.group},
                   {"controller", result.controller},
                   {"run", result.run},
                   {"run_seed", result.run_seed},
                   {"steps", steps},
                   {"assemblies", std::move(assemblies)},
                   {"z", vector_json(result.z, steps)},
                   {"z_star", vector_json(result.z_star, steps)},
                   {"control", matrix_json(result.control, steps)},
                   {"estimate", matrix_json(result.estimate, steps)},
                   {"offset", matrix_json(result.offset, steps)},
                   {"trace_p", vector_json(result.trace_p, steps)},
                   {"q_evaluations", vector_json(result.q_evaluations, steps)},
                   {"seconds", vector_json(result.seconds, steps)},
                   {"relative_residual", result.relative_residual},
                   {"estimation_error", result.estimation_error},
                   {"diverged_at", result.diverged_at},
                   {"seconds_per_assembly", result.seconds_per_assembly},
                   {"q_evaluations_per_assembly", result.q_evaluations_per_assembly},
                   {"failure", result.failure},
                   {"fallbacks", result.fallbacks},
                   {"dropped_measurements", result.dropped_measurements},
                   {"first_fallback_at", result.first_fallback_at},
                   {"first_fallback", result.first_fallback},
                   {"estimate_error_second_half", result.estimate_error_second_half},
                   {"offset_norm_second_half", result.offset_norm_second_half},
                   {"lost", result.lost}};
  return json::to_cbor(value);
}

EpisodeResult decode_episode_result(std::span<const std::uint8_t> bytes) {
  try {
    const json value = json::from_cbor(bytes.begin(), bytes.end());
    EpisodeResult result;
    result.group = value.at("group").get<std::string>();
    result.controller = value.at("controller").get<std::string>();
    result.run = value.at("run").get<Index>();
    result.run_seed = value.at("run_seed").get<std::uint64_t>();
    result.steps = value.at("steps").get<Index>();
    if (result.steps < 0) {
      throw json::other_error::create(501, "steps is negative", &value);
    }
    for (const json& x : value.at("assemblies")) {
      result.assemblies.push_back({x.at(0).get<Index>(), x.at(1).get<Index>()});
    }
    if (std::ssize(result.assemblies) != result.steps) {
      throw json::other_error::create(501, "assemblies do not number `steps`", &value);
    }
    result.z = vector_from(value.at("z"), result.steps);
    result.z_star = vector_from(value.at("z_star"), result.steps);
    result.control = matrix_from(value.at("control"));
    result.estimate = matrix_from(value.at("estimate"));
    result.offset = matrix_from(value.at("offset"));
    for (const MatrixX* trace : {&result.control, &result.estimate, &result.offset}) {
      if (trace->cols() != result.steps) {
        throw json::other_error::create(501, "a trace matrix does not have `steps` columns",
                                        &value);
      }
    }
    result.trace_p = vector_from(value.at("trace_p"), result.steps);
    result.q_evaluations = vector_from(value.at("q_evaluations"), result.steps);
    result.seconds = vector_from(value.at("seconds"), result.steps);
    result.relative_residual = value.at("relative_residual").get<double>();
    result.estimation_error = value.at("estimation_error").get<double>();
    result.diverged_at = value.at("diverged_at").get<Index>();
    result.seconds_per_assembly = value.at("seconds_per_assembly").get<double>();
    result.q_evaluations_per_assembly = value.at("q_evaluations_per_assembly").get<double>();
    result.failure = value.at("failure").get<std::string>();
    result.fallbacks = value.at("fallbacks").get<Index>();
    result.dropped_measurements = value.at("dropped_measurements").get<Index>();
    result.first_fallback_at = value.at("first_fallback_at").get<Index>();
    result.first_fallback = value.at("first_fallback").get<std::string>();
    result.estimate_error_second_half = value.at("estimate_error_second_half").get<double>();
    result.offset_norm_second_half = value.at("offset_norm_second_half").get<double>();
    result.lost = value.at("lost").get<bool>();
    return result;
  } catch (const json::exception& error) {
    throw Error("episode result",
                fmt::format("episode result: {} bytes are not an encoded EpisodeResult ({})",
                            bytes.size(), error.what()));
  }
}

}  // namespace twincal
