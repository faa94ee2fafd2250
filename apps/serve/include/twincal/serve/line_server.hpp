#pragma once
/// @file
/// The transports of `twincal serve`: a ServeSession over a byte stream (stdin/stdout) or over
/// TCP connections, one JSON request per line in, one reply per line out. A line longer than
/// ServeSession::max_line_bytes is skipped up to its newline without being held in memory and
/// answered with an error; the server keeps serving (line_splitter.hpp).

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "twincal/serve/serve_session.hpp"

namespace twincal {

/// Serves requests read from `in_fd`, writing replies to `out_fd`, until a `shutdown` request
/// or the end of the input. @throws HistoryStoreError (the session must stop); Error when a
/// descriptor cannot be read or written.
void serve_stream(ServeSession& session, int in_fd, int out_fd);

struct ListenOptions {
  std::string host = "127.0.0.1";  ///< an IPv4 address; loopback unless asked otherwise
  int port = 0;                    ///< 0: any free port (reported to on_listening)
  /// Connections open at once; one more is answered with an error line and closed.
  int max_connections = 64;
  /// A connection that sends nothing for this long is closed (its pending request, if any, stays
  /// pending in the session: another connection may observe it).
  std::chrono::milliseconds idle_timeout{std::chrono::minutes(10)};
  /// Replies waiting for a client that does not read them, in bytes, before its connection is
  /// closed (at least ServeSession::max_line_bytes).
  std::size_t max_reply_backlog = std::size_t{8} << 20;
  /// Listen on this Unix-domain socket instead of TCP (host and port unused): for a cell PC
  /// whose client runs on the same machine. Access is the socket file's permissions
  /// (`unix_socket_mode`, the owner only by default), so no token is needed (one given is still
  /// required first). A stale socket file of a killed server is replaced; a live one or any
  /// other file is refused; the file is removed when the server ends.
  std::optional<std::filesystem::path> unix_socket;
  unsigned unix_socket_mode = 0600;
  /// The shared secret a connection must send first, as {"op": "authenticate", "token": …}
  /// (compared in constant time; a wrong or missing one gets one error reply, the connection is
  /// closed and the attempt logged on stderr). Required unless `host` is a loopback address: a
  /// cell controller takes orders only from the cell. At least 16 characters.
  std::optional<std::string> token;

  [[nodiscard]] std::optional<std::string> validate() const;
};

/// Listens on `options` (TCP, or `unix_socket`) and serves every connection from one event loop
/// (Boost.Asio), applying
/// requests to the session in the order their lines arrive, until a `shutdown` request's reply
/// is written; `on_listening(port)` is called once the socket accepts connections. A client that
/// is silent, slow, half-closed or never reads its replies costs only its own connection. With a
/// token, a connection's first request must authenticate it (ListenOptions::token).
/// @throws InvalidArgumentError for invalid options; Error when the socket cannot be bound;
///         HistoryStoreError.
void serve_connections(ServeSession& session, const ListenOptions& options,
                       const std::function<void(int port)>& on_listening);

/// serve_connections with the session opened by `open_session` once the socket is bound, so
/// that a port in use leaves no new database behind (`twincal serve --listen`). `on_listening`
/// gets the TCP port (0 for a Unix-domain socket).
void serve_connections(const ListenOptions& options,
                       const std::function<ServeSession&()>& open_session,
                       const std::function<void(int port)>& on_listening);

}  // namespace twincal
