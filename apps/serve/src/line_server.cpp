// serve_stream and serve_connections (line_server.hpp).
#include "twincal/serve/line_server.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <deque>
#include <filesystem>
#include <memory>
#include <string_view>
#include <type_traits>
#include <utility>

#include <fmt/format.h>
// GCC 12 at -O3 sees a potential null dereference in Asio's own scheduler code once it is
// inlined here (boost/asio/detail/impl/scheduler.ipp); the warning is about Boost, not this file.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnull-dereference"
#endif
#include <boost/asio/buffer.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address_v4.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#include <nlohmann/json.hpp>

#include "twincal/core/json_nesting.hpp"
#include "twincal/core/options.hpp"
#include "twincal/serve/line_splitter.hpp"

namespace twincal {
namespace {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using local = asio::local::stream_protocol;
using boost::system::error_code;

void write_all(int fd, std::string_view text) {
  while (!text.empty()) {
    const ssize_t written = ::write(fd, text.data(), text.size());
    if (written < 0) {
      if (errno == EINTR) continue;
      throw Error("output", fmt::format("output: cannot be written ({})", std::strerror(errno)));
    }
    text.remove_prefix(static_cast<std::size_t>(written));
  }
}

// Whether `given` equals `expected`, in a time that depends only on their lengths.
bool same_secret(std::string_view given, std::string_view expected) noexcept {
  unsigned difference = given.size() == expected.size() ? 0U : 1U;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const char g = i < given.size() ? given[i] : '\0';
    difference |= static_cast<unsigned>(static_cast<unsigned char>(g) ^
                                        static_cast<unsigned char>(expected[i]));
  }
  return difference == 0U;
}

// Who is on the other end, for the log of a refused token.
std::string peer_name(const tcp::socket& socket) {
  error_code ignored;
  const tcp::endpoint peer = socket.remote_endpoint(ignored);
  return fmt::format("{}:{}", peer.address().to_string(), peer.port());
}
std::string peer_name(const local::socket&) { return "a local process"; }

// One event loop for every connection: requests reach the one session in the order their lines
// arrive, and a connection that is silent, slow or never reads its replies holds only its own
// buffers (ListenOptions' limits). Protocol: TCP or a Unix-domain stream socket.
template <typename Protocol>
class LineServer {
 public:
  using Socket = typename Protocol::socket;
  using Acceptor = typename Protocol::acceptor;

  // Binds `endpoint` and listens (`after_bind` runs between the two); run() serves a session.
  template <typename AfterBind>
  LineServer(const ListenOptions& options, const typename Protocol::endpoint& endpoint,
             const std::string& where, AfterBind after_bind)
      : acceptor_(io_), options_(options) {
    error_code error;
    acceptor_.open(endpoint.protocol(), error);
    if (!error && std::is_same_v<Protocol, tcp>) {
      acceptor_.set_option(typename Acceptor::reuse_address(true), error);
    }
    if (!error) acceptor_.bind(endpoint, error);
    if (!error) after_bind(error);
    if (!error) acceptor_.listen(asio::socket_base::max_listen_connections, error);
    if (error) {
      throw Error("listen",
                  fmt::format("listen: cannot listen on {} ({})", where, error.message()));
    }
  }

  [[nodiscard]] const Acceptor& acceptor() const noexcept { return acceptor_; }

  // Until a shutdown request's reply is written; rethrows HistoryStoreError.
  void run(ServeSession& session) {
    session_ = &session;
    accept();
    io_.run();
  }

 private:
  class Connection;

  void accept() {
    acceptor_.async_accept([this](const error_code& error, Socket socket) {
      if (session_->finished()) return;
      if (!error) admit(std::move(socket));
      accept();
    });
  }

  void admit(Socket socket);

  asio::io_context io_;
  Acceptor acceptor_;
  ServeSession* session_ = nullptr;  // set by run()
  ListenOptions options_;
  int open_ = 0;
};

template <typename Protocol>
class LineServer<Protocol>::Connection : public std::enable_shared_from_this<Connection> {
 public:
  Connection(LineServer& server, Socket socket)
      : server_(server), socket_(std::move(socket)), timer_(server.io_) {
    ++server_.open_;
  }

  void start() {
    arm_timer();
    read();
  }

 private:
  void read() {
    socket_.async_read_some(asio::buffer(chunk_), [self = this->shared_from_this()](
                                                      const error_code& error, std::size_t n) {
      self->on_read(error, n);
    });
  }

  void on_read(const error_code& error, std::size_t bytes) {
    if (closed_) return;
    if (error) {
      // The client closed its side (or the connection broke): replies still queued go out.
      reading_ = false;
      if (out_.empty()) close();
      return;
    }
    arm_timer();
    ServeSession& session = *server_.session_;
    splitter_.feed(
        std::string_view(chunk_.data(), bytes),
        [&](std::string_view line) {
          if (authenticated_) {
            queue(session.handle(line));
          } else {
            authenticate(line);
          }
        },
        [&](std::size_t oversized) { queue(ServeSession::oversized_reply(oversized)); },
        [&] { return !closed_ && reading_ && !session.finished(); });
    if (!closed_ && reading_ && !session.finished()) read();
  }

  // The first line of a connection to a server with a token: {"op": "authenticate", "token"}.
  void authenticate(std::string_view line) {
    const std::string& token = *server_.options_.token;
    std::string given;
    if (json_nesting_depth(line) <= max_json_nesting) {
      const nlohmann::json request = nlohmann::json::parse(line, nullptr, false);
      if (request.is_object() && request.contains("op") && request["op"] == "authenticate" &&
          request.contains("token") && request["token"].is_string() && request.size() == 2) {
        given = request["token"].get<std::string>();
      }
    }
    if (!given.empty() && same_secret(given, token)) {
      authenticated_ = true;
      queue(nlohmann::json{{"ok", true}, {"op", "authenticate"}}.dump());
      return;
    }
    fmt::print(stderr, "twincal serve: refused a connection from {}: no valid token\n",
               peer_name(socket_));
    queue(nlohmann::json{{"ok", false},
                         {"op", "authenticate"},
                         {"error",
                          {{"field", "token"},
                           {"message",
                            "token: is missing or wrong; rule: a connection's first request is "
                            "{\"op\": \"authenticate\", \"token\": \"<the server's token>\"}"}}}}
              .dump());
    reading_ = false;  // the reply goes out, then the connection closes
  }

  // A client that lets more than max_reply_backlog bytes of replies pile up is not reading
  // them: its connection is closed, and no one else waits for it.
  void queue(std::string reply) {
    if (closed_) return;
    reply += '\n';
    backlog_ += reply.size();
    if (backlog_ > server_.options_.max_reply_backlog) {
      close();
      return;
    }
    out_.push_back(std::move(reply));
    if (out_.size() == 1) write();
  }

  void write() {
    asio::async_write(socket_, asio::buffer(out_.front()),
                      [self = this->shared_from_this()](const error_code& error, std::size_t) {
                        self->on_written(error);
                      });
  }

  void on_written(const error_code& error) {
    if (closed_) return;
    if (error) {
      close();
      return;
    }
    backlog_ -= out_.front().size();
    out_.pop_front();
    if (!out_.empty()) {
      write();
    } else if (server_.session_->finished()) {
      server_.io_.stop();  // the shutdown reply is out
    } else if (!reading_) {
      close();
    }
  }

  void arm_timer() {
    timer_.expires_after(server_.options_.idle_timeout);
    timer_.async_wait([weak = this->weak_from_this()](const error_code& error) {
      if (error) return;  // re-armed or cancelled
      if (const auto self = weak.lock()) self->close();
    });
  }

  void close() {
    if (closed_) return;
    closed_ = true;
    --server_.open_;
    error_code ignored;
    socket_.shutdown(Socket::shutdown_both, ignored);
    socket_.close(ignored);
    timer_.cancel();
  }

  LineServer& server_;
  Socket socket_;
  asio::steady_timer timer_;
  std::array<char, 1 << 16> chunk_{};
  LineSplitter splitter_;
  std::deque<std::string> out_;
  std::size_t backlog_ = 0;
  bool reading_ = true;
  bool closed_ = false;
  bool authenticated_ = !server_.options_.token.has_value();
};

template <typename Protocol>
void LineServer<Protocol>::admit(Socket socket) {
  if (open_ >= options_.max_connections) {
    const nlohmann::json refusal = {
        {"ok", false},
        {"op", nullptr},
        {"error",
         {{"field", "connection"},
          {"message", fmt::format("connection: the server has {} open; rule: at most {} "
                                  "(ListenOptions::max_connections)",
                                  open_, options_.max_connections)}}}};
    error_code ignored;
    asio::write(socket, asio::buffer(refusal.dump() + '\n'), ignored);
    socket.close(ignored);
    return;
  }
  std::make_shared<Connection>(*this, std::move(socket))->start();
}

}  // namespace

void serve_stream(ServeSession& session, int in_fd, int out_fd) {
  std::array<char, 1 << 16> chunk{};
  LineSplitter splitter;
  const auto reply = [&](const std::string& text) { write_all(out_fd, text + '\n'); };
  while (!session.finished()) {
    const ssize_t got = ::read(in_fd, chunk.data(), chunk.size());
    if (got < 0) {
      if (errno == EINTR) continue;
      throw Error("input", fmt::format("input: cannot be read ({})", std::strerror(errno)));
    }
    if (got == 0) break;  // end of input; an unterminated last line is not a request
    splitter.feed(
        std::string_view(chunk.data(), static_cast<std::size_t>(got)),
        [&](std::string_view line) { reply(session.handle(line)); },
        [&](std::size_t bytes) { reply(ServeSession::oversized_reply(bytes)); },
        [&] { return !session.finished(); });
  }
}

std::optional<std::string> ListenOptions::validate() const {
  error_code error;
  const asio::ip::address_v4 address = asio::ip::make_address_v4(host, error);
  const std::string socket_path = unix_socket.value_or(std::filesystem::path{}).string();
  return first_problem(
      // sockaddr_un's sun_path holds 108 bytes with its terminating NUL.
      {rule::check(!unix_socket || (!socket_path.empty() && socket_path.size() <= 107),
                   "unix_socket", fmt::format("\"{}\" ({} bytes)", socket_path, socket_path.size()),
                   "a path of 1 … 107 bytes"),
       rule::check(!unix_socket || (unix_socket_mode & ~0777U) == 0U, "unix_socket_mode",
                   fmt::format("{:o}", unix_socket_mode), "permission bits only (e.g. 600)"),
       rule::check(!error, "host", fmt::format("\"{}\"", host),
                   "an IPv4 address such as 127.0.0.1"),
       rule::check(port >= 0 && port <= 65535, "port", port, "0 … 65535"),
       rule::at_least("max_connections", max_connections, 1),
       rule::check(idle_timeout > std::chrono::milliseconds::zero(), "idle_timeout",
                   idle_timeout.count(), "more than 0 (ms)"),
       rule::check(!token || token->size() >= 16, "token",
                   fmt::format("{} characters", token.value_or("").size()), "at least 16"),
       rule::check(unix_socket.has_value() || error || address.is_loopback() || token.has_value(),
                   "host", host,
                   "listening beyond loopback (127.0.0.0/8) needs a token (--token-file): a cell "
                   "controller takes orders only from the cell"),
       rule::check(max_reply_backlog >= ServeSession::max_line_bytes, "max_reply_backlog",
                   fmt::format("{} bytes", max_reply_backlog), "at least {} (a reply's size)",
                   ServeSession::max_line_bytes)});
}

namespace {

// The socket file of a Unix-domain listener: a stale one (no server behind it) is replaced, a
// live one or any other file is refused; the file is removed when the server ends.
class UnixSocketFile {
 public:
  explicit UnixSocketFile(std::filesystem::path path) : path_(std::move(path)) {
    struct stat status {};
    if (::lstat(path_.c_str(), &status) != 0) return;  // free
    if (!S_ISSOCK(status.st_mode)) {
      throw Error("listen", fmt::format("listen: {} exists and is not a socket; rule: --listen "
                                        "unix:PATH creates the socket file",
                                        path_.string()));
    }
    asio::io_context io;
    local::socket probe(io);
    error_code error;
    probe.connect(local::endpoint(path_.string()), error);
    if (!error) {
      throw Error("listen",
                  fmt::format("listen: {} is in use by a running server", path_.string()));
    }
    std::filesystem::remove(path_);  // left by a server that was killed
  }
  UnixSocketFile(const UnixSocketFile&) = delete;
  UnixSocketFile& operator=(const UnixSocketFile&) = delete;
  ~UnixSocketFile() {
    if (bound_) {
      std::error_code ignored;
      std::filesystem::remove(path_, ignored);
    }
  }
  void bound() noexcept { bound_ = true; }

 private:
  std::filesystem::path path_;
  bool bound_ = false;
};

}  // namespace

void serve_connections(const ListenOptions& options,
                       const std::function<ServeSession&()>& open_session,
                       const std::function<void(int port)>& on_listening) {
  require_valid("listen", options);
  if (options.unix_socket) {
    const std::string path = options.unix_socket->string();
    UnixSocketFile file(*options.unix_socket);
    // Only the owner may connect: the mode is set after bind(), before listen() accepts anyone.
    LineServer<local> server(options, local::endpoint(path), path, [&](error_code& error) {
      file.bound();
      if (::chmod(path.c_str(), options.unix_socket_mode) != 0) {
        error = error_code(errno, boost::system::system_category());
      }
    });
    ServeSession& session = open_session();
    on_listening(0);
    server.run(session);
    return;
  }
  const tcp::endpoint endpoint(asio::ip::make_address_v4(options.host),
                               static_cast<unsigned short>(options.port));
  LineServer<tcp> server(options, endpoint, fmt::format("{}:{}", options.host, options.port),
                         [](error_code&) {});
  ServeSession& session = open_session();
  on_listening(server.acceptor().local_endpoint().port());
  server.run(session);
}

void serve_connections(ServeSession& session, const ListenOptions& options,
                       const std::function<void(int port)>& on_listening) {
  serve_connections(
      options, [&]() -> ServeSession& { return session; }, on_listening);
}

}  // namespace twincal
