#include "twincal/filters/filter_scheme.hpp"

#include <string>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

TEST(FilterSchemeNames, EverySpellingParsesBack) {
  for (const FilterScheme v : {FilterScheme::merwe, FilterScheme::julier, FilterScheme::cubature,
                               FilterScheme::fifth_degree, FilterScheme::simplex}) {
    EXPECT_EQ(parse_enum<FilterScheme>(to_string(v), "filter"), v);
  }
}

TEST(FilterSchemeNames, AnUnknownSpellingNamesTheSettingAndTheChoices) {
  try {
    (void)parse_enum<FilterScheme>("ukf", "--filter");
    FAIL() << "no error";
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "--filter");
    EXPECT_NE(std::string(error.what()).find("\"ukf\""), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("merwe, julier, cubature"), std::string::npos);
  }
}

}  // namespace
}  // namespace twincal
