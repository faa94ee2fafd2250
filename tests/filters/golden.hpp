#pragma once
// Test support: reading the reference data in tests/data (filterpy's sigma points and filter
// runs) and measuring agreement the way the issue states it: the largest absolute error of a
// quantity over a run, relative to the largest magnitude of that quantity in the run.

#include <algorithm>
#include <fstream>
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "twincal/core/eigen.hpp"

namespace twincal::test_support {

inline nlohmann::json load(const std::string& name) {
  std::ifstream in(std::string(TWINCAL_TEST_DATA_DIR) + "/" + name);
  EXPECT_TRUE(in.good()) << "cannot open tests/data/" << name;
  return nlohmann::json::parse(in);
}

template <int N = Dynamic>
Vector<N> vector(const nlohmann::json& v) {
  Vector<N> out(static_cast<Index>(v.size()));
  for (Index i = 0; i < out.size(); ++i) out(i) = v[static_cast<std::size_t>(i)].get<double>();
  return out;
}

/// A JSON array of rows.
template <int R = Dynamic, int C = Dynamic>
Matrix<R, C> matrix(const nlohmann::json& rows) {
  const auto r = static_cast<Index>(rows.size());
  const auto c = static_cast<Index>(rows[0].size());
  Matrix<R, C> out(r, c);
  for (Index i = 0; i < r; ++i) {
    for (Index j = 0; j < c; ++j) {
      out(i, j) = rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)].get<double>();
    }
  }
  return out;
}

/// Per named quantity: the largest |ours − reference| and the largest |reference|.
class Agreement {
 public:
  template <typename A, typename B>
  void add(const std::string& name, const Eigen::MatrixBase<A>& ours,
           const Eigen::MatrixBase<B>& reference) {
    Entry& e = entries_[name];
    EXPECT_EQ(ours.rows(), reference.rows()) << name;
    EXPECT_EQ(ours.cols(), reference.cols()) << name;
    e.error = std::max(e.error, (ours - reference).cwiseAbs().maxCoeff());
    e.magnitude = std::max(e.magnitude, reference.cwiseAbs().maxCoeff());
  }
  void add(const std::string& name, double ours, double reference) {
    Entry& e = entries_[name];
    e.error = std::max(e.error, std::abs(ours - reference));
    e.magnitude = std::max(e.magnitude, std::abs(reference));
  }

  /// The largest relative error over all quantities, and its quantity's name.
  [[nodiscard]] std::pair<double, std::string> worst() const {
    std::pair<double, std::string> w{0.0, ""};
    for (const auto& [name, e] : entries_) {
      const double relative = e.magnitude > 0.0 ? e.error / e.magnitude : e.error;
      if (relative >= w.first) w = {relative, name};
    }
    return w;
  }

  /// Expects every quantity within `tolerance` relative error.
  void expect_within(double tolerance, const std::string& context) const {
    for (const auto& [name, e] : entries_) {
      const double relative = e.magnitude > 0.0 ? e.error / e.magnitude : e.error;
      EXPECT_LE(relative, tolerance) << context << ": " << name << " (largest error " << e.error
                                     << ", largest magnitude " << e.magnitude << ")";
    }
  }

 private:
  struct Entry {
    double error = 0.0;
    double magnitude = 0.0;
  };
  std::map<std::string, Entry> entries_;
};

}  // namespace twincal::test_support
