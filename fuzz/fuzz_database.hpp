#pragma once
// The serve fuzzers' database: one path per process in the temporary directory, emptied (with
// SQLite's -wal and -shm) before each input, so every input starts from nothing.
#include <unistd.h>

#include <filesystem>

#include <fmt/format.h>

namespace twincal::fuzzing {

inline const std::filesystem::path& fresh_database(const char* fuzzer) {
  static const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      fmt::format("twincal-fuzz-{}-{}.db", fuzzer, ::getpid());
  for (const char* suffix : {"", "-wal", "-shm"}) {
    std::filesystem::remove(path.string() + suffix);
  }
  return path;
}

}  // namespace twincal::fuzzing
