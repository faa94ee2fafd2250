#include "twincal/serve/line_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "serve_testing.hpp"
#include "twincal/core/error.hpp"

namespace twincal {
namespace {

using nlohmann::json;
using test_support::analytic_options;
using test_support::TemporaryDatabase;
using ::testing::HasSubstr;

// A blocking TCP client of the loopback server, with a deadline on every read.
class Client {
 public:
  explicit Client(int port) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    ::inet_pton(AF_INET, "127.0.0.1", &address.sin_addr);
    connected_ = ::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0;
  }
  // A client of a Unix-domain socket.
  explicit Client(const std::filesystem::path& socket) : fd_(::socket(AF_UNIX, SOCK_STREAM, 0)) {
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::snprintf(address.sun_path, sizeof address.sun_path, "%s", socket.c_str());
    connected_ = ::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0;
  }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;
  ~Client() { ::close(fd_); }

  [[nodiscard]] bool connected() const { return connected_; }
  // Whether all of `text` went out (a connection the server closed takes no more).
  bool send(const std::string& text) const {
    std::string_view rest = text;
    while (!rest.empty()) {
      const ssize_t sent = ::send(fd_, rest.data(), rest.size(), MSG_NOSIGNAL);
      if (sent <= 0) return false;
      rest.remove_prefix(static_cast<std::size_t>(sent));
    }
    return true;
  }
  // The next line, or nothing when the server closed the connection or `wait` passed.
  std::optional<std::string> line(std::chrono::milliseconds wait = std::chrono::seconds(5)) {
    const auto deadline = std::chrono::steady_clock::now() + wait;
    while (true) {
      if (const std::size_t newline = buffer_.find('\n'); newline != std::string::npos) {
        std::string line = buffer_.substr(0, newline);
        buffer_.erase(0, newline + 1);
        return line;
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      pollfd ready{fd_, POLLIN, 0};
      if (left.count() <= 0 || ::poll(&ready, 1, static_cast<int>(left.count())) <= 0) {
        return std::nullopt;
      }
      char chunk[4096];
      const ssize_t got = ::recv(fd_, chunk, sizeof chunk, 0);
      if (got <= 0) return std::nullopt;
      buffer_.append(chunk, static_cast<std::size_t>(got));
    }
  }
  // Whether the server closed the connection within `wait` (reading and dropping what came).
  bool closed_by_server(std::chrono::milliseconds wait) {
    const auto deadline = std::chrono::steady_clock::now() + wait;
    while (std::chrono::steady_clock::now() < deadline) {
      pollfd ready{fd_, POLLIN, 0};
      if (::poll(&ready, 1, 50) <= 0) continue;
      char chunk[65536];
      if (::recv(fd_, chunk, sizeof chunk, 0) <= 0) return true;
    }
    return false;
  }

 private:
  int fd_;
  bool connected_ = false;
  std::string buffer_;
};

// serve_connections on a thread of its own; the port once it listens.
class Server {
 public:
  Server(ServeSession& session, ListenOptions options) {
    std::promise<int> listening;
    std::future<int> port = listening.get_future();
    thread_ = std::thread([&session, options, &listening, this] {
      try {
        serve_connections(session, options, [&](int p) { listening.set_value(p); });
      } catch (...) {
        failure_ = std::current_exception();
      }
    });
    port_ = port.get();
  }
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;
  ~Server() {
    if (thread_.joinable()) {
      Client stopper(port_);
      stopper.send("{\"op\": \"shutdown\"}\n");
      static_cast<void>(stopper.line());
      thread_.join();
    }
  }
  [[nodiscard]] int port() const { return port_; }
  void join() {
    thread_.join();
    if (failure_) std::rethrow_exception(failure_);
  }

 private:
  std::thread thread_;
  int port_ = 0;
  std::exception_ptr failure_;
};

// Every test serves a fresh session of the analytic twin with the active controller.
class ServeTcp : public ::testing::Test {
 protected:
  TemporaryDatabase database_;
  ServeSession session_ = ServeSession::start(analytic_options("active"), database_.get());
};

bool ok(const std::optional<std::string>& line) {
  return line && json::parse(*line).value("ok", false);
}

// The first defect of the hand-written server: a client that connects and says nothing kept
// every other client waiting for as long as it stayed.
TEST_F(ServeTcp, AnIdleClientDoesNotKeepAnotherWaiting) {
  Server server(session_, ListenOptions{});
  const Client idle(server.port());
  ASSERT_TRUE(idle.connected());
  Client cell(server.port());
  cell.send("{\"op\": \"propose\", \"assembly\": 3}\n");
  const std::optional<std::string> proposal = cell.line(std::chrono::seconds(5));
  ASSERT_TRUE(ok(proposal)) << proposal.value_or("no reply");
  cell.send("{\"op\": \"shutdown\"}\n");
  EXPECT_TRUE(ok(cell.line()));
  server.join();
}

// A client that sends requests and never reads the replies fills its own backlog and is
// dropped; the cell is served throughout.
TEST_F(ServeTcp, AClientThatNeverReadsIsDroppedAlone) {
  ListenOptions options;
  options.max_reply_backlog = ServeSession::max_line_bytes;
  Server server(session_, options);
  Client deaf(server.port());
  std::string requests;
  for (int i = 0; i < 60000; ++i) requests += "{\"op\": \"state\"}\n";
  static_cast<void>(deaf.send(requests));  // cut off part way: the server closes it
  Client cell(server.port());
  cell.send("{\"op\": \"state\"}\n");
  EXPECT_TRUE(ok(cell.line(std::chrono::seconds(10))));
  EXPECT_TRUE(deaf.closed_by_server(std::chrono::seconds(10)));
  cell.send("{\"op\": \"state\"}\n");
  EXPECT_TRUE(ok(cell.line()));
}

TEST_F(ServeTcp, ClosesAConnectionThatStaysSilentPastTheTimeout) {
  ListenOptions options;
  options.idle_timeout = std::chrono::milliseconds(200);
  Server server(session_, options);
  Client silent(server.port());
  EXPECT_TRUE(silent.closed_by_server(std::chrono::seconds(5)));
  Client talking(server.port());
  talking.send("{\"op\": \"state\"}\n");
  EXPECT_TRUE(ok(talking.line()));
}

TEST_F(ServeTcp, RefusesAConnectionBeyondTheCapWithAReply) {
  ListenOptions options;
  options.max_connections = 2;
  Server server(session_, options);
  Client first(server.port());
  Client second(server.port());
  second.send("{\"op\": \"state\"}\n");
  ASSERT_TRUE(ok(second.line()));  // both are admitted by now
  Client third(server.port());
  const std::optional<std::string> refusal = third.line();
  ASSERT_TRUE(refusal.has_value());
  const json reply = json::parse(*refusal);
  EXPECT_FALSE(reply["ok"].get<bool>());
  EXPECT_EQ(reply["error"]["field"], "connection");
  EXPECT_THAT(reply["error"]["message"].get<std::string>(),
              HasSubstr("connection: the server has 2 open; rule: at most 2"));
  EXPECT_TRUE(third.closed_by_server(std::chrono::seconds(5)));
  first.send("{\"op\": \"state\"}\n");
  EXPECT_TRUE(ok(first.line()));
  first.send("{\"op\": \"shutdown\"}\n");  // the destructor's own client would be refused
  EXPECT_TRUE(ok(first.line()));
  server.join();
}

// Only the cell drives it: with a token, a connection's first request must authenticate it;
// anything else gets one error reply and the connection is closed, and no request reaches the
// controller.
TEST_F(ServeTcp, TakesRequestsOnlyAfterTheToken) {
  ListenOptions options;
  options.token = "correct horse battery staple";
  Server server(session_, options);
  const std::vector<std::string> refused = {
      R"({"op": "propose", "assembly": 3})",
      R"({"op": "authenticate", "token": "correct horse battery stapl"})",
      R"({"op": "authenticate", "token": "correct horse battery staple!"})",
      R"({"op": "authenticate"})",
      R"({"op": "authenticate", "token": 12})",
      "not json"};
  for (const std::string& first : refused) {
    Client intruder(server.port());
    intruder.send(first + "\n{\"op\": \"shutdown\"}\n");
    const std::optional<std::string> reply = intruder.line();
    ASSERT_TRUE(reply.has_value()) << first;
    const json error = json::parse(*reply);
    EXPECT_FALSE(error["ok"].get<bool>()) << first;
    EXPECT_EQ(error["error"]["field"], "token") << first;
    EXPECT_TRUE(intruder.closed_by_server(std::chrono::seconds(5))) << first;
  }
  EXPECT_EQ(session_.observed(), 0);
  EXPECT_TRUE(session_.state()["pending"].is_null());
  Client cell(server.port());
  cell.send(R"({"op": "authenticate", "token": "correct horse battery staple"})"
            "\n");
  EXPECT_TRUE(ok(cell.line()));
  cell.send("{\"op\": \"propose\", \"assembly\": 3}\n");
  EXPECT_TRUE(ok(cell.line()));
  cell.send("{\"op\": \"shutdown\"}\n");
  EXPECT_TRUE(ok(cell.line()));
  server.join();
}

TEST_F(ServeTcp, ServesAUnixSocketOnlyItsOwnerMayOpenAndRemovesItAfterwards) {
  const std::filesystem::path path = database_.get().string() + ".sock";
  // A stale socket file, as a killed server leaves it, is replaced.
  {
    const int stale = ::socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::snprintf(address.sun_path, sizeof address.sun_path, "%s", path.c_str());
    ASSERT_EQ(::bind(stale, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0);
    ::close(stale);
  }
  ListenOptions options;
  options.unix_socket = path;
  std::promise<void> listening;
  std::exception_ptr failure;
  std::thread server([&] {
    try {
      serve_connections(session_, options, [&](int) { listening.set_value(); });
    } catch (...) {
      failure = std::current_exception();
      listening.set_value();
    }
  });
  listening.get_future().wait();
  ASSERT_FALSE(failure);
  struct stat status {};
  ASSERT_EQ(::stat(path.c_str(), &status), 0);
  EXPECT_TRUE(S_ISSOCK(status.st_mode));
  EXPECT_EQ(status.st_mode & 0777, 0600U);
  // A second server on the same path is refused while the first runs.
  TemporaryDatabase other_db;
  ServeSession other = ServeSession::start(analytic_options("active"), other_db.get());
  EXPECT_THAT([&] { serve_connections(other, options, [](int) {}); },
              ::testing::ThrowsMessage<Error>(HasSubstr("is in use by a running server")));
  Client cell(path);
  ASSERT_TRUE(cell.connected());
  cell.send("{\"op\": \"propose\", \"assembly\": 3}\n");
  EXPECT_TRUE(ok(cell.line()));
  cell.send("{\"op\": \"shutdown\"}\n");
  EXPECT_TRUE(ok(cell.line()));
  server.join();
  EXPECT_FALSE(std::filesystem::exists(path));
  // Any other file in its place is refused, and left alone.
  std::ofstream(path) << "not a socket";
  EXPECT_THAT([&] { serve_connections(other, options, [](int) {}); },
              ::testing::ThrowsMessage<Error>(HasSubstr("exists and is not a socket")));
  EXPECT_TRUE(std::filesystem::exists(path));
  std::filesystem::remove(path);
}

TEST(ListenOptions, NameTheRuleTheyBreak) {
  EXPECT_EQ(ListenOptions{.host = "localhost"}.validate(),
            "host: value is \"localhost\"; rule: an IPv4 address such as 127.0.0.1");
  EXPECT_EQ(ListenOptions{.max_connections = 0}.validate(),
            "max_connections: value is 0; rule: must be >= 1");
  EXPECT_EQ(ListenOptions{.host = "0.0.0.0"}.validate(),
            "host: value is 0.0.0.0; rule: listening beyond loopback (127.0.0.0/8) needs a token "
            "(--token-file): a cell controller takes orders only from the cell");
  ListenOptions anywhere;
  anywhere.host = "0.0.0.0";
  anywhere.token = "short";
  EXPECT_EQ(anywhere.validate(), "token: value is 5 characters; rule: at least 16");
  anywhere.token = "a secret of 16 c";
  EXPECT_EQ(anywhere.validate(), std::nullopt);
  ListenOptions small;
  small.max_reply_backlog = 10;
  EXPECT_EQ(small.validate(),
            "max_reply_backlog: value is 10 bytes; rule: at least 1048576 (a reply's "
            "size)");
}

}  // namespace
}  // namespace twincal
