// Compile-time checks of twincal's concepts: what each accepts and what it rejects. A failing
// static_assert fails the build, naming the requirement.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <type_traits>

#include "twincal/core/cholesky.hpp"
#include "twincal/core/named_enum.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/random_stream.hpp"

namespace twincal::static_checks {

// --- ValidatableOptions ----------------------------------------------------------------------
struct GoodOptions {
  [[nodiscard]] std::optional<std::string> validate() const { return std::nullopt; }
};
struct BoolValidate {  // a bool says that something is wrong, not what
  [[nodiscard]] bool validate() const { return true; }
};
static_assert(ValidatableOptions<GoodOptions>);
static_assert(!ValidatableOptions<BoolValidate>);

// --- NamedEnum: an enum with a name table; no table, or a table of another enum, is refused --
enum class Tabled { a, b };
[[nodiscard]] constexpr auto name_table(std::type_identity<Tabled>) noexcept {
  return std::to_array<NameEntry<Tabled>>({{Tabled::a, "a"}, {Tabled::b, "b"}});
}
enum class Untabled { a, b };
enum class Mistabled { a };
[[nodiscard]] constexpr auto name_table(std::type_identity<Mistabled>) noexcept {
  return std::to_array<NameEntry<Tabled>>({{Tabled::a, "a"}});
}
static_assert(NamedEnum<Tabled>);
static_assert(!NamedEnum<Untabled>);
static_assert(!NamedEnum<Mistabled>);
static_assert(!NamedEnum<int>);
static_assert(NamedEnum<CovarianceRepair>);

// --- RandomStream is a standard random bit generator ------------------------------------------
static_assert(std::uniform_random_bit_generator<RandomStream>);

}  // namespace twincal::static_checks
