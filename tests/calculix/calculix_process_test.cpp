#include "twincal/calculix/calculix_process.hpp"

#include <filesystem>

#include <gtest/gtest.h>

namespace twincal {
namespace {

CalculixRun finished(int exit_status, std::string log) {
  CalculixRun run;
  run.exit_status = exit_status;
  run.log = std::move(log);
  return run;
}

TEST(CalculixProcess, ClassifiesFinishedRunsByTheirLogs) {
  EXPECT_FALSE(classify(finished(0, " STEP 2\n divergence; the increment size is decreased\n")));
  EXPECT_EQ(classify(finished(201, " STEP 1\n *ERROR: too many cutbacks\n")),
            CalculixFailure::no_convergence);
  EXPECT_EQ(classify(finished(201, " STEP 3\n *ERROR: increment size smaller than minimum\n")),
            CalculixFailure::no_convergence);
  EXPECT_EQ(classify(finished(201, " *ERROR reading *BOUNDARY: node 99999 is not defined\n")),
            CalculixFailure::deck_error);
  EXPECT_EQ(classify(finished(134, "free(): invalid pointer\n")), CalculixFailure::crashed);
}

TEST(CalculixProcess, LogTailKeepsTheLastLines) {
  EXPECT_EQ(log_tail("a\nb\nc\nd\n", 2), "c\nd\n");
  EXPECT_EQ(log_tail("only", 3), "only");
}

TEST(CalculixProcess, AMissingSolverIsNamed) {
  CalculixOptions options;
  options.executable = "twincal-no-such-solver";
  const std::filesystem::path directory =
      std::filesystem::temp_directory_path() / "twincal-calculix-process-test";
  std::filesystem::create_directories(directory);
  try {
    (void)run_calculix(options, directory, "job", "*HEADING\n");
    FAIL() << "started a missing solver";
  } catch (const CalculixError& error) {
    EXPECT_EQ(error.failure(), CalculixFailure::missing_executable);
    EXPECT_NE(std::string(error.what()).find("twincal-no-such-solver"), std::string::npos);
  }
  std::filesystem::remove_all(directory);
}

}  // namespace
}  // namespace twincal
