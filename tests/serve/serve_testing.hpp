#pragma once
// What the serve tests share: a fresh database path, and the options of a session over the
// analytic twin (fast to build) with every locator.
#include <unistd.h>

#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "twincal/serve/serve_session.hpp"

namespace twincal::testing {

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

}  // namespace twincal::testing
