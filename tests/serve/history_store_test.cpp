#include "twincal/serve/history_store.hpp"

#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "serve_testing.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;
using json = nlohmann::json;
namespace fs = std::filesystem;

using testing::TemporaryDatabase;

TEST(HistoryStore, KeepsSettingsProposalsAndObservationsAcrossReopening) {
  const TemporaryDatabase path;
  {
    HistoryStore store = HistoryStore::create(path.get(), {{"config", "{}"}, {"run", "0"}});
    store.record_proposal(1, json::array({0, 3}), json::array({0.1, -0.2}), {{"x", 1}});
    store.record_observation(1, 0.75, json::array({0.01, 0.02}),
                             json::array({json::array({1.0, 0.0}), json::array({0.0, 1.0})}));
    store.record_proposal(2, json::array({1, 2}), json::array({0.30000000000000004, 1e-300}),
                          json::object());
  }
  const HistoryStore store = HistoryStore::open(path.get());
  const json settings = store.settings();
  EXPECT_EQ(settings["config"], "{}");
  EXPECT_EQ(settings["run"], "0");
  EXPECT_EQ(settings["format"], std::to_string(HistoryStore::format));
  const std::vector<HistoryRecord> records = store.records();
  ASSERT_EQ(records.size(), 2U);
  EXPECT_EQ(records[0].request_id, 1);
  EXPECT_EQ(records[0].assembly, json::array({0, 3}));
  ASSERT_TRUE(records[0].quality.has_value());
  EXPECT_EQ(*records[0].quality, 0.75);
  EXPECT_EQ(records[0].estimate, json::array({0.01, 0.02}));
  EXPECT_FALSE(records[1].quality.has_value());
  // Doubles come back bit for bit.
  EXPECT_EQ(records[1].control[0].get<double>(), 0.1 + 0.2);
  EXPECT_EQ(records[1].control[1].get<double>(), 1e-300);
}

TEST(HistoryStore, RefusesToOverwriteAnExistingFileAndToOpenWhatIsNotAHistory) {
  const TemporaryDatabase path;
  { const HistoryStore store = HistoryStore::create(path.get(), json::object()); }
  try {
    (void)HistoryStore::create(path.get(), json::object());
    FAIL() << "created over an existing file";
  } catch (const HistoryStoreError& error) {
    EXPECT_THAT(error.what(), HasSubstr("exists; rule: a new session needs a new database"));
  }
  const TemporaryDatabase missing;
  EXPECT_THROW((void)HistoryStore::open(missing.get()), HistoryStoreError);
  const TemporaryDatabase text;
  std::ofstream(text.get()) << "not a database\n";
  try {
    (void)HistoryStore::open(text.get());
    FAIL() << "opened a text file";
  } catch (const HistoryStoreError& error) {
    EXPECT_THAT(error.what(), HasSubstr(text.get().string()));
  }
}

TEST(HistoryStore, RefusesAnotherFormat) {
  const TemporaryDatabase path;
  { const HistoryStore store = HistoryStore::create(path.get(), json::object()); }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.get().c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "UPDATE settings SET value = '99' WHERE key = 'format'", nullptr,
                         nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  try {
    (void)HistoryStore::open(path.get());
    FAIL() << "opened format 99";
  } catch (const HistoryStoreError& error) {
    EXPECT_THAT(error.what(),
                HasSubstr("has history format 99; rule: this twincal reads format 1"));
  }
}

TEST(HistoryStore, RefusesAnObservationOfAnUnknownOrObservedRequestWritingNothing) {
  const TemporaryDatabase path;
  HistoryStore store = HistoryStore::create(path.get(), json::object(), Durability::normal);
  store.record_proposal(1, json::array({0, 0}), json::array({0.0}), json::object());
  EXPECT_THROW(store.record_observation(2, 1.0, json::array(), json::array()), HistoryStoreError);
  store.record_observation(1, 1.0, json::array(), json::array());
  EXPECT_THROW(store.record_observation(1, 2.0, json::array(), json::array()), HistoryStoreError);
  EXPECT_THROW(store.record_proposal(1, json::array({0, 0}), json::array({0.0}), json::object()),
               HistoryStoreError);
  const std::vector<HistoryRecord> records = store.records();
  ASSERT_EQ(records.size(), 1U);
  EXPECT_EQ(*records[0].quality, 1.0);
}

TEST(HistoryStore, CheckpointFoldsTheLogIntoTheFile) {
  const TemporaryDatabase path;
  HistoryStore store = HistoryStore::create(path.get(), json::object());
  for (int r = 1; r <= 20; ++r) {
    store.record_proposal(r, json::array({r, r}), json::array({0.5 * r}), json::object());
  }
  const std::uintmax_t bytes = store.checkpoint();
  EXPECT_EQ(bytes, fs::file_size(path.get()));
  EXPECT_EQ(fs::file_size(path.get().string() + "-wal"), 0U);
}

}  // namespace
}  // namespace twincal
