#pragma once
/// @file
/// `LineSplitter`: cuts a byte stream into request lines for `twincal serve`'s transports. A line
/// is what ends in '\n' (a trailing '\r' dropped; an empty line is a line too, and
/// gets its error reply, so a client waiting for one does not hang); one longer than
/// ServeSession::max_line_bytes is skipped up to its newline without being held in memory and
/// reported by its size. An unterminated last line is not a request.

#include <cstddef>
#include <string>
#include <string_view>

#include "twincal/serve/serve_session.hpp"

namespace twincal {

class LineSplitter {
 public:
  /// Feeds `data`: `on_line(std::string_view line)` for each complete line and
  /// `on_oversized(std::size_t bytes)` for each skipped one, in order, while `more()` holds
  /// (a callback may end the stream, e.g. after a shutdown request).
  template <typename OnLine, typename OnOversized, typename More>
  void feed(std::string_view data, OnLine&& on_line, OnOversized&& on_oversized, More&& more) {
    while (!data.empty() && more()) {
      const std::size_t newline = data.find('\n');
      const std::string_view piece = data.substr(0, newline);
      if (skipped_ > 0 || line_.size() + piece.size() > ServeSession::max_line_bytes) {
        skipped_ += (skipped_ == 0 ? line_.size() : 0) + piece.size();
        line_.clear();
      } else {
        line_.append(piece);
      }
      if (newline == std::string_view::npos) return;
      data.remove_prefix(newline + 1);
      if (skipped_ > 0) {
        const std::size_t bytes = skipped_;
        skipped_ = 0;
        on_oversized(bytes);
        continue;
      }
      if (!line_.empty() && line_.back() == '\r') line_.pop_back();
      on_line(std::string_view(line_));
      line_.clear();
    }
  }

 private:
  std::string line_;
  std::size_t skipped_ = 0;  // > 0 while skipping an oversized line: its bytes so far
};

}  // namespace twincal
