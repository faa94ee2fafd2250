#pragma once
/// @file
/// `IndividualizedController`: Def. 2, eq. (3), the paper's baseline. Each assembly gets its own
/// optimum u0(x_t) = argmin_u Q(x_t, u; θ0) in the (uncalibrated) twin. It does not learn from
/// measurements, so it cannot diverge — nor can it correct the offset δu*.

#include <string_view>
#include <utility>

#include <nlohmann/json.hpp>

#include "twincal/controllers/controller_state_json.hpp"
#include "twincal/controllers/individual_optimum.hpp"
#include "twincal/controllers/nlopt_optimizer.hpp"
#include "twincal/controllers/optimizer.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

template <Twin T, Optimizer O = NloptOptimizer>
class IndividualizedController {
 public:
  using Assembly = typename T::Assembly;
  using ControlVector = VectorX;

  explicit IndividualizedController(const T& twin, O optimizer = O{})
      : optimum_(twin, std::move(optimizer)) {}

  /// u0(x_t); also recorded with z*(x_t) in last_optimum().
  [[nodiscard]] ControlVector propose(const Assembly& assembly) {
    last_ = optimum_(assembly);
    return last_.control;
  }

  /// The baseline ignores feedback.
  void observe(const Assembly& /*assembly*/, const ControlVector& /*control*/,
               double /*z*/) const noexcept {}

  /// u0, z* and the evaluations of the last propose.
  [[nodiscard]] const IndividualControl& last_optimum() const noexcept { return last_; }

  static constexpr std::string_view json_format = "twincal.individualized_controller";

  /// The baseline learns nothing; its snapshot keeps last_optimum(), the report of the last
  /// proposal (an empty control before the first).
  [[nodiscard]] nlohmann::json save() const {
    return {{"format", json_format},
            {"dimension", optimum_.twin().control_dimension()},
            {"last_control", json_state::doubles_to_json(last_.control)},
            {"last_quality", json_state::number_to_json(last_.quality)},
            {"last_evaluations", last_.evaluations}};
  }

  /// Restores a snapshot of save(). @throws InvalidArgumentError, DimensionMismatchError,
  /// NonFiniteError naming the field; the controller unchanged.
  void restore(const nlohmann::json& saved) {
    const Index d = optimum_.twin().control_dimension();
    json_state::require_header(saved, json_format, d);
    IndividualControl last;
    last.control = json_state::read_vector<VectorX>(json_state::field(saved, "last_control"),
                                                    "last_control", d);
    last.quality = json_state::read_double_field(saved, "last_quality");
    last.evaluations = json_state::read_count(saved, "last_evaluations");
    last_ = std::move(last);
  }

 private:
  IndividualOptimum<T, O> optimum_;
  IndividualControl last_;
};

}  // namespace twincal
