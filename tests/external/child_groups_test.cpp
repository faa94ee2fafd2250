#include "twincal/external/child_groups.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/external/external_twin.hpp"

namespace twincal {
namespace {

// Whether process `pid` has ended: gone, or a zombie waiting for a parent that is gone too (a
// container's init may not reap it).
bool ended(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return true;
  const std::size_t close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'Z';
}

bool ends_within(pid_t pid, std::chrono::seconds wait) {
  const auto deadline = std::chrono::steady_clock::now() + wait;
  while (!ended(pid)) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

TEST(ChildGroups, RegistersAndForgetsGroups) {
  child_groups::add(424242);
  child_groups::add(434343);
  const auto registered = [](pid_t group) {
    for (const auto& slot : child_groups::registry) {
      if (slot.load() == group) return true;
    }
    return false;
  };
  EXPECT_TRUE(registered(424242));
  child_groups::remove(424242);
  EXPECT_FALSE(registered(424242));
  EXPECT_TRUE(registered(434343));
  child_groups::remove(434343);
  EXPECT_FALSE(registered(434343));
}

// `twincal run` ended by SIGTERM once left its twin, and what the twin had started, running:
// their process group is not the terminal's. With the handlers installed, the signal ends them
// with the process, which still ends by the signal.
TEST(ChildGroups, ATerminatingSignalEndsTheTwinAndWhatItStarted) {
  int pids[2];
  ASSERT_EQ(::pipe(pids), 0);
  const pid_t runner = ::fork();
  ASSERT_GE(runner, 0);
  if (runner == 0) {  // a stand-in for `twincal run`
    ::close(pids[0]);
    child_groups::end_child_groups_on_termination();
    ExternalTwinOptions options;
    options.command = {TWINCAL_TEST_DATA_DIR "/script_twin.py"};
    options.locator_names = {"A", "B"};
    const ExternalTwin twin(options);
    const nlohmann::json twin_pid = {{"q0", 0.25}, {"a", {0.1, -0.2}}, {"mode", "pid"}};
    const nlohmann::json spawn = {{"q0", 0.25}, {"a", {0.1, -0.2}}, {"mode", "spawn"}};
    const std::array<pid_t, 2> started = {
        static_cast<pid_t>(twin.quality(twin_pid, VectorX::Zero(2))),
        static_cast<pid_t>(twin.quality(spawn, VectorX::Zero(2)))};
    if (::write(pids[1], started.data(), sizeof started) != sizeof started) ::_exit(2);
    ::pause();
    ::_exit(0);
  }
  ::close(pids[1]);
  std::array<pid_t, 2> started{};
  ASSERT_EQ(::read(pids[0], started.data(), sizeof started), static_cast<ssize_t>(sizeof started));
  ::close(pids[0]);
  EXPECT_FALSE(ended(started[0]));  // the twin
  EXPECT_FALSE(ended(started[1]));  // the `sleep 60` it started
  ASSERT_EQ(::kill(runner, SIGTERM), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(runner, &status, 0), runner);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
  EXPECT_TRUE(ends_within(started[0], std::chrono::seconds(5)));
  EXPECT_TRUE(ends_within(started[1], std::chrono::seconds(5)));
}

}  // namespace
}  // namespace twincal
