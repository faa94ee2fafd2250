#pragma once
// What the experiments and serve suites share about external twins: the settings of a Python
// twin program with three locators.

#include <string>

#include "twincal/experiments/external_twin_settings.hpp"

namespace twincal::test_support {

/// An external twin run as `python3 program`, with the locators A, B, C in [-1, 1] and
/// upper_parts × lower_parts assemblies; u0 is searched with `optimum_evaluations` global and as
/// many local evaluations (few: each is a request to the program).
inline ExternalTwinSettings three_locator_python_twin(const std::string& program, Index upper_parts,
                                                      Index lower_parts,
                                                      Index optimum_evaluations) {
  ExternalTwinSettings settings;
  settings.command = {"python3", program};
  settings.locators = {"A", "B", "C"};
  settings.lower_bounds = {-1.0, -1.0, -1.0};
  settings.upper_bounds = {1.0, 1.0, 1.0};
  settings.upper_parts = upper_parts;
  settings.lower_parts = lower_parts;
  settings.optimum_global_evaluations = optimum_evaluations;
  settings.optimum_local_evaluations = optimum_evaluations;
  return settings;
}

}  // namespace twincal::test_support
