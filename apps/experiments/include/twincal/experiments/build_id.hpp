#pragma once
/// @file
/// `build_id()` and `build_commit()`: which sources and which compiler built this twincal, for
/// results that must not mix builds (a `twincal run` results directory records both per group
/// and resumes a group only with its build; docs/cli.md, "Resume"). Written at every build by
/// cmake/TwincalBuildId.cmake.

#include <string_view>

namespace twincal {

/// "sources <hash> (<compiler> <version>, <build type>)": a hash (12 hex digits) of the sources
/// the library was built from — the files git tracks but the docs, their uncommitted changes
/// and the new files git does not ignore — with the compiler and the CMake build type. A change
/// to the code gives another id; a commit that changes only the docs does not. "unknown
/// sources" when the sources were not a git checkout.
[[nodiscard]] std::string_view build_id() noexcept;

/// The git commit the library was built from (12 hex digits), "+changes" when its sources had
/// uncommitted changes; "unknown" outside a git checkout. Where the id's sources can be found.
[[nodiscard]] std::string_view build_commit() noexcept;

}  // namespace twincal
