// HistoryStore (history_store.hpp): the SQLite history of a serve session.
#include "twincal/serve/history_store.hpp"

#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <limits>
#include <string_view>
#include <utility>

#include <fmt/chrono.h>
#include <fmt/format.h>
#include <boost/crc.hpp>

namespace twincal {
namespace {

using nlohmann::json;

constexpr const char* schema = R"sql(
CREATE TABLE settings (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE proposals (
  request_id INTEGER PRIMARY KEY,
  assembly TEXT NOT NULL,
  control TEXT NOT NULL,
  report TEXT NOT NULL,
  proposed_at TEXT NOT NULL,
  checksum INTEGER NOT NULL);
CREATE TABLE observations (
  request_id INTEGER PRIMARY KEY REFERENCES proposals (request_id),
  quality REAL NOT NULL,
  estimate TEXT NOT NULL,
  covariance TEXT NOT NULL,
  observed_at TEXT NOT NULL,
  checksum INTEGER NOT NULL);
)sql";

// Format 2 adds it; an upgraded format-1 history gets it too.
constexpr const char* snapshot_schema = R"sql(
CREATE TABLE snapshots (
  request_id INTEGER PRIMARY KEY REFERENCES observations (request_id),
  state TEXT NOT NULL,
  checksum INTEGER NOT NULL);
)sql";

std::string now_utc() {
  return fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", std::chrono::time_point_cast<std::chrono::seconds>(
                                                  std::chrono::system_clock::now()));
}

// CRC-32 of a row: its request id and its columns' stored text, each followed by a unit
// separator (0x1f), so that text moved from one column to the next changes it too.
std::int64_t row_checksum(std::int64_t request_id,
                          std::initializer_list<std::string_view> columns) {
  boost::crc_32_type crc;
  const std::string id = std::to_string(request_id);
  crc.process_bytes(id.data(), id.size());
  for (const std::string_view column : columns) {
    crc.process_byte('\x1f');
    crc.process_bytes(column.data(), column.size());
  }
  return static_cast<std::int64_t>(crc.checksum());
}

// The text a quality's checksum covers: the shortest form that reads back to the same double.
std::string quality_text(double quality) { return fmt::format("{}", quality); }

// A prepared statement, finalized on scope exit.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql, const std::filesystem::path& path) : path_(path) {
    if (sqlite3_prepare_v2(db, sql, -1, &statement_, nullptr) != SQLITE_OK) {
      throw HistoryStoreError(path.string(), fmt::format("{}: cannot prepare \"{}\": {}",
                                                         path.string(), sql, sqlite3_errmsg(db)));
    }
  }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  ~Statement() { sqlite3_finalize(statement_); }

  void bind(int column, std::int64_t value) { sqlite3_bind_int64(statement_, column, value); }
  void bind(int column, double value) { sqlite3_bind_double(statement_, column, value); }
  void bind(int column, const std::string& text) {
    sqlite3_bind_text(statement_, column, text.data(), static_cast<int>(text.size()),
                      SQLITE_TRANSIENT);
  }
  /// Steps once: true for a row, false when done. @throws HistoryStoreError.
  bool step() {
    const int code = sqlite3_step(statement_);
    if (code == SQLITE_ROW) return true;
    if (code == SQLITE_DONE) return false;
    throw HistoryStoreError(
        path_.string(),
        fmt::format("{}: {}", path_.string(), sqlite3_errmsg(sqlite3_db_handle(statement_))));
  }
  /// Ready to bind and step again.
  void reset() { sqlite3_reset(statement_); }
  [[nodiscard]] std::int64_t integer(int column) const {
    return sqlite3_column_int64(statement_, column);
  }
  [[nodiscard]] double real(int column) const { return sqlite3_column_double(statement_, column); }
  [[nodiscard]] bool null(int column) const {
    return sqlite3_column_type(statement_, column) == SQLITE_NULL;
  }
  [[nodiscard]] std::string text(int column) const {
    const auto* data = sqlite3_column_text(statement_, column);
    return data != nullptr ? std::string(reinterpret_cast<const char*>(data)) : std::string();
  }

 private:
  sqlite3_stmt* statement_ = nullptr;
  const std::filesystem::path& path_;
};

sqlite3* open_database(const std::filesystem::path& path, int flags) {
  sqlite3* db = nullptr;
  const int code = sqlite3_open_v2(path.c_str(), &db, flags, nullptr);
  if (code != SQLITE_OK) {
    const std::string reason = db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(code);
    sqlite3_close(db);
    throw HistoryStoreError(path.string(),
                            fmt::format("{}: cannot be opened ({})", path.string(), reason));
  }
  sqlite3_extended_result_codes(db, 1);
  return db;
}

void require_file(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw HistoryStoreError(path.string(),
                            fmt::format("{}: is not a file; rule: --resume needs the database of "
                                        "an earlier session",
                                        path.string()));
  }
}

// The database and the directory its log and shared-memory files go to are writable: checked
// before SQLite opens it, which would otherwise open it read-only, create -wal and -shm files
// it cannot use and fail at the first write.
void require_writable(const std::filesystem::path& path) {
  const std::filesystem::path directory =
      path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  for (const auto& [file, mode, what] :
       {std::tuple{path, R_OK | W_OK, "the database"},
        std::tuple{directory, W_OK | X_OK, "its directory (for the -wal and -shm files)"}}) {
    if (::access(file.c_str(), mode) != 0) {
      throw HistoryStoreError(
          path.string(),
          fmt::format("{}: {} {} is not writable ({}); rule: --resume appends to the history, so "
                      "the database and its directory must be writable",
                      path.string(), what, file.string(), std::strerror(errno)));
    }
  }
}

}  // namespace

HistoryStore::HistoryStore(std::filesystem::path path, sqlite3* db) noexcept
    : path_(std::move(path)), db_(db) {}

HistoryStore::HistoryStore(HistoryStore&& other) noexcept
    : path_(std::move(other.path_)),
      db_(std::exchange(other.db_, nullptr)),
      checksums_(other.checksums_),
      database_identity_(other.database_identity_),
      log_identity_(other.log_identity_) {}

HistoryStore& HistoryStore::operator=(HistoryStore&& other) noexcept {
  if (this != &other) {
    sqlite3_close(db_);
    path_ = std::move(other.path_);
    db_ = std::exchange(other.db_, nullptr);
    checksums_ = other.checksums_;
    database_identity_ = other.database_identity_;
    log_identity_ = other.log_identity_;
  }
  return *this;
}

HistoryStore::~HistoryStore() { sqlite3_close(db_); }

void HistoryStore::configure(Durability durability) const {
  // journal_mode answers the mode it set: a file system without shared memory keeps another.
  Statement journal(db_, "PRAGMA journal_mode = WAL", path_);
  if (!journal.step() || journal.text(0) != "wal") {
    throw HistoryStoreError(
        path_.string(),
        fmt::format("{}: keeps journal mode \"{}\"; rule: a history needs a write-ahead log "
                    "(WAL), which this file system does not support",
                    path_.string(), journal.text(0)));
  }
  execute(durability == Durability::full ? "PRAGMA synchronous = FULL"
                                         : "PRAGMA synchronous = NORMAL");
  execute("PRAGMA foreign_keys = ON");
}

void HistoryStore::execute(const char* sql) const {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string reason = message != nullptr ? message : sqlite3_errmsg(db_);
    sqlite3_free(message);
    throw HistoryStoreError(path_.string(), fmt::format("{}: {}", path_.string(), reason));
  }
}

void HistoryStore::watch_files() {
  const auto identity = [](const std::filesystem::path& file) -> std::optional<FileIdentity> {
    struct stat status {};
    if (::stat(file.c_str(), &status) != 0) return std::nullopt;
    return FileIdentity{status.st_dev, status.st_ino};
  };
  database_identity_ = identity(path_);
  log_identity_ = identity(std::filesystem::path(path_.string() + "-wal"));
  if (!database_identity_ || !log_identity_) {
    throw HistoryStoreError(
        path_.string(), fmt::format("{}: its {} is missing right after opening it", path_.string(),
                                    database_identity_ ? "write-ahead log (-wal)" : "file"));
  }
}

void HistoryStore::require_same_files() const {
  for (const auto& [suffix, expected, what] :
       {std::tuple{"", database_identity_, "database file"},
        std::tuple{"-wal", log_identity_, "write-ahead log"}}) {
    const std::string file = path_.string() + suffix;
    struct stat status {};
    const bool present = ::stat(file.c_str(), &status) == 0;
    if (!present || FileIdentity{status.st_dev, status.st_ino} != *expected) {
      throw HistoryStoreError(
          path_.string(),
          fmt::format("{}: its {} {} was {} while the server ran; rule: the history's files "
                      "stay in place — the last record may not be durable, so the server stops "
                      "(resume it to see what the database holds)",
                      path_.string(), what, file, present ? "replaced" : "removed"));
    }
  }
}

HistoryStore HistoryStore::create(const std::filesystem::path& path, const json& settings,
                                  Durability durability) {
  std::error_code error;
  if (std::filesystem::exists(path, error)) {
    throw HistoryStoreError(path.string(),
                            fmt::format("{}: exists; rule: a new session needs a new database "
                                        "(resume an existing one with --resume)",
                                        path.string()));
  }
  HistoryStore store(path, open_database(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE));
  store.configure(durability);
  const auto execute = [&](const char* sql) { store.execute(sql); };
  execute("BEGIN");
  execute(schema);
  execute(snapshot_schema);
  {
    Statement insert(store.db_, "INSERT INTO settings (key, value) VALUES (?1, ?2)", path);
    json all = settings;
    all["format"] = std::to_string(format);
    all["created_at"] = now_utc();
    for (const auto& [key, value] : all.items()) {
      insert.bind(1, key);
      insert.bind(2, value.is_string() ? value.get<std::string>() : value.dump());
      insert.step();
      insert.reset();
    }
  }
  execute("COMMIT");
  store.watch_files();
  return store;
}

int HistoryStore::stored_format() const {
  json settings;
  try {
    settings = this->settings();
  } catch (const HistoryStoreError&) {
    throw HistoryStoreError(
        path_.string(),
        fmt::format("{}: is not a twincal serve history (no settings table)", path_.string()));
  }
  const std::string stored = settings.value("format", std::string("(none)"));
  if (stored != "1" && stored != std::to_string(format)) {
    throw HistoryStoreError(
        path_.string(), fmt::format("{}: has history format {}; rule: this twincal reads formats "
                                    "1 and {}",
                                    path_.string(), stored, format));
  }
  return stored == "1" ? 1 : format;
}

HistoryStore HistoryStore::open(const std::filesystem::path& path, Durability durability) {
  require_file(path);
  require_writable(path);
  HistoryStore store(path, open_database(path, SQLITE_OPEN_READWRITE));
  // What the file is, before anything is written to it (a journal mode is written to the
  // header of a foreign database too).
  const int stored = store.stored_format();
  if (sqlite3_db_readonly(store.db_, "main") == 1) {
    throw HistoryStoreError(path.string(),
                            fmt::format("{}: SQLite opened it read-only; rule: --resume appends "
                                        "to the history, so the database must be writable",
                                        path.string()));
  }
  store.configure(durability);
  if (stored == 1) store.upgrade_from_format_1();
  store.watch_files();
  return store;
}

HistoryStore HistoryStore::open_read_only(const std::filesystem::path& path) {
  require_file(path);
  HistoryStore store(path, open_database(path, SQLITE_OPEN_READONLY));
  store.checksums_ = store.stored_format() != 1;
  return store;
}

void HistoryStore::upgrade_from_format_1() {
  execute("BEGIN IMMEDIATE");
  try {
    execute("ALTER TABLE proposals ADD COLUMN checksum INTEGER NOT NULL DEFAULT 0");
    execute("ALTER TABLE observations ADD COLUMN checksum INTEGER NOT NULL DEFAULT 0");
    execute(snapshot_schema);
    checksums_ = false;  // the rows have none yet
    Statement proposal(db_, "UPDATE proposals SET checksum = ?2 WHERE request_id = ?1", path_);
    Statement observation(db_, "UPDATE observations SET checksum = ?2 WHERE request_id = ?1",
                          path_);
    for_each_record(1, [&](const HistoryRecord& record) {
      proposal.bind(1, record.request_id);
      proposal.bind(
          2, proposal_checksum(record.request_id, record.assembly.dump(), record.control.dump(),
                               record.report.dump(), record.proposed_at));
      proposal.step();
      proposal.reset();
      if (!record.quality) return;
      observation.bind(1, record.request_id);
      observation.bind(
          2, observation_checksum(record.request_id, *record.quality, record.estimate.dump(),
                                  record.covariance.dump(), record.observed_at));
      observation.step();
      observation.reset();
    });
    checksums_ = true;
    execute("UPDATE settings SET value = '2' WHERE key = 'format'");
    execute("COMMIT");
  } catch (...) {
    checksums_ = true;
    execute("ROLLBACK");
    throw;
  }
}

json HistoryStore::settings() const {
  Statement select(db_, "SELECT key, value FROM settings ORDER BY key", path_);
  json out = json::object();
  while (select.step()) out[select.text(0)] = select.text(1);
  return out;
}

void HistoryStore::for_each_record(std::int64_t first,
                                   const std::function<void(const HistoryRecord&)>& visit) const {
  visit_records(first, std::numeric_limits<std::int64_t>::max(), false, visit);
}

void HistoryStore::for_each_scanned_record(
    std::int64_t last, const std::function<void(const HistoryRecord&)>& visit) const {
  visit_records(1, last, true, visit);
}

void HistoryStore::visit_records(std::int64_t first, std::int64_t last, bool scanned_only,
                                 const std::function<void(const HistoryRecord&)>& visit) const {
  // A format-1 history has no checksum columns: NULL stands in for them. Scanned parts are
  // stored as a JSON object, the twin's own assemblies as an array.
  const std::string sql = fmt::format(
      "SELECT p.request_id, p.assembly, p.control, p.report, o.quality, o.estimate, "
      "o.covariance, p.proposed_at, o.observed_at, {} FROM proposals p LEFT JOIN observations o "
      "USING (request_id) WHERE p.request_id BETWEEN ?1 AND ?2{} ORDER BY p.request_id",
      checksums_ ? "p.checksum, o.checksum" : "NULL, NULL",
      scanned_only ? " AND substr(p.assembly, 1, 1) = '{'" : "");
  Statement select(db_, sql.c_str(), path_);
  select.bind(1, first);
  select.bind(2, last);
  HistoryRecord record;
  const auto damage = [&](std::string_view table, std::string_view column, std::string_view what) {
    return HistoryDamageError(
        std::string(column),
        fmt::format("{}: request {}: {}.{} {}; rule: a history is read back as it was written "
                    "(a damaged or edited database cannot be resumed)",
                    path_.string(), record.request_id, table, column, what));
  };
  const auto parse = [&](int index, std::string_view table, std::string_view column) {
    const std::string text = select.text(index);
    try {
      return json::parse(text);
    } catch (const json::exception& error) {
      throw damage(table, column, fmt::format("is not JSON ({})", error.what()));
    }
  };
  std::int64_t expected = first;
  while (select.step()) {
    record.request_id = select.integer(0);
    if (!scanned_only && record.request_id != expected) {
      throw damage("proposals", "request_id", fmt::format("follows request {}", expected - 1));
    }
    ++expected;
    if (checksums_) {
      const std::int64_t sum = proposal_checksum(record.request_id, select.text(1), select.text(2),
                                                 select.text(3), select.text(7));
      if (sum != select.integer(9)) {
        throw damage("proposals", "checksum",
                     fmt::format("is {}, the row's is {}", select.integer(9), sum));
      }
    }
    record.assembly = parse(1, "proposals", "assembly");
    record.control = parse(2, "proposals", "control");
    record.report = parse(3, "proposals", "report");
    record.proposed_at = select.text(7);
    record.quality.reset();
    record.estimate = nullptr;
    record.covariance = nullptr;
    record.observed_at.clear();
    if (!select.null(4)) {
      record.quality = select.real(4);
      record.observed_at = select.text(8);
      if (checksums_) {
        const std::int64_t sum = observation_checksum(
            record.request_id, *record.quality, select.text(5), select.text(6), record.observed_at);
        if (sum != select.integer(10)) {
          throw damage("observations", "checksum",
                       fmt::format("is {}, the row's is {}", select.integer(10), sum));
        }
      }
      record.estimate = parse(5, "observations", "estimate");
      record.covariance = parse(6, "observations", "covariance");
    }
    visit(record);
  }
}

std::vector<HistoryRecord> HistoryStore::records() const {
  std::vector<HistoryRecord> out;
  for_each_record(1, [&](const HistoryRecord& record) { out.push_back(record); });
  return out;
}

std::int64_t HistoryStore::proposal_checksum(std::int64_t request_id, std::string_view assembly,
                                             std::string_view control, std::string_view report,
                                             std::string_view proposed_at) {
  return row_checksum(request_id, {assembly, control, report, proposed_at});
}

std::int64_t HistoryStore::observation_checksum(std::int64_t request_id, double quality,
                                                std::string_view estimate,
                                                std::string_view covariance,
                                                std::string_view observed_at) {
  return row_checksum(request_id, {quality_text(quality), estimate, covariance, observed_at});
}

std::int64_t HistoryStore::snapshot_checksum(std::int64_t request_id, std::string_view state) {
  return row_checksum(request_id, {state});
}

std::int64_t HistoryStore::record_count() const {
  Statement count(db_, "SELECT count(*) FROM proposals", path_);
  count.step();
  return count.integer(0);
}

void HistoryStore::record_proposal(std::int64_t request_id, const json& assembly,
                                   const json& control, const json& report) {
  Statement insert(db_,
                   "INSERT INTO proposals (request_id, assembly, control, report, proposed_at, "
                   "checksum) VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
                   path_);
  const std::string texts[] = {assembly.dump(), control.dump(), report.dump(), now_utc()};
  insert.bind(1, request_id);
  for (int i = 0; i < 4; ++i) insert.bind(i + 2, texts[i]);
  insert.bind(6, proposal_checksum(request_id, texts[0], texts[1], texts[2], texts[3]));
  insert.step();
  require_same_files();
}

void HistoryStore::record_observation(std::int64_t request_id, double quality, const json& estimate,
                                      const json& covariance) {
  Statement insert(db_,
                   "INSERT INTO observations (request_id, quality, estimate, covariance, "
                   "observed_at, checksum) VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
                   path_);
  const std::string texts[] = {estimate.dump(), covariance.dump(), now_utc()};
  insert.bind(1, request_id);
  insert.bind(2, quality);
  for (int i = 0; i < 3; ++i) insert.bind(i + 3, texts[i]);
  insert.bind(6, observation_checksum(request_id, quality, texts[0], texts[1], texts[2]));
  insert.step();
  require_same_files();
}

void HistoryStore::record_snapshot(std::int64_t request_id, const json& state) {
  Statement insert(db_, "INSERT INTO snapshots (request_id, state, checksum) VALUES (?1, ?2, ?3)",
                   path_);
  const std::string text = state.dump();
  insert.bind(1, request_id);
  insert.bind(2, text);
  insert.bind(3, snapshot_checksum(request_id, text));
  insert.step();
  require_same_files();
}

namespace {

// The snapshot in the current row of `select` (request_id, state, checksum).
HistorySnapshot read_snapshot(const Statement& select, const std::filesystem::path& path) {
  HistorySnapshot snapshot{select.integer(0), nullptr};
  const std::string text = select.text(1);
  const auto damage = [&](std::string_view column, const std::string& what) {
    return HistoryDamageError(
        std::string(column),
        fmt::format("{}: request {}: snapshots.{} {}; rule: a history is read back as it was "
                    "written (a damaged or edited database cannot be resumed)",
                    path.string(), snapshot.request_id, column, what));
  };
  const std::int64_t sum = HistoryStore::snapshot_checksum(snapshot.request_id, text);
  if (sum != select.integer(2)) {
    throw damage("checksum", fmt::format("is {}, the row's is {}", select.integer(2), sum));
  }
  try {
    snapshot.state = json::parse(text);
  } catch (const json::exception& error) {
    throw damage("state", fmt::format("is not JSON ({})", error.what()));
  }
  return snapshot;
}

}  // namespace

std::optional<HistorySnapshot> HistoryStore::last_snapshot() const {
  if (!checksums_) return std::nullopt;  // format 1 has none
  Statement select(db_,
                   "SELECT request_id, state, checksum FROM snapshots ORDER BY request_id DESC "
                   "LIMIT 1",
                   path_);
  if (!select.step()) return std::nullopt;
  return read_snapshot(select, path_);
}

std::vector<std::int64_t> HistoryStore::snapshot_requests() const {
  std::vector<std::int64_t> out;
  if (!checksums_) return out;
  Statement select(db_, "SELECT request_id FROM snapshots ORDER BY request_id", path_);
  while (select.step()) out.push_back(select.integer(0));
  return out;
}

HistorySnapshot HistoryStore::snapshot(std::int64_t request_id) const {
  const auto missing = [&] {
    return HistoryStoreError(path_.string(), fmt::format("{}: has no snapshot after request {}",
                                                         path_.string(), request_id));
  };
  if (!checksums_) throw missing();  // format 1 has none
  Statement select(db_, "SELECT request_id, state, checksum FROM snapshots WHERE request_id = ?1",
                   path_);
  select.bind(1, request_id);
  if (!select.step()) throw missing();
  return read_snapshot(select, path_);
}

std::uintmax_t HistoryStore::checkpoint() {
  execute("PRAGMA wal_checkpoint(TRUNCATE)");
  require_same_files();
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path_, error);
  return error ? 0 : size;
}

}  // namespace twincal
