#include "twincal/calculix/calculix_results.hpp"

#include <gtest/gtest.h>

#include "twincal/calculix/calculix_error.hpp"

namespace twincal {
namespace {

// As CalculiX 2.20 writes it: a heading, a blank line, rows, a blank line.
constexpr const char* kDat = R"(
 displacements (vx,vy,vz) for set KEYS and time  0.1500000E+01

        34 -2.689416E-04 -6.266471E-04  1.058728E+00
        39 -2.415569E-04 -1.197404E-04  7.670911E-01

 displacements (vx,vy,vz) for set KEYS and time  0.2000000E+01

        34 -2.000000E-04 -6.000000E-04  1.000000E+00
        39 -2.400000E-04 -1.100000E-04  7.000000E-01

 displacements (vx,vy,vz) for set KEYS and time  0.4000000E+01

        34  1.000000E-04  2.000000E-04 -5.000000E-01
        39  0.000000E+00  0.000000E+00  2.500000E-01
)";

TEST(CalculixResults, ReadsEveryDisplacementBlock) {
  const std::vector<NodePrint> prints = read_displacement_prints(kDat);
  ASSERT_EQ(prints.size(), 3U);
  EXPECT_DOUBLE_EQ(prints[0].time, 1.5);
  ASSERT_EQ(prints[1].nodes.size(), 2U);
  EXPECT_EQ(prints[1].nodes[1], 39);
  EXPECT_DOUBLE_EQ(prints[1].displacements[1](2), 0.7);
  EXPECT_DOUBLE_EQ(prints[2].displacements[0](0), 1e-4);
}

TEST(CalculixResults, ReleasePrintsAreTheEndsOfEvenSteps) {
  const std::vector<NodePrint> releases = release_prints(read_displacement_prints(kDat));
  ASSERT_EQ(releases.size(), 2U);  // the increment at 1.5 is not a release
  EXPECT_DOUBLE_EQ(releases[0].time, 2.0);
  EXPECT_DOUBLE_EQ(releases[1].time, 4.0);
  // A missing release (the solve stopped in step 4) ends the list.
  std::vector<NodePrint> gap = read_displacement_prints(kDat);
  gap[1].time = 3.0;
  EXPECT_EQ(release_prints(gap).size(), 0U);
}

TEST(CalculixResults, MalformedRowsAreNamed) {
  try {
    (void)read_displacement_prints(
        " displacements (vx,vy,vz) for set KEYS and time  0.2E+01\n\n  34 1.0 nan 2.0\n");
    FAIL() << "no error";
  } catch (const CalculixError& error) {
    EXPECT_EQ(error.failure(), CalculixFailure::unreadable_results);
    EXPECT_NE(std::string(error.what()).find("34 1.0 nan 2.0"), std::string::npos);
  }
  EXPECT_THROW((void)read_displacement_prints(
                   " displacements (vx,vy,vz) for set KEYS and time\n\n 1 0 0 0\n"),
               CalculixError);
  EXPECT_TRUE(read_displacement_prints("no results here\n").empty());
}

}  // namespace
}  // namespace twincal
