#include "twincal/serve/history_export.hpp"

#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "serve_testing.hpp"
#include "twincal/serve/serve_session.hpp"

namespace twincal {
namespace {

using json = nlohmann::json;
using test_support::TemporaryDatabase;

std::vector<std::string> csv_lines(const HistoryStore& store) {
  std::ostringstream out;
  write_history_csv(store, out);
  std::vector<std::string> lines;
  std::istringstream in(out.str());
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

ServeSession analytic_session(const std::string& controller, const TemporaryDatabase& database) {
  return ServeSession::start(test_support::analytic_options(controller, 2), database.get());
}

TEST(HistoryExport, WritesOneRowPerRequestWithEmptyFieldsWhileAwaitingTheObservation) {
  const TemporaryDatabase database;
  ServeSession session = analytic_session("default", database);
  const json first = json::parse(session.handle(R"({"op": "propose", "assembly": 12})"));
  ASSERT_TRUE(first["ok"].get<bool>());
  ASSERT_TRUE(
      json::parse(session.handle(R"({"op": "observe", "request_id": 1, "quality": 0.5})"))["ok"]
          .get<bool>());
  ASSERT_TRUE(json::parse(session.handle(R"({"op": "propose", "assembly": 3})"))["ok"].get<bool>());

  const std::vector<std::string> lines = csv_lines(session.history());
  ASSERT_EQ(lines.size(), 3U);
  EXPECT_EQ(lines[0],
            "request_id,upper,lower,assembly,proposed_at,observed_at,quality,optimal_quality,"
            "control_A,"
            "control_B,estimate_A,estimate_B,sd_A,sd_B");
  const json state = session.state();
  const std::vector<std::string> row = [&] {
    std::vector<std::string> fields;
    std::istringstream in(lines[1]);
    for (std::string f; std::getline(in, f, ',');) fields.push_back(f);
    return fields;
  }();
  ASSERT_EQ(row.size(), 14U);
  EXPECT_EQ(row[0], "1");
  EXPECT_EQ(json::array({std::stoll(row[1]), std::stoll(row[2])}), first["assembly"]);
  EXPECT_EQ(row[3], "");
  EXPECT_EQ(row[6], "0.5");
  EXPECT_EQ(std::stod(row[7]), first["report"]["optimal_quality"].get<double>());
  EXPECT_EQ(std::stod(row[8]), first["control"][0].get<double>());
  EXPECT_EQ(std::stod(row[10]), state["estimate"][0].get<double>());
  EXPECT_GT(std::stod(row[12]), 0.0);
  // Request 2 awaits its observation: observed_at, quality, estimates and sds are empty.
  EXPECT_THAT(lines[2], ::testing::StartsWith("2,"));
  EXPECT_THAT(lines[2], ::testing::EndsWith(",,,,"));
}

TEST(HistoryExport, LeavesTheStandardDeviationsOfAControllerWithoutCovarianceEmpty) {
  const TemporaryDatabase database;
  ServeSession session = analytic_session("baseline", database);
  ASSERT_TRUE(json::parse(session.handle(R"({"op": "propose", "assembly": 0})"))["ok"].get<bool>());
  ASSERT_TRUE(
      json::parse(session.handle(R"({"op": "observe", "request_id": 1, "quality": 0.7})"))["ok"]
          .get<bool>());
  const std::vector<std::string> lines = csv_lines(session.history());
  ASSERT_EQ(lines.size(), 2U);
  EXPECT_THAT(lines[1], ::testing::EndsWith(",0.0,0.0,,"));
}

}  // namespace
}  // namespace twincal
