#include "twincal/serve/serve_session.hpp"

#include <sqlite3.h>

#include <fstream>
#include <iterator>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../experiments/external_twin_testing.hpp"
#include "serve_testing.hpp"

#include "twincal/experiments/episode_runner.hpp"
#include "twincal/serve/history_export.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;
using json = nlohmann::json;
namespace fs = std::filesystem;

using test_support::analytic_options;
using test_support::TemporaryDatabase;

json call(ServeSession& session, const json& request) {
  return json::parse(session.handle(request.dump()));
}

// The cell: the plant is the twin with its locators shifted by a fixed offset δu*.
double plant(const ServeSession& session, Index assembly, const json& control) {
  VectorX u(std::ssize(control));
  for (Index i = 0; i < u.size(); ++i) {
    u(i) = control[static_cast<std::size_t>(i)].get<double>() - 0.04 * static_cast<double>(i + 1);
  }
  return session.twin().plant_quality(
      session.twin().assemblies()[static_cast<std::size_t>(assembly)], u);
}

// Assemblies [from, to) of the cell: the controls proposed.
std::vector<json> drive(ServeSession& session, int from, int to) {
  std::vector<json> controls;
  for (int t = from; t < to; ++t) {
    const Index assembly = (7 * t) % 100;
    const json proposal = call(session, {{"op", "propose"}, {"assembly", assembly}});
    EXPECT_TRUE(proposal["ok"].get<bool>()) << proposal.dump();
    const json observed =
        call(session, {{"op", "observe"},
                       {"request_id", proposal["request_id"]},
                       {"quality", plant(session, assembly, proposal["control"])}});
    EXPECT_TRUE(observed["ok"].get<bool>()) << observed.dump();
    controls.push_back(proposal["control"]);
  }
  return controls;
}

TEST(ServeSession, ProposesTheControlsOfTheEpisodeControllerDrivenDirectly) {
  const TemporaryDatabase database;
  const ServeOptions options = analytic_options("active");
  ServeSession session = ServeSession::start(options, database.get());
  const std::vector<json> controls = drive(session, 0, 12);

  AnyController direct =
      make_episode_controller(session.twin(), options.config, options.controller, options.run);
  VectorX u(3);
  for (int t = 0; t < 12; ++t) {
    const Index assembly = (7 * t) % 100;
    const AssemblyId x = session.twin().assemblies()[static_cast<std::size_t>(assembly)];
    direct.propose(x, u);
    for (Index i = 0; i < 3; ++i) {
      ASSERT_EQ(u(i), controls[static_cast<std::size_t>(t)][static_cast<std::size_t>(i)])
          << "assembly " << t;
    }
    json u_json = json::array({u(0), u(1), u(2)});
    direct.observe(x, u, plant(session, assembly, u_json));
  }
  EXPECT_EQ(session.observed(), 12);
  EXPECT_EQ(session.history().records().size(), 12U);
}

// Resuming after any record is the same as never stopping, for filtered and unfiltered
// controllers alike (the baseline's covariance is null in the history).
// For every controller, a session killed between a proposal and its observation resumes to the
// controls and state of an uninterrupted one: replaying its whole history (no snapshots), from
// its last snapshot (every 3 observations: the one after request 6, request 7 replayed), and
// from the beginning with every snapshot compared (verify_all).
TEST(ServeSession, ResumesBitForBitFromItsHistory) {
  struct Way {
    std::int64_t snapshot_interval;
    bool verify_all;
  };
  for (const std::string controller : {"active", "w=0.5", "default", "baseline"}) {
    const TemporaryDatabase whole_db;
    ServeSession whole = ServeSession::start(analytic_options(controller), whole_db.get());
    const std::vector<json> expected = drive(whole, 0, 16);
    for (const Way way : {Way{0, false}, Way{3, false}, Way{3, true}}) {
      const std::string label =
          fmt::format("{}, snapshots every {}{}", controller, way.snapshot_interval,
                      way.verify_all ? ", verify_all" : "");
      const TemporaryDatabase split_db;
      std::vector<json> controls;
      {
        ServeOptions options = analytic_options(controller);
        options.snapshot_interval = way.snapshot_interval;
        ServeSession first = ServeSession::start(options, split_db.get());
        controls = drive(first, 0, 7);
        // Killed between a proposal and its observation.
        EXPECT_TRUE(
            call(first, {{"op", "propose"}, {"assembly", (7 * 7) % 100}})["ok"].get<bool>());
      }
      const std::vector<std::int64_t> snapshots = way.snapshot_interval == 3
                                                      ? std::vector<std::int64_t>{3, 6}
                                                      : std::vector<std::int64_t>{};
      EXPECT_EQ(HistoryStore::open_read_only(split_db.get()).snapshot_requests(), snapshots)
          << label;
      ServeSession second = ServeSession::resume(
          split_db.get(), ResumeOptions{.durability = Durability::normal,
                                        .snapshot_interval = way.snapshot_interval,
                                        .verify_all = way.verify_all});
      EXPECT_EQ(second.observed(), 7) << label;
      ASSERT_FALSE(second.state()["pending"].is_null()) << label;
      // The cell re-sends the pending assembly and gets the same proposal back.
      const json again = call(second, {{"op", "propose"}, {"assembly", (7 * 7) % 100}});
      EXPECT_TRUE(again["repeated"].get<bool>());
      EXPECT_EQ(again["control"], expected[7]) << label;
      ASSERT_TRUE(call(second, {{"op", "observe"},
                                {"request_id", again["request_id"]},
                                {"quality", plant(second, 49, again["control"])}})["ok"]
                      .get<bool>());
      const std::vector<json> rest = drive(second, 8, 16);
      controls.push_back(again["control"]);
      controls.insert(controls.end(), rest.begin(), rest.end());
      EXPECT_EQ(controls, expected) << label;
      EXPECT_EQ(second.state()["estimate"], whole.state()["estimate"]) << label;
      EXPECT_EQ(second.state()["covariance"], whole.state()["covariance"]) << label;
    }
  }
}

TEST(ServeSession, StoresASnapshotAtCheckpointAndShutdownAndChecksEveryOne) {
  const TemporaryDatabase database;
  {
    ServeOptions options = analytic_options("active");
    options.snapshot_interval = 4;
    ServeSession session = ServeSession::start(options, database.get());
    drive(session, 0, 6);
    EXPECT_TRUE(call(session, {{"op", "checkpoint"}})["ok"].get<bool>());  // after request 6
    drive(session, 6, 9);
    EXPECT_TRUE(call(session, {{"op", "shutdown"}})["ok"].get<bool>());  // after request 9
  }
  EXPECT_EQ(HistoryStore::open_read_only(database.get()).snapshot_requests(),
            (std::vector<std::int64_t>{4, 6, 8, 9}));
  const HistoryCheck verified = ServeSession::check(database.get());
  EXPECT_EQ(verified.requests, 9);
  EXPECT_EQ(verified.snapshots, 4);

  // A snapshot edited and sealed again: the full replay finds it.
  test_support::edit_database(database.get(),
                              "UPDATE snapshots SET state = replace(state, '\"request_id\":6', "
                              "'\"request_id\":6,\"edited\":true') WHERE request_id = 6");
  EXPECT_THROW((void)ServeSession::check(database.get()), HistoryDamageError);
  test_support::reseal_history(database.get());
  try {
    (void)ServeSession::check(database.get());
    FAIL() << "checked a history whose snapshot was edited";
  } catch (const HistoryMismatchError& error) {
    EXPECT_EQ(error.argument(), "snapshot");
    EXPECT_THAT(error.what(), HasSubstr("request 6 replays to another snapshot"));
  }
}

TEST(ServeSession, RefusesASnapshotItCannotRestore) {
  const TemporaryDatabase database;
  {
    ServeOptions options = analytic_options("w=1");
    options.snapshot_interval = 2;
    ServeSession session = ServeSession::start(options, database.get());
    drive(session, 0, 5);
  }
  // The last snapshot's filter state loses its covariance: refused, naming the snapshot.
  test_support::edit_database(
      database.get(),
      "UPDATE snapshots SET state = json_remove(state, '$.controller.filter') "
      "WHERE request_id = 4");
  test_support::reseal_history(database.get());
  try {
    (void)ServeSession::resume(database.get(), Durability::normal);
    FAIL() << "restored a snapshot without its filter";
  } catch (const HistoryMismatchError& error) {
    EXPECT_EQ(error.argument(), "snapshot");
    EXPECT_THAT(error.what(), HasSubstr("the snapshot after request 4 cannot be restored"));
  }
  // The whole replay does not need it, and finds it differs.
  EXPECT_THROW(
      (void)ServeSession::resume(
          database.get(), ResumeOptions{.durability = Durability::normal, .verify_all = true}),
      HistoryMismatchError);
}

TEST(ServeSession, AnswersEveryBadRequestWithAnErrorAndChangesNothing) {
  const TemporaryDatabase database;
  ServeSession session = ServeSession::start(analytic_options("active"), database.get());
  drive(session, 0, 3);
  const json pending = call(session, {{"op", "propose"}, {"assembly", 5}});
  ASSERT_TRUE(pending["ok"].get<bool>());
  const json before = session.state();
  const std::size_t records = session.history().records().size();
  const std::int64_t id = pending["request_id"].get<std::int64_t>();

  struct Case {
    std::string line;
    std::string field;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"{not json", "line", "line: is not JSON"},
      {"", "line", "line: is empty; rule: one JSON request (an object) per line"},
      {" \t", "line", "line: is empty"},
      {"[1, 2]", "line", "line: is a JSON array; rule: a request is an object"},
      {R"({"assembly": 1})", "op", "op: is missing or not a string"},
      {R"({"op": "fly"})", "op", R"(op: is "fly"; rule: one of propose, observe, predict)"},
      {R"({"op": "state", "verbose": true})", "verbose",
       "verbose: is not a field of state; rule: state takes op"},
      {R"({"op": "propose", "assembly": 6})", "op",
       fmt::format("op: propose while request {} (assembly", id)},
      {R"({"op": "propose", "assembly": 100})", "assembly",
       "assembly: is 100; rule: an index must lie in [0, 99]"},
      {R"({"op": "propose", "assembly": [99, 99]})", "assembly",
       "assembly: is [99, 99]; rule: must be one of the twin's 100 assemblies"},
      {R"({"op": "propose", "assembly": "x"})", "assembly", "assembly: is \"x\"; rule: an index"},
      {R"({"op": "propose", "assembly": 5, "parts": {}})", "parts",
       "parts: this twin's assemblies are its own part indices; rule: only a twin that takes "
       "scanned parts (the external case) accepts them"},
      {R"({"op": "propose", "assembly": "s-1", "parts": null})", "parts",
       "parts: is null; rule: the scanned parts"},
      {R"({"op": "propose", "assembly": 5, "color": "red"})", "color",
       "color: is not a field of propose; rule: propose takes op, assembly, parts"},
      {fmt::format(R"({{"op": "observe", "request_id": {}, "quality": null}})", id), "quality",
       "quality: is null; rule: must be a finite number"},
      {fmt::format(R"({{"op": "observe", "request_id": {}, "quality": "nan"}})", id), "quality",
       "quality: is \"nan\"; rule: must be a finite number"},
      {fmt::format(R"({{"op": "observe", "request_id": {}}})", id), "quality",
       "quality: is missing"},
      {R"({"op": "observe", "request_id": 1, "quality": 1.0})", "request_id",
       fmt::format("request_id: 1 was already observed; rule: request {} awaits", id)},
      {R"({"op": "observe", "request_id": 99, "quality": 1.0})", "request_id",
       "request_id: 99 is unknown"},
      {R"({"op": "observe", "request_id": "4", "quality": 1.0})", "request_id",
       "request_id: is missing or not an integer"},
      {R"({"op": "predict", "assembly": 5, "control": [0, 0]})", "control",
       "control: is [0,0]; rule: an array of 3 numbers"},
      // Numbers beyond double's range, integers beyond 64 bits, nesting beyond the bound: each
      // once ended the server for every client.
      {R"({"op": "state", "x": 1e309})", "line", "number overflow parsing '1e309'"},
      {R"({"op": "state", "x": 123456789012345678901234567890})", "x",
       "x: is not a field of state"},
      {std::string(100, '[') + std::string(100, ']'), "line",
       "line: nests 100 levels of arrays and objects; rule: at most 64"},
      {R"({"op": "state", "case": )" + std::string(200000, '[') + "}", "line",
       "line: nests 200001 levels"},
      // Not UTF-8: quoted back as U+FFFD, the reply still valid JSON.
      {"{\"op\": \"\xff\"}", "line", "line: is not JSON"},
      {"{\"op\": \"state\", \"\xc3\": 1", "line", "line: is not JSON"},
      {std::string(ServeSession::max_line_bytes + 1, ' '), "line",
       fmt::format("line: has {} bytes; rule: at most {} bytes", ServeSession::max_line_bytes + 1,
                   ServeSession::max_line_bytes)},
  };
  for (const Case& c : cases) {
    const json reply = json::parse(session.handle(c.line));
    EXPECT_FALSE(reply["ok"].get<bool>()) << c.line.substr(0, 80);
    EXPECT_EQ(reply["error"]["field"], c.field) << c.line.substr(0, 80);
    EXPECT_THAT(reply["error"]["message"].get<std::string>(), HasSubstr(c.message));
    EXPECT_EQ(session.state(), before) << c.line.substr(0, 80);
    EXPECT_EQ(session.history().records().size(), records);
  }
  EXPECT_FALSE(session.finished());
}

// A finite but absurd quality (1e154) once left the paper's filter with a NaN covariance, and
// every later request failed on it. Now an observation is either taken with a finite, positive
// definite state, or refused naming the quality with the state as before it; either way the cell
// goes on: the same assembly is observed properly and 20 more follow.
TEST(ServeSession, AnAbsurdQualityNeverLeavesAStateThatCannotGoOn) {
  for (const std::string controller : {"default", "w=1", "active"}) {
    SCOPED_TRACE(controller);
    const TemporaryDatabase database;
    ServeSession session = ServeSession::start(analytic_options(controller), database.get());
    drive(session, 0, 3);
    const json pending = call(session, {{"op", "propose"}, {"assembly", 5}});
    ASSERT_TRUE(pending["ok"].get<bool>());
    const json before = session.state();
    const json absurd = call(
        session, {{"op", "observe"}, {"request_id", pending["request_id"]}, {"quality", 1e154}});
    if (absurd["ok"].get<bool>()) {
      for (const json& row : absurd["covariance"]) {
        for (const json& entry : row) EXPECT_TRUE(entry.is_number()) << absurd.dump();
      }
      {}
    } else {
      EXPECT_EQ(absurd["error"]["field"], "quality");
      EXPECT_THAT(absurd["error"]["message"].get<std::string>(),
                  HasSubstr("quality: 1e+154 leaves the offset estimate"));
      EXPECT_EQ(session.state(), before);
      const json observed = call(session, {{"op", "observe"},
                                           {"request_id", pending["request_id"]},
                                           {"quality", plant(session, 5, pending["control"])}});
      EXPECT_TRUE(observed["ok"].get<bool>()) << observed.dump();
    }
    drive(session, 4, 24);
  }
}

TEST(ServeSession, PredictsWithTheTwinAndReportsStateCheckpointAndShutdown) {
  const TemporaryDatabase database;
  ServeSession session = ServeSession::start(analytic_options("default"), database.get());
  const json predicted =
      call(session, {{"op", "predict"}, {"assembly", 4}, {"control", {0.0, 0.0, 0.0}}});
  ASSERT_TRUE(predicted["ok"].get<bool>());
  EXPECT_EQ(predicted["quality"].get<double>(),
            session.twin().plant_quality(session.twin().assemblies()[4], VectorX::Zero(3)));
  drive(session, 0, 2);
  const json state = call(session, {{"op", "state"}});
  EXPECT_EQ(state["observed"], 2);
  EXPECT_EQ(state["controller"], "default");
  EXPECT_EQ(state["locators"].size(), 3U);
  EXPECT_EQ(state["covariance"].size(), 3U);
  const json checkpoint = call(session, {{"op", "checkpoint"}});
  EXPECT_EQ(checkpoint["bytes"].get<std::uintmax_t>(), fs::file_size(database.get()));
  EXPECT_TRUE(call(session, {{"op", "shutdown"}})["ok"].get<bool>());
  EXPECT_TRUE(session.finished());
}

// A cell that sends the scanned parts of each assembly: the external case's minimal twin
// (examples/external_twin) computes its quality from them; u0 is searched per new assembly.
ServeOptions scanned_parts_options(std::int64_t snapshot_interval = 1000) {
  ServeOptions options;
  options.config.twin_case = TwinCase::external;
  // 1 × 1 parts: the twin's own assemblies are not used here.
  options.config.external_twin = test_support::three_locator_python_twin(
      TWINCAL_TEST_DATA_DIR "/../../examples/external_twin/minimal_twin.py", 1, 1, 200);
  options.config.locators = "all";
  options.controller = ControllerSpec::parse("active");
  options.durability = Durability::normal;
  options.snapshot_interval = snapshot_interval;
  return options;
}

json scanned_parts(int t) {
  return {{"upper", json::array({0.1 * (t % 5), 0.3})}, {"lower", json::array({0.05 * (t % 3)})}};
}

// Assemblies [from, to) of a cell that sends parts; the plant is the twin shifted by δu*.
std::vector<json> drive_scanned(ServeSession& session, int from, int to) {
  std::vector<json> controls;
  for (int t = from; t < to; ++t) {
    const json proposal = call(session, {{"op", "propose"},
                                         {"assembly", fmt::format("serial-{}", t)},
                                         {"parts", scanned_parts(t)}});
    EXPECT_TRUE(proposal["ok"].get<bool>()) << proposal.dump();
    EXPECT_EQ(proposal["assembly"], fmt::format("serial-{}", t));
    json shifted = proposal["control"];
    for (std::size_t i = 0; i < 3; ++i) shifted[i] = shifted[i].get<double>() - 0.05;
    const json predicted = call(session, {{"op", "predict"},
                                          {"assembly", fmt::format("serial-{}", t)},
                                          {"parts", scanned_parts(t)},
                                          {"control", shifted}});
    EXPECT_TRUE(predicted["ok"].get<bool>()) << predicted.dump();
    const json observed = call(session, {{"op", "observe"},
                                         {"request_id", proposal["request_id"]},
                                         {"quality", predicted["quality"]}});
    EXPECT_TRUE(observed["ok"].get<bool>()) << observed.dump();
    controls.push_back(proposal["control"]);
  }
  return controls;
}

TEST(ServeSession, TakesScannedPartsSearchesTheirOptimumAndResumesFromThem) {
  // Snapshots every 3 observations: they hold the active controller's kept assemblies, scanned
  // ids {k, −1} among them, and the resume restores one (before 2026-11-26 it refused them).
  const ServeOptions options = scanned_parts_options(3);
  const TemporaryDatabase whole_db;
  ServeSession whole = ServeSession::start(options, whole_db.get());
  const std::vector<json> expected = drive_scanned(whole, 0, 10);
  const json expected_estimate = whole.state()["estimate"];
  // The twin's optimum of the scanned parts is the minimal twin's closed form: u0_i =
  // 0.2 sin(1.7 U + 0.9 L + i), U and L the sums of the parts' deviations.
  const json first = call(
      whole, {{"op", "propose"},
              {"assembly", "serial-10"},
              {"parts", {{"upper", json::array({0.25, 0.5})}, {"lower", json::array({1.5})}}}});
  ASSERT_TRUE(first["ok"].get<bool>()) << first.dump();
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(first["report"]["optimum"][static_cast<std::size_t>(i)].get<double>(),
                0.2 * std::sin(1.7 * 0.75 + 0.9 * 1.5 + i), 1e-3);
  }
  // The history keeps the cell's id and its parts.
  EXPECT_EQ(whole.history().records().back().assembly["assembly"], "serial-10");
  EXPECT_EQ(whole.history().records().back().assembly["parts"]["lower"][0], 1.5);
  std::ostringstream csv;
  write_history_csv(whole.history(), csv);
  EXPECT_THAT(csv.str(), HasSubstr("\n4,,,serial-3,"));

  const TemporaryDatabase split_db;
  std::vector<json> controls;
  {
    ServeSession killed = ServeSession::start(options, split_db.get());
    controls = drive_scanned(killed, 0, 6);
  }
  ServeSession resumed = ServeSession::resume(split_db.get(), Durability::normal);
  EXPECT_EQ(resumed.observed(), 6);
  const std::vector<json> rest = drive_scanned(resumed, 6, 10);
  controls.insert(controls.end(), rest.begin(), rest.end());
  EXPECT_EQ(controls, expected);
  EXPECT_EQ(resumed.state()["estimate"], expected_estimate);
}

// A twin that fails now and then (tests/data/flaky_twin.py: every batch of several controls for
// parts whose first upper deviation is 0.2, here assemblies 2 and 7): the session goes on; a
// proposal made on the controller's fallback says why in its report, and an observation whose
// update the twin failed says that its measurement was dropped, so the cell sees what a silent
// fallback would hide.
TEST(ServeSession, ATwinThatFailsNowAndThenIsReportedAndDoesNotStopTheSession) {
  const TemporaryDatabase database;
  ServeOptions options = scanned_parts_options();
  options.config.external_twin->command.back() = TWINCAL_TEST_DATA_DIR "/flaky_twin.py";
  ServeSession session = ServeSession::start(options, database.get());
  Index fell_back = 0;
  Index dropped = 0;
  for (int t = 0; t < 12; ++t) {
    const std::string serial = fmt::format("serial-{}", t);
    const json proposal =
        call(session, {{"op", "propose"}, {"assembly", serial}, {"parts", scanned_parts(t)}});
    ASSERT_TRUE(proposal["ok"].get<bool>()) << proposal.dump();
    const json& report = proposal["report"];
    if (report.contains("fallback")) {
      ++fell_back;
      EXPECT_THAT(report["fallback"].get<std::string>(), HasSubstr("the solver did not converge"));
    }
    const json predicted = call(session, {{"op", "predict"},
                                          {"assembly", serial},
                                          {"parts", scanned_parts(t)},
                                          {"control", proposal["control"]}});
    ASSERT_TRUE(predicted["ok"].get<bool>()) << predicted.dump();
    const json observed = call(session, {{"op", "observe"},
                                         {"request_id", proposal["request_id"]},
                                         {"quality", predicted["quality"]}});
    ASSERT_TRUE(observed["ok"].get<bool>()) << observed.dump();
    if (observed.contains("dropped_measurement")) {
      ++dropped;
      EXPECT_THAT(observed["dropped_measurement"].get<std::string>(),
                  HasSubstr("the solver did not converge"));
    }
  }
  EXPECT_EQ(fell_back, 2);
  EXPECT_EQ(dropped, 2);
  EXPECT_EQ(call(session, {{"op", "state"}})["observed"], 12);
}

TEST(ServeSession, ResumesScannedPartsFromTheirRecordedOptimumWithoutSearchingAgain) {
  const TemporaryDatabase database;
  {
    ServeSession session = ServeSession::start(scanned_parts_options(), database.get());
    drive_scanned(session, 0, 4);
  }
  // The recorded u0 of request 2 moved by 1e-6: the row's checksum finds it; sealed again, a
  // resume that searched again would not notice, one that takes the record replays to other
  // controls and refuses the history.
  test_support::edit_database(
      database.get(),
      "UPDATE proposals SET assembly = json_set(assembly, '$.optimum[0]', "
      "json_extract(assembly, '$.optimum[0]') + 1e-6) WHERE request_id = 2");
  try {
    (void)ServeSession::resume(database.get(), Durability::normal);
    FAIL() << "resumed a history whose recorded optimum was edited";
  } catch (const HistoryDamageError& error) {
    EXPECT_EQ(error.argument(), "checksum");
    EXPECT_THAT(error.what(), HasSubstr("request 2: proposals.checksum is"));
  }
  test_support::reseal_history(database.get());
  try {
    (void)ServeSession::resume(database.get(), Durability::normal);
    FAIL() << "resumed a history whose recorded optimum was edited and sealed again";
  } catch (const HistoryMismatchError& error) {
    EXPECT_THAT(error.what(), HasSubstr("request 2 replays to another"));
  }
}

TEST(ServeSession, RefusesToResumeAHistoryThatDoesNotReplay) {
  const TemporaryDatabase database;
  {
    ServeSession session = ServeSession::start(analytic_options("w=1"), database.get());
    drive(session, 0, 5);
  }
  test_support::edit_database(
      database.get(), "UPDATE observations SET quality = quality + 1e-9 WHERE request_id = 3");
  try {
    (void)ServeSession::resume(database.get());
    FAIL() << "resumed a tampered history";
  } catch (const HistoryDamageError& error) {
    EXPECT_THAT(error.what(), HasSubstr("request 3: observations.checksum is"));
  }
  test_support::reseal_history(database.get());
  try {
    (void)ServeSession::resume(database.get());
    FAIL() << "resumed a tampered history sealed again";
  } catch (const HistoryMismatchError& error) {
    EXPECT_EQ(error.argument(), "estimate");
    EXPECT_THAT(error.what(), HasSubstr("request 3 replays to another estimate"));
  }
}

TEST(ServeSession, RefusesAHistoryWhoseReportDoesNotReplay) {
  const TemporaryDatabase database;
  {
    ServeSession session = ServeSession::start(analytic_options("active"), database.get());
    drive(session, 0, 4);
  }
  // z* of request 2's report, edited and sealed again: the controls replay, the report does not.
  test_support::edit_database(
      database.get(),
      "UPDATE proposals SET report = json_set(report, '$.optimal_quality', "
      "json_extract(report, '$.optimal_quality') * 2) WHERE request_id = 2");
  test_support::reseal_history(database.get());
  try {
    (void)ServeSession::resume(database.get(), Durability::normal);
    FAIL() << "resumed a history whose report was edited";
  } catch (const HistoryMismatchError& error) {
    EXPECT_EQ(error.argument(), "report");
    EXPECT_THAT(error.what(), HasSubstr("request 2 replays to another report"));
  }
}

TEST(ServeSession, ChecksAHistoryWithoutWritingToIt) {
  const TemporaryDatabase database;
  {
    ServeSession session = ServeSession::start(analytic_options("w=1"), database.get());
    drive(session, 0, 6);
    EXPECT_TRUE(call(session, {{"op", "propose"}, {"assembly", 3}})["ok"].get<bool>());
    (void)call(session, {{"op", "checkpoint"}});
  }
  const auto bytes = [&] {
    std::ifstream in(database.get(), std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  const std::string before = bytes();
  const HistoryCheck verified = ServeSession::check(database.get());
  EXPECT_EQ(verified.requests, 7);
  EXPECT_EQ(verified.observations, 6);
  EXPECT_TRUE(verified.pending);
  EXPECT_EQ(bytes(), before);

  test_support::edit_database(database.get(),
                              "UPDATE observations SET quality = 0.5 WHERE request_id = 4");
  EXPECT_THROW((void)ServeSession::check(database.get()), HistoryDamageError);
  test_support::reseal_history(database.get());
  EXPECT_THROW((void)ServeSession::check(database.get()), HistoryMismatchError);
}

TEST(ServeSession, RefusesInvalidOptionsBeforeCreatingTheDatabase) {
  const TemporaryDatabase database;
  ServeOptions options = analytic_options("active");
  options.run = -1;
  EXPECT_THROW((void)ServeSession::start(options, database.get()), InvalidArgumentError);
  EXPECT_FALSE(fs::exists(database.get()));
  // The cell is the plant: a config with a plant of its own is refused, not built for nothing.
  options = analytic_options("active");
  options.config.plant_nonlinearity = Nonlinearity::contact;
  ASSERT_FALSE(options.config.validate().has_value());
  try {
    (void)ServeSession::start(options, database.get());
    FAIL() << "served a config with a plant";
  } catch (const InvalidArgumentError& error) {
    EXPECT_NE(std::string(error.what()).find("twincal serve's plant is the cell"),
              std::string::npos);
  }
  EXPECT_FALSE(fs::exists(database.get()));
}

}  // namespace
}  // namespace twincal
