#include "twincal/core/options.hpp"

#include <cstdint>
#include <limits>

#include <gtest/gtest.h>

namespace twincal {
namespace {

struct StepOptions {
  double step = 1.0;
  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem({rule::positive_finite("step", step)});
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
    EXPECT_EQ(std::string(e.what()),
              "StepOptions: step: value is -2; rule: must be finite and > 0");
    EXPECT_EQ(e.argument(), "StepOptions");
  }
}

TEST(OptionRules, HoldOrSayTheFieldTheValueAndTheRule) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(rule::positive_finite("a", 1e-300), std::nullopt);
  EXPECT_EQ(*rule::positive_finite("a", 0.0), "a: value is 0; rule: must be finite and > 0");
  EXPECT_TRUE(rule::positive_finite("a", inf) && rule::positive_finite("a", nan));
  EXPECT_EQ(rule::non_negative_finite("a", 0.0), std::nullopt);
  EXPECT_EQ(*rule::non_negative_finite("a", -0.5),
            "a: value is -0.5; rule: must be finite and >= 0");
  EXPECT_EQ(rule::finite_above("g", 1.5, 1.0), std::nullopt);
  EXPECT_EQ(*rule::finite_above("g", 1.0, 1.0), "g: value is 1; rule: must be finite and > 1");
  EXPECT_EQ(rule::finite_at_least("m", 1.0, 1.0), std::nullopt);
  EXPECT_EQ(*rule::finite_at_least("m", inf, 1.0),
            "m: value is inf; rule: must be finite and >= 1");
  EXPECT_EQ(rule::in_closed("w", 0.0, 0.0, 1.0), std::nullopt);
  EXPECT_EQ(rule::in_closed("w", 1.0, 0.0, 1.0), std::nullopt);
  EXPECT_EQ(*rule::in_closed("w", 1.5, 0.0, 1.0), "w: value is 1.5; rule: must lie in [0, 1]");
  EXPECT_TRUE(rule::in_closed("w", nan, 0.0, 1.0));
  EXPECT_EQ(rule::in_left_open("f", 0.5, 0.0, 0.5), std::nullopt);
  EXPECT_EQ(*rule::in_left_open("f", 0.0, 0.0, 0.5), "f: value is 0; rule: must lie in (0, 0.5]");
  EXPECT_EQ(rule::in_right_open("r", 0.0, 0.0, 1.0), std::nullopt);
  EXPECT_EQ(*rule::in_right_open("r", 1.0, 0.0, 1.0), "r: value is 1; rule: must lie in [0, 1)");
  EXPECT_EQ(rule::in_open("c", 0.25, 0.0, 0.5), std::nullopt);
  EXPECT_EQ(*rule::in_open("c", 0.5, 0.0, 0.5), "c: value is 0.5; rule: must lie in (0, 0.5)");
  EXPECT_EQ(rule::at_least("n", 1, 1), std::nullopt);
  EXPECT_EQ(*rule::at_least("n", std::int64_t{0}, std::int64_t{1}),
            "n: value is 0; rule: must be >= 1");
}

TEST(OptionRules, FirstProblemIsTheFirstBrokenRuleInOrder) {
  EXPECT_EQ(first_problem({}), std::nullopt);
  EXPECT_EQ(first_problem({rule::positive_finite("a", 1.0), rule::at_least("n", 3, 1)}),
            std::nullopt);
  EXPECT_EQ(*first_problem({rule::positive_finite("a", 1.0), rule::at_least("n", 0, 1),
                            rule::positive_finite("b", -1.0)}),
            "n: value is 0; rule: must be >= 1");
}

}  // namespace
}  // namespace twincal
