// Any bytes as a history database (docs/serve.md): `twincal history --check` and
// `twincal serve --resume` on it either replay it or stop with a twincal::Error naming what is
// wrong (HistoryStoreError, HistoryDamageError, HistoryMismatchError, …), never another
// exception or a crash.
#include <cstddef>
#include <cstdint>
#include <fstream>

#include "fuzz_database.hpp"
#include "twincal/core/error.hpp"
#include "twincal/serve/serve_session.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace twincal;
  const std::filesystem::path& database = fuzzing::fresh_database("history-replay");
  std::ofstream(database, std::ios::binary)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  try {
    (void)ServeSession::check(database);
  } catch (const Error&) {
  }
  try {
    const ServeSession resumed = ServeSession::resume(database, Durability::normal);
    (void)resumed.state();
  } catch (const Error&) {
  }
  return 0;
}
