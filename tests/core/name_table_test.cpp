#include "twincal/core/name_table.hpp"

#include <array>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

enum class NameTableColour { red, green, light_blue, unlisted };

constexpr auto colour_names =
    std::to_array<NameEntry<NameTableColour>>({{NameTableColour::red, "red"},
                                               {NameTableColour::green, "green"},
                                               {NameTableColour::light_blue, "light-blue"}});

static_assert(name_of(colour_names, NameTableColour::green) == "green");
static_assert(noexcept(name_of(colour_names, NameTableColour::red)));

TEST(NameTable, NamesEveryListedValue) {
  EXPECT_EQ(name_of(colour_names, NameTableColour::red), "red");
  EXPECT_EQ(name_of(colour_names, NameTableColour::light_blue), "light-blue");
  EXPECT_EQ(name_of(colour_names, NameTableColour::unlisted), "unknown");
}

TEST(NameTable, EverySpellingParsesBack) {
  for (const NameEntry<NameTableColour>& entry : colour_names) {
    EXPECT_EQ(parse_name(colour_names, entry.name, "colour"), entry.value) << entry.name;
  }
}

TEST(NameTable, AnUnknownSpellingNamesTheSettingAndTheChoices) {
  EXPECT_THAT([] { (void)parse_name(colour_names, "blue", "--colour"); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  "--colour: is \"blue\"; rule: must be one of [red, green, light-blue]"));
  try {
    (void)parse_name(colour_names, "", "colour");
    FAIL() << "no error";
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "colour");
    EXPECT_EQ(std::string(error.what()),
              "colour: is \"\"; rule: must be one of [red, green, light-blue]");
  }
}

TEST(NameTable, ParsingIsExact) {
  EXPECT_THROW((void)parse_name(colour_names, "Red", "colour"), InvalidArgumentError);
  EXPECT_THROW((void)parse_name(colour_names, "red ", "colour"), InvalidArgumentError);
  EXPECT_THROW((void)parse_name(colour_names, "unknown", "colour"), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal
