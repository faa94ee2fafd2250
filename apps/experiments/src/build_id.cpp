#include "twincal/experiments/build_id.hpp"

namespace twincal {

std::string_view build_id() noexcept {
  // Generated at build time by cmake/TwincalBuildId.cmake.
  static constexpr std::string_view id =
#include "twincal_build_id.inc"
      ;
  return id;
}

}  // namespace twincal
