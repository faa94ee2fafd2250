#pragma once
// What the serve tests share: a fresh database path, and the options of a session over the
// analytic twin (fast to build) with every locator.
#include <sqlite3.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "twincal/serve/serve_session.hpp"

namespace twincal::test_support {

/// A path in the temporary directory, removed with SQLite's side files (-wal, -shm) afterwards.
class TemporaryDatabase {
 public:
  TemporaryDatabase()
      : path_(std::filesystem::temp_directory_path() /
              fmt::format("twincal-serve-test-{}-{}.db", ::getpid(), next_++)) {
    remove();
  }
  TemporaryDatabase(const TemporaryDatabase&) = delete;
  TemporaryDatabase& operator=(const TemporaryDatabase&) = delete;
  ~TemporaryDatabase() { remove(); }
  [[nodiscard]] const std::filesystem::path& get() const noexcept { return path_; }

 private:
  void remove() const {
    for (const char* suffix : {"", "-wal", "-shm"}) {
      std::filesystem::remove(path_.string() + suffix);
    }
  }
  static inline int next_ = 0;
  std::filesystem::path path_;
};

/// Runs `sql` on the database at `path` as someone editing it by hand would (sqlite3).
inline void edit_database(const std::filesystem::path& path, const std::string& sql) {
  sqlite3* db = nullptr;
  if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) throw std::runtime_error("cannot open");
  char* message = nullptr;
  const int code = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &message);
  const std::string reason = message != nullptr ? message : "";
  sqlite3_free(message);
  sqlite3_close(db);
  if (code != SQLITE_OK) throw std::runtime_error(sql + ": " + reason);
}

/// Recomputes every proposals, observations and snapshots checksum of the history at `path`: an
/// edit that is sealed again, so that what resume sees is only what its replay can find.
inline void reseal_history(const std::filesystem::path& path) {
  sqlite3* db = nullptr;
  if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) throw std::runtime_error("cannot open");
  const auto run = [&](const char* select, const char* update, auto checksum) {
    sqlite3_stmt* rows = nullptr;
    sqlite3_stmt* write = nullptr;
    sqlite3_prepare_v2(db, select, -1, &rows, nullptr);
    sqlite3_prepare_v2(db, update, -1, &write, nullptr);
    while (sqlite3_step(rows) == SQLITE_ROW) {
      const auto text = [&](int c) {
        return std::string(reinterpret_cast<const char*>(sqlite3_column_text(rows, c)));
      };
      const std::int64_t id = sqlite3_column_int64(rows, 0);
      sqlite3_bind_int64(write, 1, checksum(id, text, rows));
      sqlite3_bind_int64(write, 2, id);
      sqlite3_step(write);
      sqlite3_reset(write);
    }
    sqlite3_finalize(rows);
    sqlite3_finalize(write);
  };
  run("SELECT request_id, assembly, control, report, proposed_at FROM proposals",
      "UPDATE proposals SET checksum = ?1 WHERE request_id = ?2",
      [](std::int64_t id, const auto& text, sqlite3_stmt*) {
        return HistoryStore::proposal_checksum(id, text(1), text(2), text(3), text(4));
      });
  run("SELECT request_id, quality, estimate, covariance, observed_at FROM observations",
      "UPDATE observations SET checksum = ?1 WHERE request_id = ?2",
      [](std::int64_t id, const auto& text, sqlite3_stmt* rows) {
        return HistoryStore::observation_checksum(id, sqlite3_column_double(rows, 1), text(2),
                                                  text(3), text(4));
      });
  run("SELECT request_id, state FROM snapshots",
      "UPDATE snapshots SET checksum = ?1 WHERE request_id = ?2",
      [](std::int64_t id, const auto& text, sqlite3_stmt*) {
        return HistoryStore::snapshot_checksum(id, text(1));
      });
  sqlite3_close(db);
}

/// A session over the analytic twin with `dimension` locators, all controlled; no fsync.
inline ServeOptions analytic_options(const std::string& controller, Index dimension = 3) {
  ServeOptions options;
  options.config.twin_case = TwinCase::analytic;
  options.config.analytic_dimension = dimension;
  options.config.locators = "all";
  options.controller = ControllerSpec::parse(controller);
  options.durability = Durability::normal;
  return options;
}

}  // namespace twincal::test_support
