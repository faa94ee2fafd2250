#pragma once
/// @file
/// The process groups of the external twins' children alive in this process. Each child runs in
/// a process group of its own (so that stopping it ends the programs it started too), which a
/// terminal's Ctrl-C does not reach, and a process ended by a signal runs no destructors: without
/// this registry, `twincal run` interrupted by SIGINT or SIGTERM left a busy twin running.
/// `end_child_groups_on_termination()` installs handlers that kill every registered group and
/// then end the process as the signal would have.

#include <signal.h>
#include <sys/types.h>

#include <array>
#include <atomic>
#include <cstddef>

namespace twincal::child_groups {

/// Room for this many children at once (a pool's workers); more are not registered.
inline constexpr std::size_t capacity = 1024;
inline std::array<std::atomic<pid_t>, capacity> registry{};

/// Registers process group `group` (its leader's pid).
inline void add(pid_t group) noexcept {
  for (std::atomic<pid_t>& slot : registry) {
    pid_t empty = 0;
    if (slot.compare_exchange_strong(empty, group)) return;
  }
}

/// Forgets process group `group`.
inline void remove(pid_t group) noexcept {
  for (std::atomic<pid_t>& slot : registry) {
    pid_t registered = group;
    if (slot.compare_exchange_strong(registered, 0)) return;
  }
}

/// SIGKILL to every registered group. Async-signal-safe (atomics and kill only).
inline void kill_all() noexcept {
  for (std::atomic<pid_t>& slot : registry) {
    if (const pid_t group = slot.load(); group > 0) ::kill(-group, SIGKILL);
  }
}

extern "C" inline void end_with_children(int signal) {
  kill_all();
  ::signal(signal, SIG_DFL);
  ::raise(signal);
}

/// On SIGINT, SIGTERM and SIGHUP: kill_all(), then the signal's default action (the process ends
/// with it, as it would have). Call once, early in main.
inline void end_child_groups_on_termination() noexcept {
  struct sigaction action {};
  action.sa_handler = end_with_children;
  sigemptyset(&action.sa_mask);
  for (const int signal : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(signal, &action, nullptr);
}

}  // namespace twincal::child_groups
