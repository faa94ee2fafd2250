// Any bytes as the lines a cell sends `twincal serve` (docs/serve.md), to a session of the
// active controller on the analytic twin (d = 3): every line gets one reply that is a JSON object
// with "ok" and "op", nothing a client sends ends the session, and a resume of the history it
// wrote is in the state the session is in.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "fuzz_database.hpp"
#include "twincal/external/twin_reply.hpp"
#include "twincal/serve/serve_session.hpp"

namespace {

using namespace twincal;

[[noreturn]] void broken(const std::string& what) {
  fmt::print(stderr, "serve_requests fuzzer: {}\n", what);
  std::abort();
}

ServeOptions session_options() {
  ServeOptions options;
  options.config.twin_case = TwinCase::analytic;
  options.config.analytic_dimension = 3;
  options.config.locators = "all";
  options.controller = ControllerSpec::active();
  options.durability = Durability::normal;
  options.snapshot_interval = 2;  // snapshots and the replay after them, within a short input
  return options;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path& database = fuzzing::fresh_database("serve-requests");
  ServeSession session = ServeSession::start(session_options(), database);
  std::string_view input(reinterpret_cast<const char*>(data), size);
  while (!input.empty() && !session.finished()) {
    const std::size_t end = std::min(input.find('\n'), input.size());
    const std::string_view line = input.substr(0, end);
    input.remove_prefix(std::min(end + 1, input.size()));
    const std::string reply = session.handle(line);
    const nlohmann::json parsed = nlohmann::json::parse(reply, nullptr, false);
    if (parsed.is_discarded() || !parsed.is_object() || !parsed.contains("ok") ||
        !parsed.at("ok").is_boolean() || !parsed.contains("op")) {
      broken(fmt::format("the reply {} to {} is not a reply", reply, quoted_output(line)));
    }
  }
  const ServeSession resumed = ServeSession::resume(database, Durability::normal);
  if (resumed.state() != session.state()) {
    broken(fmt::format("resumed to {}, the session is at {}", resumed.state().dump(),
                       session.state().dump()));
  }
  return 0;
}
