#pragma once
/// @file
/// The active controller's settings in a config: the `active` object of an experiment config
/// (docs/cli.md) holds the ActiveOptions fields a study changes from their defaults, with the
/// estimator's and the surrogate's under `trajectory` and `surrogate`, e.g.
/// `{"regret_probe": 0.2, "trajectory": {"velocity_fraction": 0.02}}`. So an ablation of the
/// controller is a sweep axis (`"active.trajectory.change_gate": [1.5, 2, 3]`), not a rebuild.
///
/// The JSON names are the C++ members'. σz² and the initial variance are not among them: they
/// are the config's own `measurement_variance` and `initial_variance`, which every controller
/// shares.

#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "twincal/controllers/active/active_options.hpp"

namespace twincal {

/// The fields of `options` that differ from a default-constructed ActiveOptions (an empty object
/// when none does), nested as apply_active_overrides() reads them. Numbers are written as they
/// are held, so that reading them back gives the same bits.
[[nodiscard]] nlohmann::json active_overrides(const ActiveOptions& options);

/// Sets the fields `overrides` names on `options`; `path` names the object in errors ("active"
/// in a config). Integers must be JSON integers, flags JSON booleans; validation is the owner's
/// (ActiveOptions::validate()).
/// @throws InvalidArgumentError naming "<path>.<key>" for a key ActiveOptions does not have (the
///         message lists the ones it has), for measurement_variance and initial_variance (the
///         config's own keys), for a value of the wrong type, or when `overrides` or a nested
///         section is not a JSON object. `options` is untouched then.
void apply_active_overrides(const nlohmann::json& overrides, ActiveOptions& options,
                            std::string_view path = "active");

}  // namespace twincal
