#pragma once
// The twincal subcommands: each takes the arguments after its name and returns the exit code.

#include <span>
#include <string>

namespace twincal::cli {

int run_command(std::span<const std::string> args);
int paper_command(std::span<const std::string> args);
int scaling_command(std::span<const std::string> args);
int sweep_command(std::span<const std::string> args);
int plot_command(std::span<const std::string> args, const char* argv0);
int summary_command(std::span<const std::string> args);
int merge_command(std::span<const std::string> args);
int serve_command(std::span<const std::string> args);
int history_command(std::span<const std::string> args);
int trace_command(std::span<const std::string> args);

}  // namespace twincal::cli
