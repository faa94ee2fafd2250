// HistoryStore (history_store.hpp): the SQLite history of a serve session.
#include "twincal/serve/history_store.hpp"

#include <sqlite3.h>

#include <chrono>
#include <utility>

#include <fmt/chrono.h>
#include <fmt/format.h>

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
  proposed_at TEXT NOT NULL);
CREATE TABLE observations (
  request_id INTEGER PRIMARY KEY REFERENCES proposals (request_id),
  quality REAL NOT NULL,
  estimate TEXT NOT NULL,
  covariance TEXT NOT NULL,
  observed_at TEXT NOT NULL);
)sql";

std::string now_utc() {
  return fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", std::chrono::time_point_cast<std::chrono::seconds>(
                                                  std::chrono::system_clock::now()));
}

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

}  // namespace

HistoryStore::HistoryStore(std::filesystem::path path, sqlite3* db) noexcept
    : path_(std::move(path)), db_(db) {}

HistoryStore::HistoryStore(HistoryStore&& other) noexcept
    : path_(std::move(other.path_)), db_(std::exchange(other.db_, nullptr)) {}

HistoryStore& HistoryStore::operator=(HistoryStore&& other) noexcept {
  if (this != &other) {
    sqlite3_close(db_);
    path_ = std::move(other.path_);
    db_ = std::exchange(other.db_, nullptr);
  }
  return *this;
}

HistoryStore::~HistoryStore() { sqlite3_close(db_); }

void HistoryStore::configure(Durability durability) const {
  execute("PRAGMA journal_mode = WAL");
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
  return store;
}

HistoryStore HistoryStore::open(const std::filesystem::path& path, Durability durability) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw HistoryStoreError(path.string(),
                            fmt::format("{}: is not a file; rule: --resume needs the database of "
                                        "an earlier session",
                                        path.string()));
  }
  HistoryStore store(path, open_database(path, SQLITE_OPEN_READWRITE));
  store.configure(durability);
  json settings;
  try {
    settings = store.settings();
  } catch (const HistoryStoreError&) {
    throw HistoryStoreError(
        path.string(),
        fmt::format("{}: is not a twincal serve history (no settings table)", path.string()));
  }
  if (!settings.contains("format") || settings["format"] != std::to_string(format)) {
    throw HistoryStoreError(
        path.string(),
        fmt::format("{}: has history format {}; rule: this twincal reads format {}", path.string(),
                    settings.value("format", std::string("(none)")), format));
  }
  return store;
}

json HistoryStore::settings() const {
  Statement select(db_, "SELECT key, value FROM settings ORDER BY key", path_);
  json out = json::object();
  while (select.step()) out[select.text(0)] = select.text(1);
  return out;
}

std::vector<HistoryRecord> HistoryStore::records() const {
  Statement select(db_,
                   "SELECT p.request_id, p.assembly, p.control, p.report, o.quality, o.estimate, "
                   "o.covariance, p.proposed_at, o.observed_at FROM proposals p LEFT JOIN "
                   "observations o USING (request_id) "
                   "ORDER BY p.request_id",
                   path_);
  std::vector<HistoryRecord> out;
  while (select.step()) {
    HistoryRecord record;
    record.request_id = select.integer(0);
    record.assembly = json::parse(select.text(1));
    record.control = json::parse(select.text(2));
    record.report = json::parse(select.text(3));
    record.proposed_at = select.text(7);
    if (!select.null(4)) {
      record.quality = select.real(4);
      record.estimate = json::parse(select.text(5));
      record.covariance = json::parse(select.text(6));
      record.observed_at = select.text(8);
    }
    out.push_back(std::move(record));
  }
  return out;
}

void HistoryStore::record_proposal(std::int64_t request_id, const json& assembly,
                                   const json& control, const json& report) {
  Statement insert(db_,
                   "INSERT INTO proposals (request_id, assembly, control, report, proposed_at) "
                   "VALUES (?1, ?2, ?3, ?4, ?5)",
                   path_);
  insert.bind(1, request_id);
  insert.bind(2, assembly.dump());
  insert.bind(3, control.dump());
  insert.bind(4, report.dump());
  insert.bind(5, now_utc());
  insert.step();
}

void HistoryStore::record_observation(std::int64_t request_id, double quality, const json& estimate,
                                      const json& covariance) {
  Statement insert(db_,
                   "INSERT INTO observations (request_id, quality, estimate, covariance, "
                   "observed_at) VALUES (?1, ?2, ?3, ?4, ?5)",
                   path_);
  insert.bind(1, request_id);
  insert.bind(2, quality);
  insert.bind(3, estimate.dump());
  insert.bind(4, covariance.dump());
  insert.bind(5, now_utc());
  insert.step();
}

std::uintmax_t HistoryStore::checkpoint() {
  execute("PRAGMA wal_checkpoint(TRUNCATE)");
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path_, error);
  return error ? 0 : size;
}

}  // namespace twincal
