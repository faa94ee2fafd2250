#include "twincal/experiments/controller_spec.hpp"

#include <charconv>
#include <cmath>
#include <optional>
#include <system_error>

#include <fmt/format.h>

#include "twincal/core/error.hpp"

namespace twincal {

std::vector<ControllerSpec> ControllerSpec::paper() {
  std::vector<ControllerSpec> specs{baseline(), default_controller()};
  // k/10 rather than accumulated steps of 0.1, so the labels read w=0.3, not w=0.30000000000000004.
  for (int k = 0; k <= 10; ++k) specs.push_back(lookahead(static_cast<double>(k) / 10.0));
  specs.push_back(active());
  return specs;
}

std::string ControllerSpec::label() const {
  switch (kind) {
    case Kind::baseline:
      return "baseline";
    case Kind::nominal:
      return "nominal";
    case Kind::default_control:
      return "default";
    case Kind::lookahead:
      return fmt::format("w={}", w);
    case Kind::per_component:
      return fmt::format("per-component:w={}", w);
    case Kind::active:
      return "active";
  }
  return "unknown";
}

namespace {

// The w of "w=<number>" in `text` (the whole label, for the message), or nothing if `form` is not
// of that form. @throws InvalidArgumentError for a w outside [0, 1].
std::optional<double> parse_w(std::string_view form, std::string_view text) {
  if (!form.starts_with("w=")) return std::nullopt;
  const std::string_view number = form.substr(2);
  double w = 0.0;
  const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), w);
  if (error != std::errc{} || end != number.data() + number.size()) return std::nullopt;
  if (!(w >= 0.0 && w <= 1.0)) {
    throw InvalidArgumentError(
        "controller",
        fmt::format("controller: \"{}\" has w = {}; rule: w must lie in [0, 1]", text, w));
  }
  return w;
}

}  // namespace

ControllerSpec ControllerSpec::parse(std::string_view text) {
  if (text == "baseline") return baseline();
  if (text == "nominal") return nominal();
  if (text == "default") return default_controller();
  if (text == "active") return active();
  if (const std::optional<double> w = parse_w(text, text)) return lookahead(*w);
  constexpr std::string_view per_component_prefix = "per-component:";
  if (text.starts_with(per_component_prefix)) {
    if (const std::optional<double> w = parse_w(text.substr(per_component_prefix.size()), text)) {
      return per_component(*w);
    }
  }
  throw InvalidArgumentError(
      "controller",
      fmt::format("controller: is \"{}\"; rule: must be baseline, nominal, default, "
                  "active, w=<number in [0, 1]> or per-component:w=<number in [0, 1]>",
                  text));
}

}  // namespace twincal
