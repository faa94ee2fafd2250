#include "twincal/core/named_enum.hpp"

#include <array>
#include <string>
#include <type_traits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

enum class NamedEnumShape { circle, square, unlisted };

[[nodiscard]] constexpr auto name_table(std::type_identity<NamedEnumShape>) noexcept {
  return std::to_array<NameEntry<NamedEnumShape>>(
      {{NamedEnumShape::circle, "circle"}, {NamedEnumShape::square, "square"}});
}

static_assert(NamedEnum<NamedEnumShape>);
static_assert(to_string(NamedEnumShape::square) == "square");
static_assert(noexcept(to_string(NamedEnumShape::circle)));

TEST(NamedEnum, NamesEveryListedValue) {
  EXPECT_EQ(to_string(NamedEnumShape::circle), "circle");
  EXPECT_EQ(to_string(NamedEnumShape::unlisted), "unknown");
}

TEST(NamedEnum, EverySpellingParsesBack) {
  for (const NamedEnumShape v : {NamedEnumShape::circle, NamedEnumShape::square}) {
    EXPECT_EQ(parse_enum<NamedEnumShape>(to_string(v), "shape"), v);
  }
}

TEST(NamedEnum, AnUnknownSpellingNamesTheSettingAndTheChoices) {
  EXPECT_THAT([] { (void)parse_enum<NamedEnumShape>("triangle", "--shape"); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "--shape: is \"triangle\"; rule: must be one of [circle, square]"));
}

}  // namespace
}  // namespace twincal
