// serve_stream and serve_tcp (line_server.hpp).
#include "twincal/serve/line_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <string_view>

#include <fmt/format.h>

#include "twincal/core/options.hpp"

namespace twincal {
namespace {

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

// A socket or descriptor closed on scope exit.
class Descriptor {
 public:
  explicit Descriptor(int fd) noexcept : fd_(fd) {}
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  [[nodiscard]] int get() const noexcept { return fd_; }

 private:
  int fd_;
};

}  // namespace

void serve_stream(ServeSession& session, int in_fd, int out_fd) {
  std::array<char, 1 << 16> chunk{};
  std::string line;
  std::size_t skipped = 0;  // > 0 while skipping an oversized line: its bytes so far
  const auto reply = [&](const std::string& text) { write_all(out_fd, text + '\n'); };
  while (!session.finished()) {
    const ssize_t got = ::read(in_fd, chunk.data(), chunk.size());
    if (got < 0) {
      if (errno == EINTR) continue;
      throw Error("input", fmt::format("input: cannot be read ({})", std::strerror(errno)));
    }
    if (got == 0) break;  // end of input; an unterminated last line is not a request
    std::string_view data(chunk.data(), static_cast<std::size_t>(got));
    while (!data.empty() && !session.finished()) {
      const std::size_t newline = data.find('\n');
      const std::string_view piece = data.substr(0, newline);
      if (skipped > 0 || line.size() + piece.size() > ServeSession::max_line_bytes) {
        skipped += (skipped == 0 ? line.size() : 0) + piece.size();
        line.clear();
      } else {
        line.append(piece);
      }
      if (newline == std::string_view::npos) break;
      data.remove_prefix(newline + 1);
      if (skipped > 0) {
        reply(ServeSession::oversized_reply(skipped));
        skipped = 0;
        continue;
      }
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (!line.empty()) reply(session.handle(line));
      line.clear();
    }
  }
}

std::optional<std::string> ListenOptions::validate() const {
  in_addr address{};
  if (::inet_pton(AF_INET, host.c_str(), &address) != 1) {
    return fmt::format("host: is \"{}\"; rule: an IPv4 address such as 127.0.0.1", host);
  }
  if (port < 0 || port > 65535) return fmt::format("port: is {}; rule: 0 … 65535", port);
  return std::nullopt;
}

void serve_tcp(ServeSession& session, const ListenOptions& options,
               const std::function<void(int port)>& on_listening) {
  require_valid("listen", options);
  const Descriptor server(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (server.get() < 0) {
    throw Error("listen", fmt::format("listen: no socket ({})", std::strerror(errno)));
  }
  const int yes = 1;
  ::setsockopt(server.get(), SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(options.port));
  ::inet_pton(AF_INET, options.host.c_str(), &address.sin_addr);
  if (::bind(server.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0 ||
      ::listen(server.get(), 16) != 0) {
    throw Error("listen", fmt::format("listen: cannot listen on {}:{} ({})", options.host,
                                      options.port, std::strerror(errno)));
  }
  socklen_t length = sizeof address;
  ::getsockname(server.get(), reinterpret_cast<sockaddr*>(&address), &length);
  on_listening(ntohs(address.sin_port));
  while (!session.finished()) {
    const Descriptor client(::accept4(server.get(), nullptr, nullptr, SOCK_CLOEXEC));
    if (client.get() < 0) {
      if (errno == EINTR || errno == ECONNABORTED) continue;
      throw Error("listen", fmt::format("listen: accept failed ({})", std::strerror(errno)));
    }
    try {
      serve_stream(session, client.get(), client.get());
    } catch (const HistoryStoreError&) {
      throw;
    } catch (const Error&) {
      // A client that vanished mid-reply ends its connection, not the server.
    }
  }
}

}  // namespace twincal
