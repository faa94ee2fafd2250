// Compile-time checks of twincal's concepts: what each accepts and what it rejects. A failing
// static_assert fails the build, naming the requirement.
#include <cstdint>
#include <optional>
#include <string>

#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"

namespace twincal::static_checks {

// --- ValidatableOptions ----------------------------------------------------------------------
struct GoodOptions {
  [[nodiscard]] std::optional<std::string> validate() const { return std::nullopt; }
};
struct BoolValidate {  // a bool says that something is wrong, not what
  [[nodiscard]] bool validate() const { return true; }
};
static_assert(ValidatableOptions<GoodOptions>);
static_assert(!ValidatableOptions<BoolValidate>);

// --- RandomStream is a standard random bit generator ------------------------------------------
static_assert(std::uniform_random_bit_generator<RandomStream>);

}  // namespace twincal::static_checks
