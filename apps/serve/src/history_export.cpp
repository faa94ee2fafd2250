// write_history_csv (history_export.hpp).
#include "twincal/serve/history_export.hpp"

#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace twincal {
namespace {

using nlohmann::json;

// A number as the shortest text that reads back to it; null (no value) as an empty field.
std::string field(const json& value) { return value.is_number() ? value.dump() : std::string(); }

// A CSV field of free text: quoted, with its quotes doubled, when it holds a comma, a quote or a
// line break.
std::string text_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + '"';
}

// upper,lower,assembly of a stored assembly: the part indices of one of the twin's own, or the
// cell's id of a scanned one (a string as is, anything else as JSON).
std::string assembly_fields(const json& stored) {
  if (stored.is_object()) {
    const json& id = stored.at("assembly");
    return ",," + text_field(id.is_string() ? id.get<std::string>() : id.dump());
  }
  return fmt::format("{},{},", stored.at(0).dump(), stored.at(1).dump());
}

}  // namespace

void write_history_csv(const HistoryStore& store, std::ostream& out) {
  const json settings = store.settings();
  std::vector<std::string> names;
  try {
    names = json::parse(settings.at("locator_names").get<std::string>())
                .get<std::vector<std::string>>();
  } catch (const json::exception& error) {
    throw HistoryStoreError(store.path().string(),
                            fmt::format("{}: its locator names cannot be read ({})",
                                        store.path().string(), error.what()));
  }
  out << "request_id,upper,lower,assembly,proposed_at,observed_at,quality,optimal_quality";
  for (const char* prefix : {"control_", "estimate_", "sd_"}) {
    for (const std::string& name : names) out << ',' << prefix << name;
  }
  out << '\n';
  const std::size_t d = names.size();
  store.for_each_record(1, [&](const HistoryRecord& record) {
    out << record.request_id << ',' << assembly_fields(record.assembly) << ',' << record.proposed_at
        << ',' << record.observed_at << ','
        << (record.quality ? json(*record.quality).dump() : std::string()) << ','
        << field(record.report.value("optimal_quality", json()));
    for (std::size_t i = 0; i < d; ++i) out << ',' << field(record.control.at(i));
    for (std::size_t i = 0; i < d; ++i) {
      out << ',' << (record.quality ? field(record.estimate.at(i)) : std::string());
    }
    for (std::size_t i = 0; i < d; ++i) {
      std::string sd;
      if (record.quality && record.covariance.at(i).at(i).is_number()) {
        sd = json(std::sqrt(record.covariance.at(i).at(i).get<double>())).dump();
      }
      out << ',' << sd;
    }
    out << '\n';
  });
}

}  // namespace twincal
