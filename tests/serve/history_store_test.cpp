#include "twincal/serve/history_store.hpp"

#include <sqlite3.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

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

using test_support::edit_database;
using test_support::TemporaryDatabase;

// The bytes of a file.
std::string file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A history of two observed requests and a third one pending.
void write_three_requests(const fs::path& path) {
  HistoryStore store = HistoryStore::create(path, {{"run", "0"}}, Durability::normal);
  for (int r = 1; r <= 3; ++r) {
    store.record_proposal(r, json::array({r, r}), json::array({0.25 * r}), {{"z", r}});
    if (r < 3) store.record_observation(r, 0.5 * r, json::array({0.1 * r}), json::array({{1.0}}));
  }
}

// What `attempt` throws as a HistoryStoreError's message ("" when it does not throw).
template <typename F>
std::string refusal(F attempt) {
  try {
    attempt();
  } catch (const HistoryStoreError& error) {
    return error.what();
  }
  return {};
}

// Runs `check` as the unprivileged user nobody (65534) when this process is root (root writes
// any file, so permissions would prove nothing), otherwise as this user: its exit status.
template <typename F>
int exit_status_as_unprivileged_user(F check) {
  const pid_t child = ::fork();
  if (child == 0) {
    if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) ::_exit(3);
    ::_exit(check() ? 0 : 1);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

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
                HasSubstr("has history format 99; rule: this twincal reads formats 1 and 2"));
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

TEST(HistoryStore, RefusesADamagedRowNamingTheDatabaseTheRequestAndTheColumn) {
  const auto damaged = [](const std::string& sql) {
    const TemporaryDatabase path;
    write_three_requests(path.get());
    edit_database(path.get(), sql);
    try {
      (void)HistoryStore::open(path.get()).records();
    } catch (const HistoryDamageError& error) {
      EXPECT_THAT(error.what(), HasSubstr(path.get().string()));
      return std::pair{error.argument(), std::string(error.what())};
    }
    return std::pair{std::string(), std::string()};
  };
  // One character of a report, of an estimate, of a timestamp.
  auto [column, message] =
      damaged("UPDATE proposals SET report = '{\"z\":7}' WHERE request_id = 2");
  EXPECT_EQ(column, "checksum");
  EXPECT_THAT(message, HasSubstr("request 2: proposals.checksum is"));
  std::tie(column, message) =
      damaged("UPDATE observations SET estimate = '[0.3]' WHERE request_id = 1");
  EXPECT_THAT(message, HasSubstr("request 1: observations.checksum is"));
  std::tie(column, message) =
      damaged("UPDATE observations SET observed_at = '2020-01-01T00:00:00Z' WHERE request_id = 2");
  EXPECT_THAT(message, HasSubstr("request 2: observations.checksum is"));
  // A request missing from the middle.
  std::tie(column, message) = damaged(
      "PRAGMA foreign_keys = OFF; DELETE FROM proposals WHERE request_id = 2; "
      "DELETE FROM observations WHERE request_id = 2");
  EXPECT_EQ(column, "request_id");
  EXPECT_THAT(message, HasSubstr("request 3: proposals.request_id follows request 1"));
}

TEST(HistoryStore, RefusesARowThatIsNotJsonEvenWithAMatchingChecksum) {
  const TemporaryDatabase path;
  write_three_requests(path.get());
  edit_database(path.get(), "UPDATE proposals SET control = '[0.5,' WHERE request_id = 2");
  test_support::reseal_history(path.get());
  try {
    (void)HistoryStore::open_read_only(path.get()).records();
    FAIL() << "read a control that is not JSON";
  } catch (const HistoryDamageError& error) {
    EXPECT_EQ(error.argument(), "control");
    EXPECT_THAT(error.what(), HasSubstr("request 2: proposals.control is not JSON"));
  }
}

TEST(HistoryStore, LeavesAForeignFileAsItWasWhenRefusingIt) {
  const TemporaryDatabase path;
  edit_database(path.get(), "CREATE TABLE parts (id INTEGER); INSERT INTO parts VALUES (7)");
  const std::string before = file_bytes(path.get());
  EXPECT_THAT(refusal([&] { (void)HistoryStore::open(path.get()); }),
              HasSubstr("is not a twincal serve history"));
  EXPECT_EQ(file_bytes(path.get()), before);  // no journal mode written into its header
  EXPECT_FALSE(fs::exists(path.get().string() + "-wal"));

  const TemporaryDatabase text;
  std::ofstream(text.get()) << "request_id,quality\n1,0.5\n";
  EXPECT_THAT(refusal([&] { (void)HistoryStore::open(text.get()); }),
              HasSubstr("is not a twincal serve history"));
  EXPECT_EQ(file_bytes(text.get()), "request_id,quality\n1,0.5\n");
}

TEST(HistoryStore, RefusesAReadOnlyDatabaseOrDirectoryBeforeWritingAnything) {
  const TemporaryDatabase path;
  write_three_requests(path.get());
  ASSERT_EQ(::chmod(path.get().c_str(), 0444), 0);
  const std::string before = file_bytes(path.get());
  EXPECT_EQ(exit_status_as_unprivileged_user([&] {
              const std::string message = refusal([&] { (void)HistoryStore::open(path.get()); });
              return message.find("the database " + path.get().string() + " is not writable") !=
                         std::string::npos &&
                     !fs::exists(path.get().string() + "-wal") &&
                     !fs::exists(path.get().string() + "-shm");
            }),
            0);
  EXPECT_EQ(file_bytes(path.get()), before);
  // Read-only is fine for reading.
  EXPECT_EQ(HistoryStore::open_read_only(path.get()).records().size(), 3U);

  // A writable file in a directory that is not: SQLite could not create its -wal file.
  const fs::path directory =
      fs::temp_directory_path() / fmt::format("twincal-serve-test-{}-ro", ::getpid());
  fs::create_directories(directory);
  const fs::path inside = directory / "cell.db";
  write_three_requests(inside);
  ASSERT_EQ(::chmod(directory.c_str(), 0555), 0);
  if (::geteuid() == 0) ASSERT_EQ(::chown(inside.c_str(), 65534, 65534), 0);
  EXPECT_EQ(exit_status_as_unprivileged_user([&] {
              return refusal([&] { (void)HistoryStore::open(inside); })
                         .find("its directory (for the -wal and -shm files) " + directory.string() +
                               " is not writable") != std::string::npos;
            }),
            0);
  ::chmod(directory.c_str(), 0755);
  fs::remove_all(directory);
}

TEST(HistoryStore, StopsWhenItsWriteAheadLogIsRemovedUnderIt) {
  const TemporaryDatabase path;
  HistoryStore store = HistoryStore::create(path.get(), json::object(), Durability::normal);
  store.record_proposal(1, json::array({0, 0}), json::array({0.0}), json::object());
  ASSERT_TRUE(fs::remove(path.get().string() + "-wal"));
  EXPECT_THAT(refusal([&] { store.record_observation(1, 1.0, json::array(), json::array()); }),
              HasSubstr("its write-ahead log " + path.get().string() +
                        "-wal was removed while the server ran"));
}

TEST(HistoryStore, ReadsAFormatOneHistoryAndUpgradesItWhenOpenedToWrite) {
  const TemporaryDatabase path;
  // The format-1 schema and rows, as twincal wrote them before checksums.
  edit_database(path.get(), R"sql(
    PRAGMA journal_mode = WAL;
    CREATE TABLE settings (key TEXT PRIMARY KEY, value TEXT NOT NULL);
    CREATE TABLE proposals (request_id INTEGER PRIMARY KEY, assembly TEXT NOT NULL,
      control TEXT NOT NULL, report TEXT NOT NULL, proposed_at TEXT NOT NULL);
    CREATE TABLE observations (request_id INTEGER PRIMARY KEY REFERENCES proposals (request_id),
      quality REAL NOT NULL, estimate TEXT NOT NULL, covariance TEXT NOT NULL,
      observed_at TEXT NOT NULL);
    INSERT INTO settings VALUES ('format', '1'), ('run', '0');
    INSERT INTO proposals VALUES (1, '[0,1]', '[0.1]', '{}', '2026-11-01T00:00:00Z'),
                                 (2, '[1,2]', '[0.2]', '{}', '2026-11-01T00:00:01Z');
    INSERT INTO observations VALUES (1, 0.3, '[0.01]', '[[1.0]]', '2026-11-01T00:00:00Z');
  )sql");
  EXPECT_EQ(HistoryStore::open_read_only(path.get()).records().size(), 2U);
  EXPECT_EQ(HistoryStore::open_read_only(path.get()).settings()["format"], "1");
  {
    HistoryStore store = HistoryStore::open(path.get(), Durability::normal);
    EXPECT_EQ(store.settings()["format"], "2");
    store.record_observation(2, 0.4, json::array({0.02}), json::array({json::array({1.0})}));
    store.record_snapshot(2, {{"x", 1}});
  }
  const std::vector<HistoryRecord> records = HistoryStore::open_read_only(path.get()).records();
  ASSERT_EQ(records.size(), 2U);
  EXPECT_EQ(*records[0].quality, 0.3);
  EXPECT_EQ(*records[1].quality, 0.4);
  // The upgraded rows carry checksums that find damage.
  edit_database(path.get(), "UPDATE proposals SET control = '[0.15]' WHERE request_id = 1");
  EXPECT_THROW((void)HistoryStore::open_read_only(path.get()).records(), HistoryDamageError);
}

TEST(HistoryStore, KeepsSnapshotsWithTheirChecksums) {
  const TemporaryDatabase path;
  write_three_requests(path.get());
  {
    HistoryStore store = HistoryStore::open(path.get(), Durability::normal);
    EXPECT_FALSE(store.last_snapshot().has_value());
    store.record_snapshot(1, {{"mean", {0.5, 1e-300}}});
    store.record_snapshot(2, {{"mean", {0.1 + 0.2}}});
    EXPECT_THROW(store.record_snapshot(3, json::object()), HistoryStoreError);  // not observed
  }
  const HistoryStore store = HistoryStore::open_read_only(path.get());
  EXPECT_EQ(store.snapshot_requests(), (std::vector<std::int64_t>{1, 2}));
  const std::optional<HistorySnapshot> last = store.last_snapshot();
  ASSERT_TRUE(last.has_value());
  EXPECT_EQ(last->request_id, 2);
  EXPECT_EQ(last->state["mean"][0].get<double>(), 0.1 + 0.2);
  EXPECT_EQ(store.snapshot(1).state["mean"][1].get<double>(), 1e-300);
  EXPECT_THAT(refusal([&] { (void)store.snapshot(3); }),
              HasSubstr("has no snapshot after request 3"));
  edit_database(path.get(), "UPDATE snapshots SET state = '{\"mean\":[0.3]}' WHERE request_id = 2");
  EXPECT_THAT(refusal([&] { (void)store.last_snapshot(); }),
              HasSubstr("request 2: snapshots.checksum is"));
}

TEST(HistoryStore, ReadsRecordsFromAGivenRequestOneAtATime) {
  const TemporaryDatabase path;
  write_three_requests(path.get());
  const HistoryStore store = HistoryStore::open_read_only(path.get());
  std::vector<std::int64_t> seen;
  store.for_each_record(2, [&](const HistoryRecord& record) { seen.push_back(record.request_id); });
  EXPECT_EQ(seen, (std::vector<std::int64_t>{2, 3}));
  EXPECT_EQ(store.record_count(), 3);
}

}  // namespace
}  // namespace twincal
