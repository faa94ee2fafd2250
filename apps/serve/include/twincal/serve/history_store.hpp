#pragma once
/// @file
/// `HistoryStore`: the SQLite database of a `twincal serve` session — its settings, every
/// proposal and every observation with the controller's estimate δû_t and covariance P_t after
/// it (eq. 8) — written before the server replies, so that a session killed at any moment
/// resumes from the database alone (serve_session.hpp replays it).
///
/// Durability: WAL journal, one transaction per record, `synchronous = FULL` by default (a
/// record survives a power cut; `NORMAL` survives a killed process only and costs no fsync per
/// record). Doubles are stored as JSON text in nlohmann's shortest round-trip form, so a replay
/// can compare the controls and estimates it recomputes with the recorded ones bit for bit, and
/// `sqlite3 DB 'select * from observations'` shows numbers a person can read.
///
/// Tables (docs/serve.md):
///   settings(key TEXT PRIMARY KEY, value TEXT)           — "format", "config", "controller", …
///   proposals(request_id INTEGER PRIMARY KEY, assembly TEXT, control TEXT, report TEXT,
///             proposed_at TEXT)
///   observations(request_id INTEGER PRIMARY KEY REFERENCES proposals, quality REAL,
///                estimate TEXT, covariance TEXT, observed_at TEXT)

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"

struct sqlite3;

namespace twincal {

/// A database that cannot be opened, created, read or written, or that is not a twincal serve
/// history; the message names the file and what SQLite said.
class HistoryStoreError : public Error {
 public:
  using Error::Error;
};

enum class Durability { full, normal };

/// One proposal and, once the cell measured it, its observation.
struct HistoryRecord {
  std::int64_t request_id = 0;
  nlohmann::json assembly;
  nlohmann::json control;  ///< array of d numbers
  nlohmann::json report;
  std::optional<double> quality;  ///< unset while the request awaits its observation
  nlohmann::json estimate;        ///< δû_t after the observation (null before)
  nlohmann::json covariance;      ///< P_t after the observation, d rows (null before)
  std::string proposed_at;        ///< UTC, ISO 8601
  std::string observed_at;        ///< UTC, ISO 8601; empty before the observation
};

class HistoryStore {
 public:
  /// Creates a new database at `path` holding `settings` (an object of strings).
  /// @throws HistoryStoreError when `path` exists or cannot be created.
  [[nodiscard]] static HistoryStore create(const std::filesystem::path& path,
                                           const nlohmann::json& settings,
                                           Durability durability = Durability::full);
  /// Opens an existing history.
  /// @throws HistoryStoreError when `path` is missing or not a twincal serve history.
  [[nodiscard]] static HistoryStore open(const std::filesystem::path& path,
                                         Durability durability = Durability::full);

  HistoryStore(HistoryStore&&) noexcept;
  HistoryStore& operator=(HistoryStore&&) noexcept;
  HistoryStore(const HistoryStore&) = delete;
  HistoryStore& operator=(const HistoryStore&) = delete;
  ~HistoryStore();

  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }
  /// The settings given to create().
  [[nodiscard]] nlohmann::json settings() const;
  /// Every record, in request order.
  [[nodiscard]] std::vector<HistoryRecord> records() const;

  /// Inserts a proposal (one transaction). @throws HistoryStoreError (nothing written).
  void record_proposal(std::int64_t request_id, const nlohmann::json& assembly,
                       const nlohmann::json& control, const nlohmann::json& report);
  /// Inserts the observation of a recorded proposal (one transaction).
  /// @throws HistoryStoreError (nothing written).
  void record_observation(std::int64_t request_id, double quality, const nlohmann::json& estimate,
                          const nlohmann::json& covariance);

  /// Moves the write-ahead log into the database file (PRAGMA wal_checkpoint(TRUNCATE)), e.g.
  /// before copying the file; returns the database's size in bytes.
  std::uintmax_t checkpoint();

  /// The current format; a history of another format is refused by open().
  static constexpr int format = 1;

 private:
  HistoryStore(std::filesystem::path path, sqlite3* db) noexcept;
  void configure(Durability durability) const;
  void execute(const char* sql) const;

  std::filesystem::path path_;
  sqlite3* db_ = nullptr;
};

}  // namespace twincal
