#pragma once
/// @file
/// `ExternalTwin`: a twin implemented by any executable that speaks JSON lines on stdin/stdout,
/// so a real twin (an FEM program behind a wrapper script) plugs in without recompiling.
///
/// Protocol (one JSON object per line, UTF-8, '\n'-terminated, in both directions):
///   request  {"id": n, "assembly": <any JSON value>, "controls": [[u_1, …, u_d], …]}  (k ≥ 1)
///   reply    {"qualities": [q_1, …, q_k]}    numbers, in request order; null for a quality the
///                                           twin could not compute (reported as non-finite)
///        or  {"error": "<message>"}          the twin refuses this request
/// A twin that also answers its m key points' deviations r(x, u), Q = ‖r‖ / √m (`key_points`
/// = m; models' TwinWithDeviations), is asked for them with "deviations": true in the request:
///   reply    {"deviations": [[r_1, …, r_m], …]}  one array per control, null for a control it
///                                           could not evaluate; "qualities" may come too, and
///                                           must then equal each array's RMS
/// A reply may echo "id" (recommended): a reply with another id is rejected, which catches a
/// child that answers out of step. Exactly one reply line per request.
/// The child is started once (argv `options.command`, its stdin and stdout connected to one
/// socket, stderr inherited) and kept for every request. Every request has a deadline
/// (`timeout`, plus `startup_grace` for the first request after a start). Failures:
///   - the child cannot be started                         → start_failed
///   - it exits or closes its stdout during a request      → crashed      (restarted on next use)
///   - no complete reply line before the deadline          → timeout      (killed, restarted)
///   - a reply that is not the JSON above                   → malformed_reply (killed, restarted)
///   - a reply with the wrong number of qualities (or of    → wrong_count  (kept: the line
///     deviations: arrays, or entries of one)                             framing is intact)
///   - an {"error": …} reply                                → twin_error   (kept)
///   - a quality below 0 or above max_quality (1e6 mm), a   → implausible_quality (kept)
///     deviation beyond ±max_quality, or qualities that are
///     not their deviations' RMS
/// each as an ExternalTwinError carrying the assembly and the controls of the request. The child
/// runs in its own process group, so killing it also kills programs it started. Requests are
/// serialized by a mutex: the twin may be shared by threads, one request is in flight at a time.

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/external/child_groups.hpp"
#include "twincal/external/external_twin_failure.hpp"
#include "twincal/external/twin_reply.hpp"
#include "twincal/models/twin.hpp"

extern char** environ;  // NOLINT: POSIX, passed to the child unchanged

namespace twincal {

struct ExternalTwinOptions {
  std::vector<std::string> command;           ///< argv; command[0] is looked up in PATH if bare
  std::vector<std::string> locator_names;     ///< d names (d = control dimension)
  VectorX lower_bounds;                       ///< d entries; empty means −∞
  VectorX upper_bounds;                       ///< d entries; empty means +∞
  std::chrono::milliseconds timeout{10'000};  ///< longest wait for one reply
  std::chrono::milliseconds startup_grace{10'000};  ///< extra wait for a freshly started child
  std::chrono::milliseconds shutdown_grace{200};    ///< wait for a clean exit before SIGKILL
  /// The longest reply line; a child that writes more without a newline (a flood) is a
  /// malformed reply, killed and restarted, and twincal's memory stays bounded.
  std::size_t max_reply_bytes = std::size_t{64} << 20;
  /// The largest quality a reply may hold, in mm: a quality is an RMS deviation, so one below 0
  /// or above this is a twin's bug (an unconverged solve printed as 1e300), refused as
  /// implausible_quality instead of being fed to a filter. null stays the way to say "could not
  /// compute this control".
  double max_quality = 1e6;
  /// m, the key points whose deviations the twin answers when a request asks for them
  /// ("deviations": true); 0 for a twin that answers qualities only.
  Index key_points = 0;

  [[nodiscard]] std::optional<std::string> validate() const {
    const Index d = std::ssize(locator_names);
    return first_problem(
        {rule::check(!command.empty() && !command.front().empty(), "command", "empty",
                     "must name an executable"),
         rule::check(d >= 1, "locator_names", "empty", "must name >= 1 locator"),
         rule::check(lower_bounds.size() == 0 || lower_bounds.size() == d, "lower_bounds",
                     fmt::join(lower_bounds, ", "), "must be empty or hold {} entries", d),
         rule::check(upper_bounds.size() == 0 || upper_bounds.size() == d, "upper_bounds",
                     fmt::join(upper_bounds, ", "), "must be empty or hold {} entries", d),
         rule::check(timeout.count() > 0, "timeout", timeout.count(), "must be > 0 (ms)"),
         rule::at_least("max_reply_bytes", max_reply_bytes, decltype(max_reply_bytes){1024}),
         rule::positive_finite("max_quality", max_quality),
         rule::at_least("key_points", key_points, Index{0}),
         rule::check_fields(startup_grace.count() >= 0 && shutdown_grace.count() >= 0,
                            "startup_grace and shutdown_grace",
                            std::array{startup_grace.count(), shutdown_grace.count()},
                            "must be >= 0 (ms)")});
  }
};

/// Refuses a deviations request to a twin of `key_points` = 0 (it answers qualities only), naming
/// the setting that would allow it; every ExternalTwinBackend checks this before sending.
/// @throws InvalidArgumentError.
inline void require_key_points(Index key_points) {
  if (key_points == 0) {
    throw InvalidArgumentError(
        "deviations",
        "deviations: the twin answers qualities only; rule: set key_points (m, the "
        "length of each control's deviations) to ask a twin for them");
  }
}

class ExternalTwinError : public TwinError {
 public:
  ExternalTwinError(ExternalTwinFailure failure, std::string assembly, MatrixX controls,
                    const std::string& detail)
      : TwinError("twin", fmt::format("twin: external twin {}: {} (request: assembly {}, {} "
                                      "control(s))",
                                      to_string(failure), detail, assembly, controls.cols())),
        failure_(failure),
        assembly_(std::move(assembly)),
        controls_(std::move(controls)),
        detail_(detail) {}

  [[nodiscard]] ExternalTwinFailure failure() const noexcept { return failure_; }
  /// What happened, without the message's framing (for errors that wrap this one).
  [[nodiscard]] const std::string& detail() const noexcept { return detail_; }
  /// The request's assembly, as JSON text.
  [[nodiscard]] const std::string& assembly() const noexcept { return assembly_; }
  /// The request's d × k controls.
  [[nodiscard]] const MatrixX& controls() const noexcept { return controls_; }

 private:
  ExternalTwinFailure failure_;
  std::string assembly_;
  MatrixX controls_;
  std::string detail_;
};

class ExternalTwin {
 public:
  using Assembly = nlohmann::json;
  using Clock = std::chrono::steady_clock;

  /// Starts the child.
  /// @throws InvalidArgumentError for invalid options; ExternalTwinError(start_failed).
  explicit ExternalTwin(ExternalTwinOptions options) : options_(std::move(options)) {
    require_valid("options", options_);
    const auto d = static_cast<Index>(options_.locator_names.size());
    if (options_.lower_bounds.size() == 0) {
      options_.lower_bounds = VectorX::Constant(d, -std::numeric_limits<double>::infinity());
    }
    if (options_.upper_bounds.size() == 0) {
      options_.upper_bounds = VectorX::Constant(d, std::numeric_limits<double>::infinity());
    }
    const std::lock_guard lock(mutex_);
    start(Assembly(nullptr), MatrixX(d, 0));
  }

  ExternalTwin(const ExternalTwin&) = delete;
  ExternalTwin& operator=(const ExternalTwin&) = delete;

  /// Closes the child's input, waits `shutdown_grace` for it to exit, then kills it.
  ~ExternalTwin() {
    const std::lock_guard lock(mutex_);
    stop(/*graceful=*/true);
  }

  [[nodiscard]] Index control_dimension() const noexcept {
    return static_cast<Index>(options_.locator_names.size());
  }
  [[nodiscard]] const std::vector<std::string>& locator_names() const noexcept {
    return options_.locator_names;
  }
  [[nodiscard]] const VectorX& lower_bounds() const noexcept { return options_.lower_bounds; }
  [[nodiscard]] const VectorX& upper_bounds() const noexcept { return options_.upper_bounds; }
  [[nodiscard]] const ExternalTwinOptions& options() const noexcept { return options_; }

  /// How many times the child was started (1 after construction; +1 per restart).
  [[nodiscard]] int starts() const {
    const std::lock_guard lock(mutex_);
    return starts_;
  }
  /// The running child's process id, if one is running.
  [[nodiscard]] std::optional<pid_t> process_id() const {
    const std::lock_guard lock(mutex_);
    return running() ? std::optional<pid_t>(pid_) : std::nullopt;
  }

  /// Kills the child, if one is running; the next request starts a new one (a pool restarts a
  /// worker that answered with the wrong count this way, ExternalTwinPool).
  void restart() const {
    const std::lock_guard lock(mutex_);
    stop(/*graceful=*/false);
  }

  /// m, the key points of deviations_batch (0: the twin answers qualities only).
  [[nodiscard]] Index key_point_count() const noexcept { return options_.key_points; }

  /// One request with every column of `controls`; a null quality comes back as NaN.
  /// @throws DimensionMismatchError for bad shapes; ExternalTwinError on a failure.
  void quality_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    require_control_batch(controls, out, control_dimension());
    require_finite("controls", controls);  // JSON has no NaN or ∞
    if (controls.cols() == 0) return;
    exchange(assembly, controls, /*deviations=*/false,
             [&](const std::string& reply, std::uint64_t id) {
               return read_twin_reply(reply, id, options_.max_quality, out);
             });
  }

  /// One request with every column of `controls` that asks for the key points' deviations:
  /// out.col(j) = r(x, controls.col(j)) (m × k), a NaN column for a control the twin could not
  /// evaluate (TwinWithDeviations).
  /// @throws InvalidArgumentError when key_points is 0; DimensionMismatchError for bad shapes;
  ///         ExternalTwinError on a failure.
  void deviations_batch(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const {
    require_key_points(key_point_count());
    require_deviations_batch(controls, out, control_dimension(), key_point_count());
    require_finite("controls", controls);
    if (controls.cols() == 0) return;
    exchange(assembly, controls, /*deviations=*/true,
             [&](const std::string& reply, std::uint64_t id) {
               return read_twin_deviations_reply(reply, id, options_.max_quality, out);
             });
  }

  /// Q(x, u): one request with one control.
  [[nodiscard]] double quality(const Assembly& assembly,
                               const Eigen::Ref<const VectorX>& control) const {
    return quality_of_one(*this, assembly, control);
  }

 private:
  [[nodiscard]] bool running() const noexcept { return pid_ > 0; }

  // Must hold mutex_. Starts the child with stdin and stdout on one end of a socket pair.
  void start(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls) const {
    int sockets[2] = {-1, -1};
    if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sockets) != 0) {
      throw ExternalTwinError(ExternalTwinFailure::start_failed, assembly.dump(), controls,
                              fmt::format("socketpair failed: {}", std::strerror(errno)));
    }
    std::vector<char*> argv;
    for (const std::string& arg : options_.command) argv.push_back(const_cast<char*>(arg.c_str()));
    argv.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawnattr_t attributes;
    posix_spawn_file_actions_init(&actions);
    posix_spawnattr_init(&attributes);
    // dup2 clears close-on-exec on the targets: the child keeps fds 0 and 1, nothing else.
    posix_spawn_file_actions_adddup2(&actions, sockets[1], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions, sockets[1], STDOUT_FILENO);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGPIPE);
    sigset_t empty;
    sigemptyset(&empty);
    posix_spawnattr_setsigdefault(&attributes, &defaults);
    posix_spawnattr_setsigmask(&attributes, &empty);
    posix_spawnattr_setpgroup(&attributes, 0);
    posix_spawnattr_setflags(
        &attributes, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
    pid_t pid = -1;
    const int status =
        ::posix_spawnp(&pid, argv.front(), &actions, &attributes, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attributes);
    ::close(sockets[1]);
    if (status != 0) {
      ::close(sockets[0]);
      throw ExternalTwinError(
          ExternalTwinFailure::start_failed, assembly.dump(), controls,
          fmt::format("\"{}\": {}", options_.command.front(), std::strerror(status)));
    }
    ::fcntl(sockets[0], F_SETFL, ::fcntl(sockets[0], F_GETFL) | O_NONBLOCK);
    pid_ = pid;
    child_groups::add(pid);  // ended with this process if a signal ends it
    socket_ = sockets[0];
    buffer_.clear();
    answered_ = false;
    ++starts_;
  }

  // Must hold mutex_. Ends the child: gracefully (close its input, wait shutdown_grace) or at
  // once; either way it is reaped. Returns how it ended ("exited with status 3").
  std::string stop(bool graceful) const noexcept {
    if (!running()) return "not running";
    // At once means killed before its input closes: else a child blocked on a read may see the
    // end of input and exit cleanly first, and the report would depend on that race.
    if (!graceful) ::kill(-pid_, SIGKILL);
    ::close(socket_);
    socket_ = -1;
    int status = 0;
    pid_t reaped = 0;
    if (graceful) {
      const Clock::time_point until = Clock::now() + options_.shutdown_grace;
      while ((reaped = ::waitpid(pid_, &status, WNOHANG)) == 0 && Clock::now() < until) {
        std::this_thread::sleep_for(std::chrono::milliseconds{1});
      }
    }
    // The whole process group: the child if it is still running, and programs it started
    // (ESRCH where none are left).
    ::kill(-pid_, SIGKILL);
    if (reaped == 0) {
      while ((reaped = ::waitpid(pid_, &status, 0)) < 0 && errno == EINTR) {
      }
    }
    child_groups::remove(pid_);
    pid_ = -1;
    buffer_.clear();
    if (reaped < 0) return "could not be reaped";
    if (WIFEXITED(status)) return fmt::format("exited with status {}", WEXITSTATUS(status));
    if (WIFSIGNALED(status)) return fmt::format("was killed by signal {}", WTERMSIG(status));
    return "ended";
  }

  // Waits for `events` on the socket until `deadline`; false on timeout.
  [[nodiscard]] bool wait_for(short events, Clock::time_point deadline) const {
    while (true) {
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
      if (left.count() <= 0) return false;
      pollfd descriptor{socket_, events, 0};
      const int ready = ::poll(&descriptor, 1, static_cast<int>(left.count()));
      if (ready > 0) return true;
      if (ready < 0 && errno != EINTR) return true;  // let the read or write report the error
    }
  }

  template <typename Fail>
  void send_all(std::string_view data, Clock::time_point deadline, const Fail& fail) const {
    while (!data.empty()) {
      const ssize_t sent = ::send(socket_, data.data(), data.size(), MSG_NOSIGNAL);
      if (sent > 0) {
        data.remove_prefix(static_cast<std::size_t>(sent));
        continue;
      }
      if (sent < 0 && errno == EINTR) continue;
      if (sent < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        if (wait_for(POLLOUT, deadline)) continue;
        const std::string ended = stop(/*graceful=*/false);
        throw fail(
            ExternalTwinFailure::timeout,
            fmt::format("the request was not read within the deadline; the child {}", ended));
      }
      const std::string reason = std::strerror(errno);
      const std::string ended = stop(/*graceful=*/true);
      throw fail(ExternalTwinFailure::crashed,
                 fmt::format("writing the request failed ({}); the child {}", reason, ended));
    }
  }

  template <typename Fail>
  std::string receive_line(Clock::time_point deadline, const Fail& fail) const {
    char chunk[4096];
    while (true) {
      if (const auto newline = buffer_.find('\n'); newline != std::string::npos) {
        std::string line = buffer_.substr(0, newline);
        buffer_.erase(0, newline + 1);
        return line;
      }
      if (buffer_.size() > options_.max_reply_bytes) {
        const std::string shown = quoted_output(buffer_);
        const std::string ended = stop(/*graceful=*/false);
        throw fail(ExternalTwinFailure::malformed_reply,
                   fmt::format("the reply exceeds {} bytes without a newline (max_reply_bytes): "
                               "{}; the child {} and will be restarted",
                               options_.max_reply_bytes, shown, ended));
      }
      const ssize_t received = ::recv(socket_, chunk, sizeof chunk, 0);
      if (received > 0) {
        buffer_.append(chunk, static_cast<std::size_t>(received));
        continue;
      }
      if (received < 0 && errno == EINTR) continue;
      if (received < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        if (wait_for(POLLIN, deadline)) continue;
        const auto waited = options_.timeout.count();
        const std::string ended = stop(/*graceful=*/false);
        throw fail(ExternalTwinFailure::timeout,
                   fmt::format("no reply within {} ms; the child {}", waited, ended));
      }
      const std::string reason =
          received == 0 ? std::string("end of output") : std::string(std::strerror(errno));
      const std::string partial = buffer_;
      const std::string ended = stop(/*graceful=*/true);
      throw fail(
          ExternalTwinFailure::crashed,
          fmt::format("{} before a complete reply{}; the child {}", reason,
                      partial.empty() ? "" : fmt::format(" (got {})", quoted_output(partial)),
                      ended));
    }
  }

  // Moves output that is already waiting into buffer_ without blocking.
  void drain() const {
    char chunk[4096];
    ssize_t received = 0;
    while (buffer_.size() <= options_.max_reply_bytes &&
           (received = ::recv(socket_, chunk, sizeof chunk, MSG_DONTWAIT)) > 0) {
      buffer_.append(chunk, static_cast<std::size_t>(received));
    }
  }

  // One request and its reply, read by `read` (read_twin_reply or read_twin_deviations_reply);
  // a reply that is not the protocol's JSON also stops the child (the stream cannot be
  // trusted), which is restarted on next use.
  template <typename Read>
  void exchange(const Assembly& assembly, const Eigen::Ref<const MatrixX>& controls,
                bool deviations, const Read& read) const {
    const std::lock_guard lock(mutex_);
    const std::uint64_t id = ++requests_;
    nlohmann::json request = {
        {"id", id}, {"assembly", assembly}, {"controls", nlohmann::json::array()}};
    for (Index j = 0; j < controls.cols(); ++j) {
      nlohmann::json control = nlohmann::json::array();
      for (Index i = 0; i < controls.rows(); ++i) control.push_back(controls(i, j));
      request["controls"].push_back(std::move(control));
    }
    if (deviations) request["deviations"] = true;
    const std::string line = request.dump() + '\n';

    const auto fail = [&](ExternalTwinFailure failure, const std::string& detail) {
      return ExternalTwinError(failure, assembly.dump(), controls, detail);
    };
    if (running()) drain();
    if (running() && !buffer_.empty()) {
      // A correct child never writes without a request: the stream cannot be trusted.
      const std::string unsolicited = buffer_;
      const std::string ended = stop(/*graceful=*/false);
      throw fail(ExternalTwinFailure::malformed_reply,
                 fmt::format("unrequested output {} before the request; the child {} and "
                             "will be restarted",
                             quoted_output(unsolicited), ended));
    }
    if (!running()) start(assembly, controls);
    const Clock::time_point deadline =
        Clock::now() + options_.timeout +
        (answered_ ? std::chrono::milliseconds{0} : options_.startup_grace);
    send_all(line, deadline, fail);
    const std::string reply = receive_line(deadline, fail);
    answered_ = true;
    std::optional<TwinReplyFault> fault = read(reply, id);
    if (!fault) return;
    if (fault->failure == ExternalTwinFailure::malformed_reply) {
      const std::string ended = stop(/*graceful=*/false);
      fault->detail += fmt::format("; the child {} and will be restarted", ended);
    }
    throw fail(fault->failure, fault->detail);
  }

  ExternalTwinOptions options_;
  mutable std::mutex mutex_;
  mutable pid_t pid_ = -1;
  mutable int socket_ = -1;
  mutable std::string buffer_;     // bytes received after the last complete line
  mutable bool answered_ = false;  // the running child has answered at least once
  mutable int starts_ = 0;
  mutable std::uint64_t requests_ = 0;
};

static_assert(TwinWithDeviations<ExternalTwin>);

}  // namespace twincal
