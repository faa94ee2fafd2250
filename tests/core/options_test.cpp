#include "twincal/core/options.hpp"

#include <gtest/gtest.h>

namespace twincal {
namespace {

struct StepOptions {
  double step = 1.0;
  [[nodiscard]] std::optional<std::string> validate() const {
    if (step > 0.0) return std::nullopt;
    return fmt::format("step is {}; it must be > 0", step);
  }
};

struct NoValidate {
  double step = 1.0;
};

static_assert(ValidatableOptions<StepOptions>);
static_assert(!ValidatableOptions<NoValidate>);

TEST(RequireValid, PassesValidOptions) {
  EXPECT_NO_THROW(require_valid("StepOptions", StepOptions{}));
}

TEST(RequireValid, ThrowsTheSentenceWithTheOptionsName) {
  try {
    require_valid("StepOptions", StepOptions{.step = -2.0});
    FAIL() << "expected InvalidArgumentError";
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(std::string(e.what()), "StepOptions: step is -2; it must be > 0");
    EXPECT_EQ(e.argument(), "StepOptions");
  }
}

}  // namespace
}  // namespace twincal
