#pragma once
/// @file
/// The transports of `twincal serve`: a ServeSession over a byte stream (stdin/stdout) or over
/// TCP connections, one JSON request per line in, one reply per line out. A line longer than
/// ServeSession::max_line_bytes is skipped up to its newline without being held in memory and
/// answered with an error; the server keeps serving.

#include <functional>
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

  [[nodiscard]] std::optional<std::string> validate() const;
};

/// Listens on `options` and serves one connection at a time (serve_stream on it) until a
/// `shutdown` request; `on_listening(port)` is called once the socket accepts connections.
/// @throws InvalidArgumentError for an invalid host or port; Error when the socket cannot be
///         bound; HistoryStoreError.
void serve_tcp(ServeSession& session, const ListenOptions& options,
               const std::function<void(int port)>& on_listening);

}  // namespace twincal
