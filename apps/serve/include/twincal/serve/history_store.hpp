#pragma once
/// @file
/// `HistoryStore`: the SQLite database of a `twincal serve` session — its settings, every
/// proposal and every observation with the controller's estimate δû_t and covariance P_t after
/// it (eq. 8), and snapshots of the controller — written before the server replies, so that a
/// session killed at any moment resumes from the database alone (serve_session.hpp replays it).
///
/// Durability: WAL journal, one transaction per record, `synchronous = FULL` by default (a
/// record survives a power cut; `NORMAL` survives a killed process only and costs no fsync per
/// record). After each commit the database file and its write-ahead log are checked to be the
/// files the store opened: a log deleted or replaced under a running server would take the
/// records with it, so the store throws instead of letting the server answer "ok". Doubles are
/// stored as JSON text in nlohmann's shortest round-trip form, so a replay can compare the
/// controls and estimates it recomputes with the recorded ones bit for bit, and
/// `sqlite3 DB 'select * from observations'` shows numbers a person can read.
///
/// Integrity: every proposal, observation and snapshot row carries the CRC-32 (Boost.CRC) of
/// its columns, checked whenever it is read: a damaged row is refused with a HistoryDamageError
/// naming the database, the request and the column. The checksum finds damage (a flipped bit,
/// an edit by hand); it does not stop someone who recomputes it.
///
/// Tables (docs/serve.md), format 2:
///   settings(key TEXT PRIMARY KEY, value TEXT)           — "format", "config", "controller", …
///   proposals(request_id INTEGER PRIMARY KEY, assembly TEXT, control TEXT, report TEXT,
///             proposed_at TEXT, checksum INTEGER)
///   observations(request_id INTEGER PRIMARY KEY REFERENCES proposals, quality REAL,
///                estimate TEXT, covariance TEXT, observed_at TEXT, checksum INTEGER)
///   snapshots(request_id INTEGER PRIMARY KEY REFERENCES observations, state TEXT,
///             checksum INTEGER)
/// A format-1 history (no checksums, no snapshots; written before commit 3d8ae74) is read as it is
/// and upgraded in place, in one transaction, when it is opened to be written.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <sys/types.h>

#include <nlohmann/json.hpp>

#include "twincal/core/error.hpp"

struct sqlite3;

namespace twincal {

/// A database that cannot be opened, created, read or written, that is not a twincal serve
/// history, or whose files changed under the store; the message names the file and what SQLite
/// or the file system said.
class HistoryStoreError : public Error {
 public:
  using Error::Error;
};

/// A row of the history that does not read back as it was written: its checksum differs, a JSON
/// column does not parse, or the requests are not numbered 1, 2, …; argument() is the column.
class HistoryDamageError : public HistoryStoreError {
 public:
  using HistoryStoreError::HistoryStoreError;
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

/// The controller's state after the observation of `request_id` (serve_session.hpp).
struct HistorySnapshot {
  std::int64_t request_id = 0;
  nlohmann::json state;
};

class HistoryStore {
 public:
  /// Creates a new database at `path` holding `settings` (an object of strings).
  /// @throws HistoryStoreError when `path` exists or cannot be created.
  [[nodiscard]] static HistoryStore create(const std::filesystem::path& path,
                                           const nlohmann::json& settings,
                                           Durability durability = Durability::full);
  /// Opens an existing history to append to it. Refused, before anything is written to the
  /// file: a missing file, one that is not a twincal serve history (of format 1 or 2), a
  /// database or directory this process cannot write, a file system that does not keep a
  /// write-ahead log.
  /// @throws HistoryStoreError.
  [[nodiscard]] static HistoryStore open(const std::filesystem::path& path,
                                         Durability durability = Durability::full);
  /// Opens an existing history only to read it (export, check): writes nothing, so it also
  /// reads the history of a running server.
  /// @throws HistoryStoreError.
  [[nodiscard]] static HistoryStore open_read_only(const std::filesystem::path& path);

  HistoryStore(HistoryStore&&) noexcept;
  HistoryStore& operator=(HistoryStore&&) noexcept;
  HistoryStore(const HistoryStore&) = delete;
  HistoryStore& operator=(const HistoryStore&) = delete;
  ~HistoryStore();

  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }
  /// The settings given to create().
  [[nodiscard]] nlohmann::json settings() const;
  /// Calls `visit` with every record from request `first` on, in request order, one at a time
  /// (a long history is never held in memory). @throws HistoryDamageError for a damaged row (the
  /// records before it have been visited); what `visit` throws.
  void for_each_record(std::int64_t first,
                       const std::function<void(const HistoryRecord&)>& visit) const;
  /// Calls `visit` with every record up to request `last` whose assembly is scanned parts (a
  /// JSON object), in request order: what a resume from a snapshot registers with the twin
  /// without replaying the requests between. @throws HistoryDamageError.
  void for_each_scanned_record(std::int64_t last,
                               const std::function<void(const HistoryRecord&)>& visit) const;
  /// Every record, in request order (for_each_record into a vector).
  [[nodiscard]] std::vector<HistoryRecord> records() const;
  /// The number of proposals.
  [[nodiscard]] std::int64_t record_count() const;

  /// Inserts a proposal (one transaction). @throws HistoryStoreError (nothing written).
  void record_proposal(std::int64_t request_id, const nlohmann::json& assembly,
                       const nlohmann::json& control, const nlohmann::json& report);
  /// Inserts the observation of a recorded proposal (one transaction).
  /// @throws HistoryStoreError (nothing written).
  void record_observation(std::int64_t request_id, double quality, const nlohmann::json& estimate,
                          const nlohmann::json& covariance);
  /// Inserts the controller's state after the observation of `request_id` (one transaction).
  /// @throws HistoryStoreError (nothing written).
  void record_snapshot(std::int64_t request_id, const nlohmann::json& state);
  /// The snapshot of the highest request, if any. @throws HistoryDamageError.
  [[nodiscard]] std::optional<HistorySnapshot> last_snapshot() const;
  /// Every snapshot's request, ascending.
  [[nodiscard]] std::vector<std::int64_t> snapshot_requests() const;
  /// The snapshot after `request_id`. @throws HistoryStoreError when there is none;
  /// HistoryDamageError.
  [[nodiscard]] HistorySnapshot snapshot(std::int64_t request_id) const;

  /// The checksum column of a proposals, observations and snapshots row: the CRC-32 of the
  /// request id and the columns' stored text (the quality in its shortest round-trip form), each
  /// followed by 0x1f. What a tool that edits a history on purpose must write.
  [[nodiscard]] static std::int64_t proposal_checksum(std::int64_t request_id,
                                                      std::string_view assembly,
                                                      std::string_view control,
                                                      std::string_view report,
                                                      std::string_view proposed_at);
  [[nodiscard]] static std::int64_t observation_checksum(std::int64_t request_id, double quality,
                                                         std::string_view estimate,
                                                         std::string_view covariance,
                                                         std::string_view observed_at);
  [[nodiscard]] static std::int64_t snapshot_checksum(std::int64_t request_id,
                                                      std::string_view state);

  /// Moves the write-ahead log into the database file (PRAGMA wal_checkpoint(TRUNCATE)), e.g.
  /// before copying the file; returns the database's size in bytes.
  std::uintmax_t checkpoint();

  /// The current format; open() reads this one and format 1.
  static constexpr int format = 2;

 private:
  // The identity of a file the store writes: a file replaced or deleted has another (or none).
  struct FileIdentity {
    dev_t device = 0;
    ino_t inode = 0;
    friend bool operator==(const FileIdentity&, const FileIdentity&) = default;
  };

  HistoryStore(std::filesystem::path path, sqlite3* db) noexcept;
  void configure(Durability durability) const;
  void execute(const char* sql) const;
  [[nodiscard]] int stored_format() const;
  void upgrade_from_format_1();
  // The records with request_id in [first, last], of scanned assemblies only if
  // `scanned_only` (then not necessarily contiguous), checked and parsed.
  void visit_records(std::int64_t first, std::int64_t last, bool scanned_only,
                     const std::function<void(const HistoryRecord&)>& visit) const;
  // Records the identities of the database and its log (after the log exists).
  void watch_files();
  // After a commit: the database and its log are still the files watch_files() saw.
  // @throws HistoryStoreError naming the file that changed.
  void require_same_files() const;

  std::filesystem::path path_;
  sqlite3* db_ = nullptr;
  bool checksums_ = true;  // false for a format-1 history opened read-only
  std::optional<FileIdentity> database_identity_;
  std::optional<FileIdentity> log_identity_;
};

}  // namespace twincal
