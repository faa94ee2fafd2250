#pragma once
/// @file
/// `build_id()`: which sources and which compiler built this twincal, for results that must not
/// mix builds (a `twincal run` results directory records it per group and refuses to resume a
/// group with another build's episodes; docs/cli.md, "Resume").

#include <string_view>

namespace twincal {

/// "<commit>[+<changes>] (<compiler> <version>, <build type>)": the git commit the library was
/// built from (12 hex digits), a hash of its uncommitted changes to anything but the docs when
/// there are any, and the compiler and CMake build type; "unknown" for the commit when the
/// sources were not a git checkout. Written at every build, so a rebuild after any change to the
/// code gives another id.
[[nodiscard]] std::string_view build_id() noexcept;

}  // namespace twincal
