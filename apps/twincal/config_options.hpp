#pragma once
// The command-line options that set an ExperimentConfig (run, paper, scaling, serve): one table
// holds each option's flag, its help and how it sets the config, so that `--help` and what
// runs are one declaration. Defaults and choices in the help are read from ExperimentConfig{}
// and the enums' name tables, never written twice.

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "arguments.hpp"
#include "twincal/experiments/controller_spec.hpp"
#include "twincal/experiments/experiment_config.hpp"

namespace twincal::cli {

/// One option of the table.
struct ConfigOption {
  std::string_view flag;        ///< without the leading "--"
  std::string_view value_name;  ///< "N", "NAME", …; empty for a flag
  /// The help sentence, given the default config (for its defaults).
  std::string (*help)(const ExperimentConfig& defaults);
  /// Sets the config from the option if given; null where another row's apply reads it (the
  /// external twin's two options are applied together).
  void (*apply)(Arguments& arguments, ExperimentConfig& config);
};

/// Every option that sets an ExperimentConfig, in the order --help lists and applies them
/// (after --config, which gives the base they override).
[[nodiscard]] std::span<const ConfigOption> config_options();

/// The help of config_options(), one option per line, wrapped at 100 columns.
[[nodiscard]] std::string config_options_help();

/// The base config from --config (or the defaults, with `default_controllers`), then every
/// option of config_options() given in `arguments`. Controllers are `default_controllers`
/// unless the config file or --controllers names them.
/// @throws InvalidArgumentError naming the option and the rule it broke.
[[nodiscard]] ExperimentConfig read_config(
    Arguments& arguments,
    const std::vector<ControllerSpec>& default_controllers = ControllerSpec::paper());

/// --twin-command and --twin-workers: the program and the processes of the external twin of
/// every config (which must describe one: its locators and bounds come from the config).
/// @throws InvalidArgumentError when a config has no external_twin.
void apply_twin_options(Arguments& arguments, std::span<ExperimentConfig> configs);

}  // namespace twincal::cli
