// Any bytes as a part-deviation CSV (docs/sheet_metal.md) on a 4 x 2-element mesh: read()
// answers finite deviations for every node or an InvalidArgumentError naming the file.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "twincal/core/error.hpp"
#include "twincal/sheet_metal/part_deviation_file.hpp"
#include "twincal/sheet_metal/plate_mesh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace twincal;
  // Nodes at x = 0, 25, …, 100 and y = 0, 20, 40 mm: the seeds' coordinates.
  static const PlateMesh mesh(4, 2, 25.0, 20.0);
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const VectorX deviations = PartDeviationFile::read(in, "part.csv", mesh);
    if (deviations.size() != mesh.dof_count() || !deviations.allFinite()) {
      fmt::print(stderr, "part_deviation fuzzer: read {} values, finite: {}\n", deviations.size(),
                 deviations.allFinite());
      std::abort();
    }
  } catch (const InvalidArgumentError& error) {
    if (error.argument() != "part.csv") {
      fmt::print(stderr, "part_deviation fuzzer: error names '{}'\n", error.argument());
      std::abort();
    }
  }
  return 0;
}
