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
/// settings. It cannot record the program's build: a program that changed answers other optima,
/// so its file must be deleted. It is rewritten after every pair the search finishes, so a study
/// killed during the search loses one pair per worker at most: the next one reads the pairs
/// found and searches the others, to the same optima (each pair's search depends only on its
/// start, and the starts only on pairs found before it). Numbers are written in their shortest
/// exact form, so optima read back are the searched ones to the last bit and a study gives the
/// same digits with the file as without it. JSON:
///   {"format": "twincal searched optima 1", "settings": {<the deciding fields>},
///    "search": {"evaluations": 2940, "requests": 2940},
///    "optima": [{"upper": 0, "lower": 0, "control": [0.12, -0.3], "quality": 0.034}, …]}
/// with the pairs found so far upper-major, as ExternalCaseTwin::assemblies() lists them, and
/// "search" what finding them cost.

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "twincal/core/eigen.hpp"
#include "twincal/experiments/external_twin_settings.hpp"

namespace twincal {

/// What a search found for the pairs it has finished, and what that cost.
struct SearchedOptima {
  MatrixX controls;               ///< d × pairs, column upper · lower_parts + lower
  VectorX qualities;              ///< z*(x) of each pair
  std::vector<bool> found;        ///< whether each pair's column holds its optimum yet
  std::uint64_t evaluations = 0;  ///< the search's twin evaluations, over the pairs found
  std::uint64_t requests = 0;     ///< its requests (rounds of the twin's latency)

  /// Nothing found yet, for `pairs` pairs of a d-locator twin.
  SearchedOptima(Index d, Index pairs)
      : controls(MatrixX::Zero(d, pairs)),
        qualities(VectorX::Zero(pairs)),
        found(static_cast<std::size_t>(pairs), false) {}
  /// Whether every pair is found.
  [[nodiscard]] bool complete() const noexcept {
    return std::find(found.begin(), found.end(), false) == found.end();
  }
};

/// The optima that `path` holds for `settings`; nothing when there is no file at `path`.
/// @throws InvalidArgumentError naming the file and what is wrong with it: unreadable or not
///         JSON, another format, settings other than these (the first field that differs),
///         pairs out of order or beyond upper_parts × lower_parts, a control of another
///         dimension, not finite or outside the bounds, a quality not finite or negative.
[[nodiscard]] std::optional<SearchedOptima> read_searched_optima(
    const std::filesystem::path& path, const ExternalTwinSettings& settings);

/// Writes the pairs `optima` has found, for `settings`, to `path`, whole or not at all (a
/// temporary file beside it, then renamed over it).
/// @throws InvalidArgumentError when the file cannot be written, or `optima` does not fit the
///         settings (dimension, number of pairs).
void write_searched_optima(const std::filesystem::path& path, const ExternalTwinSettings& settings,
                           const SearchedOptima& optima);

/// Checks, before a long search, that write_searched_optima() will be able to create `path`:
/// its folder exists and a file can be created there (the probe is removed again).
/// @throws InvalidArgumentError naming the path.
void require_writable_optima_file(const std::filesystem::path& path);

}  // namespace twincal
