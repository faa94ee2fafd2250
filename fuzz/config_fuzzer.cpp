// Any bytes as a config file (`twincal run --config`) and as a sweep file (`twincal sweep`):
// reading, converting and checking them — what run and dry run do before anything runs —
// answers a config or a twincal::Error naming what is wrong, never another exception, and a
// config that passes round-trips through JSON unchanged.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"
#include "twincal/experiments/config_file.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/experiments/experiment_group.hpp"
#include "twincal/experiments/experiment_runner.hpp"
#include "twincal/experiments/sweep.hpp"

namespace {

using namespace twincal;

void as_config(const nlohmann::json& document) {
  const ExperimentGroup group{document.get<ExperimentConfig>()};
  (void)require_study_fits(std::span(&group, 1));
  const nlohmann::json written = group.config;
  const nlohmann::json again = written.get<ExperimentConfig>();
  if (again != written) {
    fmt::print(stderr, "config fuzzer: {} reads back as {}\n", written.dump(), again.dump());
    std::abort();
  }
}

void as_sweep(const nlohmann::json& document) {
  const std::vector<ExperimentGroup> groups = expand_sweep(document);
  (void)require_study_fits(groups);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  nlohmann::json document;
  try {
    document = parse_config_text(text, "study.json");
  } catch (const InvalidArgumentError&) {
    return 0;
  }
  try {
    as_config(document);
  } catch (const Error&) {
  }
  try {
    as_sweep(document);
  } catch (const Error&) {
  }
  return 0;
}
