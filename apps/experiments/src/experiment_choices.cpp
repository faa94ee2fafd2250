#include "twincal/experiments/experiment_choices.hpp"

#include <array>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "twincal/core/error.hpp"

namespace twincal {
namespace {

template <typename Enum, std::size_t Size>
using NameTable = std::array<std::pair<Enum, std::string_view>, Size>;

constexpr NameTable<TwinCase, 6> twin_case_names{{{TwinCase::body, "body"},
                                                  {TwinCase::door, "door"},
                                                  {TwinCase::analytic, "analytic"},
                                                  {TwinCase::external, "external"},
                                                  {TwinCase::body_contact, "body-contact"},
                                                  {TwinCase::door_contact, "door-contact"}}};
constexpr NameTable<Nonlinearity, 4> nonlinearity_names{{{Nonlinearity::none, "none"},
                                                         {Nonlinearity::contact, "contact"},
                                                         {Nonlinearity::stiffening, "stiffening"},
                                                         {Nonlinearity::kink, "kink"}}};
constexpr NameTable<FilterScheme, 5> filter_scheme_names{
    {{FilterScheme::merwe, "merwe"},
     {FilterScheme::julier, "julier"},
     {FilterScheme::cubature, "cubature"},
     {FilterScheme::fifth_degree, "fifth_degree"},
     {FilterScheme::simplex, "simplex"}}};
constexpr NameTable<CandidateSampler, 4> sampler_names{
    {{CandidateSampler::sobol, "sobol"},
     {CandidateSampler::halton, "halton"},
     {CandidateSampler::random, "random"},
     {CandidateSampler::latin_hypercube, "latin_hypercube"}}};
constexpr NameTable<ExplorationKind, 4> exploration_names{
    {{ExplorationKind::trace, "trace"},
     {ExplorationKind::weighted_trace, "weighted_trace"},
     {ExplorationKind::log_det, "log_det"},
     {ExplorationKind::max_eigenvalue, "max_eigenvalue"}}};

template <typename Enum, std::size_t Size>
std::string_view name_of(const NameTable<Enum, Size>& table, Enum value) noexcept {
  for (const auto& [entry, name] : table) {
    if (entry == value) return name;
  }
  return "unknown";
}

template <typename Enum, std::size_t Size>
Enum parse(const NameTable<Enum, Size>& table, std::string_view text, std::string_view what) {
  std::array<std::string_view, Size> names{};
  for (std::size_t i = 0; i < Size; ++i) {
    if (table[i].second == text) return table[i].first;
    names[i] = table[i].second;
  }
  throw InvalidArgumentError(
      std::string(what),
      fmt::format("{}: is \"{}\"; rule: must be one of [{}]", what, text, fmt::join(names, ", ")));
}

}  // namespace

std::string_view to_string(TwinCase value) noexcept { return name_of(twin_case_names, value); }
std::string_view to_string(Nonlinearity value) noexcept {
  return name_of(nonlinearity_names, value);
}
std::string_view to_string(FilterScheme value) noexcept {
  return name_of(filter_scheme_names, value);
}
std::string_view to_string(CandidateSampler value) noexcept {
  return name_of(sampler_names, value);
}
std::string_view to_string(ExplorationKind value) noexcept {
  return name_of(exploration_names, value);
}

TwinCase parse_twin_case(std::string_view text, std::string_view what) {
  return parse(twin_case_names, text, what);
}
Nonlinearity parse_nonlinearity(std::string_view text, std::string_view what) {
  return parse(nonlinearity_names, text, what);
}
FilterScheme parse_filter_scheme(std::string_view text, std::string_view what) {
  return parse(filter_scheme_names, text, what);
}
CandidateSampler parse_candidate_sampler(std::string_view text, std::string_view what) {
  return parse(sampler_names, text, what);
}
ExplorationKind parse_exploration_kind(std::string_view text, std::string_view what) {
  return parse(exploration_names, text, what);
}

}  // namespace twincal
