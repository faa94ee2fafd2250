#pragma once
/// @file
/// `ServeSession`: the online controller of `twincal serve` — the paper's Fig. 1 loop with a
/// real cell on the other side. Per assembly the cell sends `propose` (which assembly, or its
/// scanned parts for a twin that takes them: the external case), the
/// session answers with the locator adjustment u_t; after welding the cell sends `observe` (the
/// measured quality z_t) and the controller learns from it (eq. 5a–b, 8). One request at a time:
/// the controllers predict in propose and update in observe, so a second propose before the
/// first one's observation is refused (unless it repeats the pending request's assembly: then
/// the pending proposal is answered again, so a client that lost a reply retries safely).
///
/// Nothing is lost: each proposal, and each observation with δû_t and P_t after it, is in the
/// HistoryStore before the reply leaves. resume() rebuilds the controller from the settings and
/// replays the history, checking every recomputed control and estimate against the recorded
/// one bit for bit, so a session killed at any moment continues exactly where it was.
///
/// `predict` asks the twin for Q(x, u) without touching the controller (what a simulated cell
/// or an engineer checking a control needs). The protocol (docs/serve.md) is one JSON object
/// per line; handle() maps a request line to a
/// reply line and never throws for a bad request: a malformed, oversized or unknown request, an
/// unknown assembly, an observation of an unknown or already observed request, a non-finite
/// quality get {"ok": false, "error": {"field", "message"}} and change nothing.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "twincal/controllers/any_controller.hpp"
#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/experiments/case_twin.hpp"
#include "twincal/experiments/controller_spec.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/serve/history_store.hpp"

namespace twincal {

/// What a new session controls: the twin case and the controller's settings of `config` (its
/// `controllers` and `runs` are not used), `controller`, built with the seeds of `run` as
/// `twincal run` builds it (episode_runner.hpp's make_episode_controller).
struct ServeOptions {
  ExperimentConfig config;
  ControllerSpec controller = ControllerSpec::active();
  Index run = 0;
  Durability durability = Durability::full;
  /// Observations between snapshots of the controller's state in the history (and one at each
  /// `checkpoint` and `shutdown`): a resume restores the last snapshot and replays only what
  /// follows. 0: no snapshots (a resume replays the whole history).
  std::int64_t snapshot_interval = 1000;

  [[nodiscard]] std::optional<std::string> validate() const;
};

/// How ServeSession::resume() rebuilds the controller.
struct ResumeOptions {
  Durability durability = Durability::full;
  /// For the records the resumed session writes (ServeOptions::snapshot_interval).
  std::int64_t snapshot_interval = 1000;
  /// Replay the whole history from the settings, comparing every snapshot on the way, instead
  /// of starting from the last snapshot (`twincal serve --resume --verify-all`).
  bool verify_all = false;

  [[nodiscard]] std::optional<std::string> validate() const;
};

/// The history does not replay to what it recorded (another twincal build, a hand-edited
/// database); the message names the request and the quantity that differs.
class HistoryMismatchError : public Error {
 public:
  using Error::Error;
};

/// What ServeSession::check() verified of a history.
struct HistoryCheck {
  std::int64_t requests = 0;      ///< proposals replayed
  std::int64_t observations = 0;  ///< observations replayed
  std::int64_t snapshots = 0;     ///< snapshots compared with the replayed controller
  bool pending = false;           ///< the last request awaits its observation
};

class ServeSession {
 public:
  /// A line longer than this (without its newline) is refused unread.
  static constexpr std::size_t max_line_bytes = 1 << 20;
  /// An observation that leaves the offset estimate beyond this many box widths on a locator
  /// (or the estimate or its covariance non-finite, or the covariance not positive definite) is
  /// refused and the state kept: no cell is that far off, and a filter's sigma points lose
  /// every digit there (a quality of 1e154 put the paper's filter at 1e137 mm).
  static constexpr double max_estimate_widths = 1000.0;

  /// A new session writing to a new database at `database`.
  /// @throws InvalidArgumentError for invalid options; HistoryStoreError.
  [[nodiscard]] static ServeSession start(const ServeOptions& options,
                                          const std::filesystem::path& database);
  /// The session of `database`: the controller restored from the last snapshot (if any) and
  /// the requests after it replayed, each checked bit for bit; with `verify_all`, the whole
  /// history replayed and every snapshot compared.
  /// @throws InvalidArgumentError for invalid options; HistoryStoreError (HistoryDamageError);
  ///         HistoryMismatchError.
  [[nodiscard]] static ServeSession resume(const std::filesystem::path& database,
                                           const ResumeOptions& options);
  /// resume() with `durability` and the other options' defaults.
  [[nodiscard]] static ServeSession resume(const std::filesystem::path& database,
                                           Durability durability = Durability::full);

  /// Replays the whole history of `database` without writing to it (a running server's too),
  /// checking every row's checksum and every recomputed control, report, estimate, covariance
  /// and snapshot bit for bit: what `twincal history --check` runs.
  /// @throws HistoryStoreError (HistoryDamageError for a damaged row); HistoryMismatchError.
  [[nodiscard]] static HistoryCheck check(const std::filesystem::path& database);

  /// One request line → one reply line (without newline). @throws HistoryStoreError when the
  /// database cannot be written: the session must then stop (resume() continues from what the
  /// database holds).
  [[nodiscard]] std::string handle(std::string_view line);
  /// The reply to a line that exceeded max_line_bytes.
  [[nodiscard]] static std::string oversized_reply(std::size_t bytes);

  /// Whether a `shutdown` request was served.
  [[nodiscard]] bool finished() const noexcept { return finished_; }
  /// Observations so far.
  [[nodiscard]] std::int64_t observed() const noexcept { return observed_; }
  /// The body of the `state` reply: controller, locators, observed, pending, δû, P.
  [[nodiscard]] nlohmann::json state() const;
  [[nodiscard]] const HistoryStore& history() const noexcept { return store_; }
  [[nodiscard]] const CaseTwin& twin() const noexcept { return *twin_; }

 private:
  // An assembly as the controller sees it, and as the history stores it: [upper, lower] for
  // one of the twin's own, {"assembly": the cell's id, "parts": …} for scanned parts.
  struct ResolvedAssembly {
    AssemblyId id;
    nlohmann::json stored;
  };
  struct Pending {
    std::int64_t request_id = 0;
    AssemblyId assembly;
    nlohmann::json assembly_json;  // as stored
    VectorX control;
    nlohmann::json reply;
  };

  // Builds the controller over `twin`, which stays where it is: the controller refers to it.
  ServeSession(ServeOptions options, std::unique_ptr<CaseTwin> twin, HistoryStore store);
  // The session of `store`, built from its settings, nothing replayed yet.
  [[nodiscard]] static ServeSession from_settings(HistoryStore store, const ResumeOptions& options);

  // The reply to a request of `op` (a known or unknown operation). @throws Error.
  [[nodiscard]] nlohmann::json dispatch(const std::string& op, const nlohmann::json& request);
  [[nodiscard]] nlohmann::json propose(const nlohmann::json& request);
  [[nodiscard]] nlohmann::json observe(const nlohmann::json& request);
  [[nodiscard]] nlohmann::json predict(const nlohmann::json& request);
  // The request's assembly (scanned parts are registered with the twin: a search of u0 the
  // first time). @throws InvalidArgumentError naming `assembly` or `parts`; the twin's errors.
  [[nodiscard]] ResolvedAssembly resolve_assembly(const nlohmann::json& request);
  // The assembly of a stored proposal. @throws nlohmann::json::exception when malformed.
  [[nodiscard]] ResolvedAssembly recorded_assembly(const nlohmann::json& stored);
  // What replies show of a stored assembly: [upper, lower], or the cell's id.
  [[nodiscard]] static nlohmann::json echo(const nlohmann::json& stored);
  // u_t and the report, without touching the store.
  [[nodiscard]] nlohmann::json make_proposal(std::int64_t request_id, const AssemblyId& assembly,
                                             const nlohmann::json& stored);
  // δû_t and P_t as JSON.
  [[nodiscard]] nlohmann::json estimate_json() const;
  [[nodiscard]] nlohmann::json covariance_json() const;
  // Replays the records from next_request_ on; with `verify_snapshots`, compares the
  // controller with each stored snapshot it passes (returns how many).
  std::int64_t replay(bool verify_snapshots = false);
  // Restores the controller from the last snapshot, if any (registering the scanned assemblies
  // up to it with the twin first when `register_scanned`).
  void restore_last_snapshot(bool register_scanned);
  // The controller's state as a snapshot stores it.
  [[nodiscard]] nlohmann::json snapshot_json() const;
  // Stores a snapshot after the last observation when one is due (every snapshot_interval
  // observations) or `now` (checkpoint, shutdown), unless there is one already.
  void snapshot_if_due(bool now);
  // Rebuilds the controller from the settings, the last snapshot and the records after it
  // (after a failed step).
  void rebuild();
  // After an observe, for a controller that estimates: the state is one it can go on from
  // (max_estimate_widths); otherwise NonFiniteError naming the quality (the caller rebuilds).
  void require_sound_state(double quality) const;

  ServeOptions options_;
  std::unique_ptr<CaseTwin> twin_;  // heap: the controller holds its address; grows by scans
  AnyController controller_;
  HistoryStore store_;
  std::optional<Pending> pending_;
  std::int64_t next_request_ = 1;
  std::int64_t observed_ = 0;
  std::int64_t last_snapshot_ = 0;  // the request of the last stored snapshot (0: none)
  // The first snapshot rebuild() may restore: one this process restored or took (0: none yet).
  std::int64_t trusted_snapshot_ = 0;
  bool finished_ = false;
  VectorX control_;             // workspaces: d
  mutable VectorX estimate_;    // d
  mutable MatrixX covariance_;  // d × d
};

}  // namespace twincal
