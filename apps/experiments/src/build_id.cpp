#include "twincal/experiments/build_id.hpp"

namespace twincal {
namespace {

// generated_build_id and generated_build_commit, written at build time by
// cmake/TwincalBuildId.cmake.
#include "twincal_build_id.inc"

}  // namespace

std::string_view build_id() noexcept { return generated_build_id; }

std::string_view build_commit() noexcept { return generated_build_commit; }

}  // namespace twincal
