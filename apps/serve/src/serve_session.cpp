// ServeSession (serve_session.hpp): the protocol, the history and its replay.
#include "twincal/serve/serve_session.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <Eigen/Cholesky>

#include "twincal/core/error.hpp"
#include "twincal/core/json_nesting.hpp"
#include "twincal/core/options.hpp"
#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/twin_cases.hpp"

namespace twincal {
namespace {

using nlohmann::json;

constexpr const char* operations = "propose, observe, predict, state, checkpoint, shutdown";
// The "format" of a snapshot's state (serve_session.hpp, snapshot_json).
constexpr const char* snapshot_format = "twincal.serve_snapshot.1";

// JSON has no NaN: a non-finite entry (a controller without P) is null, in replies and in the
// history alike, so a replay compares like with like.
json vector_json(const Eigen::Ref<const VectorX>& v) {
  json out = json::array();
  for (Index i = 0; i < v.size(); ++i) {
    out.push_back(std::isfinite(v(i)) ? json(v(i)) : json(nullptr));
  }
  return out;
}

json error_reply(const json& op, const std::string& field, const std::string& message) {
  return {{"ok", false}, {"op", op}, {"error", {{"field", field}, {"message", message}}}};
}

// A reply line. Bytes that are not UTF-8 (a request's, quoted in a message) become U+FFFD
// instead of failing the reply.
std::string line_of(const json& reply) {
  return reply.dump(-1, ' ', false, json::error_handler_t::replace);
}

// Refuses keys a request of `op` does not take, naming the first one.
void require_keys(const json& request, std::string_view op,
                  std::initializer_list<std::string_view> allowed) {
  for (const auto& [key, value] : request.items()) {
    bool known = key == "op";
    for (const std::string_view name : allowed) known = known || key == name;
    if (!known) {
      std::string list = "op";
      for (const std::string_view name : allowed) list += fmt::format(", {}", name);
      throw InvalidArgumentError(
          key, fmt::format("{}: is not a field of {}; rule: {} takes {}", key, op, op, list));
    }
  }
}

// Whether a recomputed report is the recorded one: u0, z*, δû and σ bit for bit. Its
// twin_evaluations is a cost, not a result (a resume from a snapshot searches u0 again where the
// recorded run had it cached), and its fallback a reason (a twin error need not recur in a
// replay; the recomputed control is compared on its own); the row's checksum covers both.
bool same_report(const json& recomputed, const json& recorded) {
  const auto compared = [](json report) {
    if (report.is_object()) {
      report.erase("twin_evaluations");
      report.erase("fallback");
    }
    return report;
  };
  return compared(recomputed) == compared(recorded);
}

ExperimentConfig settings_config(const json& settings) {
  return json::parse(settings.at("config").get<std::string>()).get<ExperimentConfig>();
}

}  // namespace

std::optional<std::string> ServeOptions::validate() const {
  return first_problem(
      {rule::nested("config", config),
       rule::check(!config.plant_case && !config.plant_nonlinearity && !config.plant_external_twin,
                   "config.plant_case, plant_nonlinearity and plant_external_twin",
                   "one of them set",
                   "twincal serve's plant is the cell, so a served config sets "
                   "none"),
       rule::check(run >= 0, "run", run, "must be >= 0"),
       rule::check(snapshot_interval >= 0, "snapshot_interval", snapshot_interval,
                   "must be >= 0 (0: no snapshots)")});
}
std::optional<std::string> ResumeOptions::validate() const {
  return rule::check(snapshot_interval >= 0, "snapshot_interval", snapshot_interval,
                     "must be >= 0 (0: no snapshots)");
}

ServeSession::ServeSession(ServeOptions options, std::unique_ptr<CaseTwin> twin, HistoryStore store)
    : options_(std::move(options)),
      twin_(std::move(twin)),
      controller_(
          make_episode_controller(*twin_, options_.config, options_.controller, options_.run)),
      store_(std::move(store)),
      control_(twin_->control_dimension()),
      estimate_(twin_->control_dimension()),
      covariance_(twin_->control_dimension(), twin_->control_dimension()) {}

ServeSession ServeSession::start(const ServeOptions& options,
                                 const std::filesystem::path& database) {
  require_valid("options", options);
  auto twin = std::make_unique<CaseTwin>(make_case_twin(options.config));
  // Checks the controller's settings before the database exists.
  (void)make_episode_controller(*twin, options.config, options.controller, options.run);
  const json settings = {{"config", json(options.config).dump()},
                         {"locator_names", json(twin->locator_names()).dump()},
                         {"controller", options.controller.label()},
                         {"run", std::to_string(options.run)},
                         {"twincal_version", TWINCAL_VERSION}};
  HistoryStore store = HistoryStore::create(database, settings, options.durability);
  return {options, std::move(twin), std::move(store)};
}

ServeSession ServeSession::from_settings(HistoryStore store, const ResumeOptions& resume) {
  const json settings = store.settings();
  const std::string database = store.path().string();
  ServeOptions options;
  try {
    options.config = settings_config(settings);
    options.controller = ControllerSpec::parse(settings.at("controller").get<std::string>());
    options.run = std::stoll(settings.at("run").get<std::string>());
  } catch (const std::exception& error) {
    throw HistoryStoreError(
        database, fmt::format("{}: its settings cannot be read ({})", database, error.what()));
  }
  options.durability = resume.durability;
  options.snapshot_interval = resume.snapshot_interval;
  return {options, std::make_unique<CaseTwin>(make_case_twin(options.config)), std::move(store)};
}

ServeSession ServeSession::resume(const std::filesystem::path& database,
                                  const ResumeOptions& options) {
  require_valid("options", options);
  ServeSession session = from_settings(HistoryStore::open(database, options.durability), options);
  if (options.verify_all) {
    (void)session.replay(/*verify_snapshots=*/true);
  } else {
    session.restore_last_snapshot(/*register_scanned=*/true);
    (void)session.replay();
  }
  return session;
}

ServeSession ServeSession::resume(const std::filesystem::path& database, Durability durability) {
  return resume(database, ResumeOptions{.durability = durability});
}

HistoryCheck ServeSession::check(const std::filesystem::path& database) {
  ServeSession session = from_settings(HistoryStore::open_read_only(database), ResumeOptions{});
  const std::int64_t snapshots = session.replay(/*verify_snapshots=*/true);
  return {session.next_request_ - 1, session.observed_, snapshots, session.pending_.has_value()};
}

std::string ServeSession::oversized_reply(std::size_t bytes) {
  return line_of(error_reply(nullptr, "line",
                             fmt::format("line: has {} bytes; rule: at most {} bytes per request",
                                         bytes, max_line_bytes)));
}

std::string ServeSession::handle(std::string_view line) {
  if (line.size() > max_line_bytes) return oversized_reply(line.size());
  if (line.find_first_not_of(" \t\r") == std::string_view::npos) {
    return line_of(error_reply(nullptr, "line",
                               "line: is empty; rule: one JSON request (an object) per line"));
  }
  json request;
  try {
    require_json_nesting(line, "line");
    request = json::parse(line);
  } catch (const InvalidArgumentError& error) {
    return line_of(error_reply(nullptr, error.argument(), error.what()));
  } catch (const json::exception& error) {
    // Any parser failure, a number beyond double's range (1e309) included.
    return line_of(
        error_reply(nullptr, "line", fmt::format("line: is not JSON ({})", error.what())));
  }
  if (!request.is_object()) {
    return line_of(error_reply(
        nullptr, "line",
        fmt::format("line: is a JSON {}; rule: a request is an object", request.type_name())));
  }
  const auto op_it = request.find("op");
  if (op_it == request.end() || !op_it->is_string()) {
    return line_of(error_reply(
        nullptr, "op", fmt::format("op: is missing or not a string; rule: one of {}", operations)));
  }
  const std::string op = op_it->get<std::string>();
  try {
    return line_of(dispatch(op, request));
  } catch (const HistoryStoreError&) {
    throw;  // the reply would promise what is not stored: the session must stop
  } catch (const Error& error) {
    return line_of(error_reply(op, error.argument(), error.what()));
  } catch (const std::exception& error) {
    // Not one of twincal's typed errors (a library's own): still this request's failure only.
    return line_of(error_reply(op, "op", fmt::format("{}: failed ({})", op, error.what())));
  }
}

json ServeSession::dispatch(const std::string& op, const json& request) {
  if (op == "propose") return propose(request);
  if (op == "observe") return observe(request);
  if (op == "predict") return predict(request);
  if (op == "state") {
    require_keys(request, op, {});
    json reply = state();
    reply["ok"] = true;
    reply["op"] = op;
    return reply;
  }
  if (op == "checkpoint") {
    require_keys(request, op, {});
    snapshot_if_due(/*now=*/true);
    const std::uintmax_t bytes = store_.checkpoint();
    return {{"ok", true}, {"op", op}, {"database", store_.path().string()}, {"bytes", bytes}};
  }
  if (op == "shutdown") {
    require_keys(request, op, {});
    snapshot_if_due(/*now=*/true);
    finished_ = true;
    return {{"ok", true}, {"op", op}, {"observed", observed_}};
  }
  throw InvalidArgumentError("op", fmt::format("op: is \"{}\"; rule: one of {}", op, operations));
}

ServeSession::ResolvedAssembly ServeSession::resolve_assembly(const json& request) {
  const auto it = request.find("assembly");
  if (it == request.end()) {
    throw InvalidArgumentError("assembly",
                               "assembly: is missing; rule: a request names the assembly, as an "
                               "index or [upper, lower], or by any id together with its parts");
  }
  if (const auto parts = request.find("parts"); parts != request.end()) {
    if (parts->is_null()) {
      throw InvalidArgumentError("parts",
                                 "parts: is null; rule: the scanned parts, any other JSON value");
    }
    const AssemblyId id = twin_->add_scanned(*parts);
    // The full twin's u0 and z* go into the history with the parts, so that a resume registers
    // them again without searching (a slow twin's search takes thousands of calls).
    const AnyTwin& full = twin_->full_twin();
    return {id,
            {{"assembly", *it},
             {"parts", *parts},
             {"optimum", vector_json(full.optimum(id))},
             {"optimal_quality", full.optimal_quality(id)}}};
  }
  const std::vector<AssemblyId>& all = twin_->assemblies();
  if (it->is_number_integer()) {
    const auto index = it->get<std::int64_t>();
    if (index < 0 || index >= std::ssize(all)) {
      throw InvalidArgumentError(
          "assembly", fmt::format("assembly: is {}; rule: an index must lie in [0, {}]", index,
                                  std::ssize(all) - 1));
    }
    const AssemblyId id = all[static_cast<std::size_t>(index)];
    return {id, {id.upper, id.lower}};
  }
  if (it->is_array() && it->size() == 2 && (*it)[0].is_number_integer() &&
      (*it)[1].is_number_integer()) {
    const AssemblyId id{(*it)[0].get<Index>(), (*it)[1].get<Index>()};
    if (std::find(all.begin(), all.end(), id) == all.end()) {
      throw InvalidArgumentError(
          "assembly", fmt::format("assembly: is [{}, {}]; rule: must be one of the twin's {} "
                                  "assemblies",
                                  id.upper, id.lower, all.size()));
    }
    return {id, {id.upper, id.lower}};
  }
  throw InvalidArgumentError("assembly", fmt::format("assembly: is {}; rule: an index or [upper, "
                                                     "lower] (integers), or any id with parts",
                                                     it->dump()));
}

ServeSession::ResolvedAssembly ServeSession::recorded_assembly(const json& stored) {
  if (stored.is_object()) {
    const auto optimum = stored.at("optimum").get<std::vector<double>>();
    const ScannedOptimum known{Eigen::Map<const VectorX>(optimum.data(), std::ssize(optimum)),
                               stored.at("optimal_quality").get<double>()};
    return {twin_->add_scanned(stored.at("parts"), known), stored};
  }
  return {AssemblyId{stored.at(0).get<Index>(), stored.at(1).get<Index>()}, stored};
}

json ServeSession::echo(const json& stored) {
  return stored.is_object() ? stored.at("assembly") : stored;
}

json ServeSession::estimate_json() const {
  controller_.offset_estimate(estimate_);
  return vector_json(estimate_);
}

json ServeSession::covariance_json() const {
  controller_.offset_covariance(covariance_);
  json rows = json::array();
  for (Index i = 0; i < covariance_.rows(); ++i) rows.push_back(vector_json(covariance_.row(i)));
  return rows;
}

json ServeSession::make_proposal(std::int64_t request_id, const AssemblyId& assembly,
                                 const json& stored) {
  const std::uint64_t before = CaseTwin::evaluations_on_this_thread();
  controller_.propose(assembly, control_);
  const std::uint64_t evaluations = CaseTwin::evaluations_on_this_thread() - before;
  const VectorX optimum = twin_->optimum(assembly);
  json standard_deviation = json::array();
  controller_.offset_covariance(covariance_);
  for (Index i = 0; i < covariance_.rows(); ++i) {
    const double sd = std::sqrt(covariance_(i, i));
    standard_deviation.push_back(std::isfinite(sd) ? json(sd) : json(nullptr));
  }
  json report{{"optimum", vector_json(optimum)},
              {"optimal_quality", twin_->optimal_quality(assembly)},
              {"estimate", estimate_json()},
              {"standard_deviation", standard_deviation},
              {"twin_evaluations", evaluations}};
  if (const std::string_view why = controller_.fallback(); !why.empty()) {
    report["fallback"] = why;
  }
  return {{"ok", true},
          {"op", "propose"},
          {"request_id", request_id},
          {"assembly", echo(stored)},
          {"control", vector_json(control_)},
          {"report", std::move(report)}};
}

json ServeSession::propose(const json& request) {
  require_keys(request, "propose", {"assembly", "parts"});
  const ResolvedAssembly assembly = resolve_assembly(request);
  if (pending_) {
    if (pending_->assembly_json == assembly.stored) {
      json reply = pending_->reply;
      reply["repeated"] = true;
      return reply;
    }
    throw InvalidArgumentError(
        "op", fmt::format("op: propose while request {} (assembly {}) awaits its observation; "
                          "rule: one assembly at a time — observe it first",
                          pending_->request_id, echo(pending_->assembly_json).dump()));
  }
  json reply;
  try {
    reply = make_proposal(next_request_, assembly.id, assembly.stored);
  } catch (...) {
    rebuild();  // the controller may have predicted: back to what the history holds
    throw;
  }
  store_.record_proposal(next_request_, assembly.stored, reply["control"], reply["report"]);
  pending_ = Pending{next_request_, assembly.id, assembly.stored, control_, reply};
  ++next_request_;
  return reply;
}

json ServeSession::observe(const json& request) {
  require_keys(request, "observe", {"request_id", "quality"});
  const auto id_it = request.find("request_id");
  if (id_it == request.end() || !id_it->is_number_integer()) {
    throw InvalidArgumentError("request_id",
                               "request_id: is missing or not an integer; rule: observe names "
                               "the request_id of its proposal");
  }
  const auto request_id = id_it->get<std::int64_t>();
  const auto quality_it = request.find("quality");
  if (quality_it == request.end() || !quality_it->is_number() ||
      !std::isfinite(quality_it->get<double>())) {
    throw InvalidArgumentError(
        "quality", fmt::format("quality: is {}; rule: must be a finite number",
                               quality_it == request.end() ? "missing" : quality_it->dump()));
  }
  const double quality = quality_it->get<double>();
  if (!pending_ || pending_->request_id != request_id) {
    const std::string rule =
        pending_ ? fmt::format("request {} awaits its observation", pending_->request_id)
                 : std::string("no request awaits an observation");
    const bool past = request_id >= 1 && request_id < next_request_;
    throw InvalidArgumentError("request_id",
                               fmt::format("request_id: {} {}; rule: {}", request_id,
                                           past ? "was already observed" : "is unknown", rule));
  }
  try {
    controller_.observe(pending_->assembly, pending_->control, quality);
    require_sound_state(quality);
  } catch (...) {
    rebuild();  // the history does not hold this observation: the state is as before it
    throw;
  }
  json estimate = estimate_json();
  json covariance = covariance_json();
  store_.record_observation(request_id, quality, estimate, covariance);
  pending_.reset();
  ++observed_;
  snapshot_if_due(/*now=*/false);
  json reply{{"ok", true},           {"op", "observe"},          {"request_id", request_id},
             {"estimate", estimate}, {"covariance", covariance}, {"observed", observed_}};
  if (const std::string_view why = controller_.dropped_measurement(); !why.empty()) {
    reply["dropped_measurement"] = why;
  }
  return reply;
}

json ServeSession::predict(const json& request) {
  require_keys(request, "predict", {"assembly", "parts", "control"});
  const ResolvedAssembly assembly = resolve_assembly(request);
  const auto it = request.find("control");
  const Index d = twin_->control_dimension();
  if (it == request.end() || !it->is_array() || std::ssize(*it) != d) {
    throw InvalidArgumentError("control",
                               fmt::format("control: is {}; rule: an array of {} numbers",
                                           it == request.end() ? "missing" : it->dump(), d));
  }
  VectorX control(d);
  for (Index i = 0; i < d; ++i) {
    const json& entry = (*it)[static_cast<std::size_t>(i)];
    if (!entry.is_number() || !std::isfinite(entry.get<double>())) {
      throw InvalidArgumentError(
          "control",
          fmt::format("control[{}]: is {}; rule: must be a finite number", i, entry.dump()));
    }
    control(i) = entry.get<double>();
  }
  return {{"ok", true},
          {"op", "predict"},
          {"assembly", echo(assembly.stored)},
          {"quality", twin_->plant_quality(assembly.id, control)}};
}

json ServeSession::state() const {
  json pending = nullptr;
  if (pending_) {
    pending = {{"request_id", pending_->request_id},
               {"assembly", echo(pending_->assembly_json)},
               {"control", vector_json(pending_->control)}};
  }
  return {{"controller", options_.controller.label()},
          {"group", options_.config.group_name()},
          {"locators", twin_->locator_names()},
          {"observed", observed_},
          {"pending", pending},
          {"estimate", estimate_json()},
          {"covariance", covariance_json()},
          {"database", store_.path().string()}};
}

std::int64_t ServeSession::replay(bool verify_snapshots) {
  const std::string database = store_.path().string();
  std::int64_t unobserved = 0;  // a request without its observation, which must be the last
  // The snapshots to compare, ascending; the replay passes them in order.
  const std::vector<std::int64_t> snapshots =
      verify_snapshots ? store_.snapshot_requests() : std::vector<std::int64_t>{};
  auto next_snapshot = std::lower_bound(snapshots.begin(), snapshots.end(), next_request_);
  std::int64_t compared = 0;
  store_.for_each_record(next_request_, [&](const HistoryRecord& record) {
    const auto mismatch = [&](std::string_view what) {
      return HistoryMismatchError(
          std::string(what),
          fmt::format("{}: request {} replays to another {} than the one recorded; rule: a "
                      "history resumes with the twincal build that wrote it",
                      database, record.request_id, what));
    };
    if (unobserved != 0) {
      throw HistoryMismatchError(
          "observation", fmt::format("{}: request {} has no observation, yet request {} follows; "
                                     "rule: the cell observes one request before the next",
                                     database, unobserved, record.request_id));
    }
    if (record.request_id != next_request_) throw mismatch("request_id");
    AssemblyId assembly;
    try {
      assembly = recorded_assembly(record.assembly).id;
    } catch (const json::exception&) {
      throw mismatch("assembly");
    } catch (const InvalidArgumentError&) {  // scanned parts the twin takes none of, or
      throw mismatch("assembly");            // a recorded optimum of the wrong size
    } catch (const NonFiniteError&) {
      throw mismatch("assembly");
    }
    const json reply = make_proposal(record.request_id, assembly, record.assembly);
    if (reply["control"] != record.control) throw mismatch("control");
    if (!same_report(reply["report"], record.report)) throw mismatch("report");
    ++next_request_;
    if (!record.quality) {
      unobserved = record.request_id;
      pending_ = Pending{record.request_id, assembly, record.assembly, control_, reply};
      return;
    }
    controller_.observe(assembly, control_, *record.quality);
    if (estimate_json() != record.estimate) throw mismatch("estimate");
    if (covariance_json() != record.covariance) throw mismatch("covariance");
    ++observed_;
    if (next_snapshot != snapshots.end() && *next_snapshot == record.request_id) {
      const json stored = store_.snapshot(record.request_id).state;
      // Comparable when the snapshot's process had the replay's scanned ids (restore above).
      if (!stored.is_object() || stored.value("scanned", Index{-1}) == twin_->scanned_count()) {
        if (snapshot_json().dump() != stored.dump()) throw mismatch("snapshot");
        ++compared;
      }
      last_snapshot_ = record.request_id;
      ++next_snapshot;
    }
  });
  if (next_snapshot != snapshots.end()) {
    throw HistoryMismatchError(
        "snapshot", fmt::format("{}: has a snapshot after request {}, which was not replayed; "
                                "rule: a snapshot follows an observation",
                                database, *next_snapshot));
  }
  return compared;
}

void ServeSession::restore_last_snapshot(bool register_scanned) {
  const std::optional<HistorySnapshot> snapshot = store_.last_snapshot();
  if (!snapshot) return;
  const std::string database = store_.path().string();
  const auto mismatch = [&](const std::string& why) {
    return HistoryMismatchError(
        "snapshot",
        fmt::format("{}: the snapshot after request {} cannot be restored ({}); rule: a history "
                    "resumes with the twincal build that wrote it (--verify-all replays it "
                    "whole instead)",
                    database, snapshot->request_id, why));
  };
  const json& state = snapshot->state;
  if (!state.is_object() || state.value("format", "") != snapshot_format ||
      state.value("request_id", std::int64_t{-1}) != snapshot->request_id ||
      !state.contains("controller") || !state.contains("scanned")) {
    throw mismatch("not a twincal serve snapshot of this request");
  }
  // The controller refers to scanned assemblies by id, given in the order they first arrived:
  // the proposals up to the snapshot, registered again in that order (a scan of the table,
  // skipped when there are none), give the snapshot's ids unless its process also registered
  // parts it was only asked to `predict`. Then the ids differ, and the whole history is
  // replayed instead (its ids are the proposals' own).
  if (register_scanned && state.at("scanned") != 0) {
    try {
      store_.for_each_scanned_record(snapshot->request_id, [&](const HistoryRecord& record) {
        (void)recorded_assembly(record.assembly);
      });
    } catch (const HistoryStoreError&) {
      throw;
    } catch (const std::exception& error) {
      throw mismatch(error.what());
    }
  }
  if (state.at("scanned") != twin_->scanned_count()) return;
  try {
    controller_.restore(state.at("controller"));
  } catch (const std::exception& error) {
    throw mismatch(error.what());
  }
  next_request_ = snapshot->request_id + 1;
  observed_ = snapshot->request_id;
  last_snapshot_ = snapshot->request_id;
  trusted_snapshot_ = snapshot->request_id;
  pending_.reset();
}

json ServeSession::snapshot_json() const {
  return {{"format", snapshot_format},
          {"request_id", next_request_ - 1},
          {"scanned", twin_->scanned_count()},
          {"controller", controller_.save()}};
}

void ServeSession::snapshot_if_due(bool now) {
  const std::int64_t last = next_request_ - 1;  // observed, as nothing is pending
  if (options_.snapshot_interval == 0 || pending_ || observed_ == 0 || last_snapshot_ == last) {
    return;
  }
  if (!now && observed_ % options_.snapshot_interval != 0) return;
  store_.record_snapshot(last, snapshot_json());
  last_snapshot_ = last;
  if (trusted_snapshot_ == 0) trusted_snapshot_ = last;
}

void ServeSession::require_sound_state(double quality) const {
  if (!controller_.estimates()) return;  // no estimate, nothing an observation can spoil
  controller_.offset_estimate(estimate_);
  controller_.offset_covariance(covariance_);
  const VectorX reach = max_estimate_widths * (twin_->upper_bounds() - twin_->lower_bounds());
  std::string_view broken;
  if (!estimate_.allFinite() || !covariance_.allFinite()) {
    broken = "the offset estimate or its covariance non-finite";
  } else if ((estimate_.array().abs() > reach.array()).any()) {
    broken = "the offset estimate beyond max_estimate_widths (1000) box widths";
  } else if (covariance_.llt().info() != Eigen::Success) {
    broken = "the offset covariance not positive definite";
  } else {
    return;
  }
  throw NonFiniteError("quality",
                       fmt::format("quality: {} leaves {}; rule: an observation the controller can "
                                   "take (it is refused, and the state is as before it)",
                                   quality, broken));
}

void ServeSession::rebuild() {
  controller_ = make_episode_controller(*twin_, options_.config, options_.controller, options_.run);
  pending_.reset();
  next_request_ = 1;
  observed_ = 0;
  last_snapshot_ = 0;
  // A snapshot this process took or restored shares this twin's scanned ids; an older one
  // (resume replayed the whole history instead of restoring it) may not.
  if (const std::optional<HistorySnapshot> last = store_.last_snapshot();
      last && last->request_id >= trusted_snapshot_ && trusted_snapshot_ > 0) {
    restore_last_snapshot(/*register_scanned=*/false);  // the twin has them already
  }
  (void)replay();
}

}  // namespace twincal
