#pragma once
/// @file
/// `SearchedOptima` and its file: u0(x) and z*(x) of an external twin's upper_parts ×
/// lower_parts pairs as a search found them, kept on disk so that the search runs once per file
/// rather than once per `twincal run` (ExternalTwinSettings::optima_file). With a slow program
/// the search is the study's largest cost: the CalculiX lap joint as the plant takes 14–25 min
/// for its 30 pairs before the first assembly (docs/calculix.md).
///
/// The file records the settings that decide the search (result_defining_json(): every field of
/// ExternalTwinSettings but those that change no result) and is read only under the same
/// settings. It cannot record the program's build: a program that
/// changed answers other optima, so its file must be deleted. Numbers are written in their
/// shortest exact form, so optima read back are the searched ones to the last bit and a study
/// gives the same digits with the file as without it. JSON:
///   {"format": "twincal searched optima 1", "settings": {<the deciding fields>},
///    "search": {"evaluations": 2940, "requests": 2940},
///    "optima": [{"upper": 0, "lower": 0, "control": [0.12, -0.3], "quality": 0.034}, …]}
/// with the pairs upper-major, as ExternalCaseTwin::assemblies() lists them.

#include <cstdint>
#include <filesystem>
#include <optional>

#include <nlohmann/json_fwd.hpp>

#include "twincal/core/eigen.hpp"
#include "twincal/experiments/external_twin_settings.hpp"

namespace twincal {

/// What a search found for every pair, and what it cost.
struct SearchedOptima {
  MatrixX controls;               ///< d × pairs, column upper · lower_parts + lower
  VectorX qualities;              ///< z*(x) of each pair
  std::uint64_t evaluations = 0;  ///< the search's twin evaluations, over all pairs
  std::uint64_t requests = 0;     ///< its requests (rounds of the twin's latency)
};

/// The optima that `path` holds for `settings`; nothing when there is no file at `path`.
/// @throws InvalidArgumentError naming the file and what is wrong with it: unreadable or not
///         JSON, another format, settings other than these (the first field that differs),
///         another number of pairs, a control of another dimension, not finite or outside the
///         bounds, a quality not finite or negative.
[[nodiscard]] std::optional<SearchedOptima> read_searched_optima(
    const std::filesystem::path& path, const ExternalTwinSettings& settings);

/// Writes `optima` for `settings` to `path`, whole or not at all (a temporary file beside it,
/// then renamed over it).
/// @throws InvalidArgumentError when the file cannot be written, or `optima` does not fit the
///         settings (dimension, number of pairs).
void write_searched_optima(const std::filesystem::path& path, const ExternalTwinSettings& settings,
                           const SearchedOptima& optima);

/// Checks, before a long search, that write_searched_optima() will be able to create `path`:
/// its folder exists and a file can be created there (the probe is removed again).
/// @throws InvalidArgumentError naming the path.
void require_writable_optima_file(const std::filesystem::path& path);

}  // namespace twincal
