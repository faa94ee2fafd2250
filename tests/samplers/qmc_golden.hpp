#pragma once
// Reads tests/data/qmc.json (SciPy 1.10 scipy.stats.qmc reference points and discrepancies,
// copied unchanged from the project's shared reference data) into Eigen matrices with points as
// columns, the samplers' layout.
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/core/eigen.hpp"

namespace twincal::test_support {

inline const nlohmann::json& qmc_golden() {
  static const nlohmann::json data = [] {
    std::ifstream file(std::string(TWINCAL_TEST_DATA_DIR) + "/qmc.json");
    if (!file) throw std::runtime_error("cannot open tests/data/qmc.json");
    return nlohmann::json::parse(file);
  }();
  return data;
}

/// The "points" array (n rows of d values) of a record as a d × n matrix.
inline MatrixX golden_points(const nlohmann::json& record) {
  const auto& rows = record.at("points");
  const auto d = record.at("d").get<Index>();
  MatrixX points(d, static_cast<Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(static_cast<Index>(rows[i].size()), d);
    for (Index k = 0; k < d; ++k) {
      points(k, static_cast<Index>(i)) = rows[i][static_cast<std::size_t>(k)].get<double>();
    }
  }
  return points;
}

}  // namespace twincal::test_support
