#pragma once
/// @file
/// The conformance suite every SigmaPointScheme passes, as a GoogleTest typed test suite that
/// users instantiate for their own schemes (include it from a test, not from library code):
///
///     struct MyCase {
///       using Scheme = MyScheme;
///       static constexpr int dimension = 3;        // tested as fixed size and as Dynamic
///       static Scheme make() { return MyScheme{...}; }
///     };
///     namespace twincal::conformance {  // the suite's namespace
///     INSTANTIATE_TYPED_TEST_SUITE_P(Mine, SigmaPointSchemeConformance,
///                                    ::testing::Types<MyCase>);
///     }
///
/// Checked for a seeded random mean and covariance: the point count, Σ Wm = 1, the exact
/// reproduction of the mean (Wm) and the covariance (Wc), mirror symmetry with equal weights when
/// the scheme claims `is_symmetric`, and exact integration of every monomial of total degree <=
/// `Scheme::degree` under the Gaussian (standardised points ξ = L⁻¹(χ − x) against the moments
/// of N(0, I)). Tolerances are relative to the sum of absolute terms, i.e. to round-off.

#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/filters/sigma_point_scheme.hpp"
#include "twincal/filters/sigma_points.hpp"

namespace twincal::conformance {

/// E[z^k] for z ~ N(0, 1): (k − 1)!! for even k, 0 for odd k.
[[nodiscard]] inline double standard_normal_moment(int k) {
  if (k % 2 != 0) return 0.0;
  double m = 1.0;
  for (int j = k - 1; j > 1; j -= 2) m *= j;
  return m;
}

/// Every multi-index of `n` non-negative exponents with total degree <= `degree`.
[[nodiscard]] inline std::vector<std::vector<int>> multi_indices(Index n, int degree) {
  std::vector<std::vector<int>> out;
  std::vector<int> current(static_cast<std::size_t>(n), 0);
  auto recurse = [&](auto&& self, std::size_t position, int remaining) -> void {
    if (position == current.size()) {
      out.push_back(current);
      return;
    }
    for (int k = 0; k <= remaining; ++k) {
      current[position] = k;
      self(self, position + 1, remaining - k);
    }
    current[position] = 0;
  };
  recurse(recurse, 0, degree);
  return out;
}

/// A random mean and a random well-conditioned covariance's lower factor, seeded.
template <int N>
struct RandomGaussian {
  Vector<N> mean;
  SquareMatrix<N> lower;

  static RandomGaussian draw(Index n, std::uint64_t seed) {
    RandomStream stream(seed);
    RandomGaussian g{Vector<N>(n), SquareMatrix<N>(n, n)};
    stream.fill_normal(g.mean);
    SquareMatrix<N> a(n, n);
    stream.fill_normal(a);
    SquareMatrix<N> covariance = a * a.transpose();
    covariance.diagonal().array() += 0.5;
    g.lower = covariance.llt().matrixL();
    return g;
  }
};

template <typename Case>
class SigmaPointSchemeConformance : public ::testing::Test {
 protected:
  using Scheme = typename Case::Scheme;
  static constexpr int kFixed = Case::dimension;

  template <int N>
  static SigmaPoints<N, Scheme::points_at_compile_time(N)> draw(std::uint64_t seed,
                                                                RandomGaussian<N>* g = nullptr) {
    const RandomGaussian<N> gaussian = RandomGaussian<N>::draw(Case::dimension, seed);
    if (g != nullptr) *g = gaussian;
    return draw_sigma_points(Case::make(), gaussian.mean, gaussian.lower);
  }

  template <int N>
  static void check_moments_reproduced() {
    RandomGaussian<N> g;
    const auto set = draw<N>(7, &g);
    const SquareMatrix<N> covariance = g.lower * g.lower.transpose();
    const double scale = covariance.cwiseAbs().maxCoeff() + g.mean.cwiseAbs().maxCoeff();
    const double weight_scale = set.covariance_weights.cwiseAbs().sum();
    EXPECT_LE((set.mean() - g.mean).cwiseAbs().maxCoeff(), 1e-12 * weight_scale * scale);
    EXPECT_LE((set.covariance(g.mean) - covariance).cwiseAbs().maxCoeff(),
              1e-12 * weight_scale * scale);
  }

  template <int N>
  static void check_symmetry() {
    RandomGaussian<N> g;
    const auto set = draw<N>(11, &g);
    const Index m = set.size();
    const double tolerance = 1e-12 * (set.points.cwiseAbs().maxCoeff() + 1.0);
    for (Index j = 0; j < m; ++j) {
      const Vector<N> mirror = 2.0 * g.mean - set.points.col(j);
      bool found = false;
      for (Index k = 0; k < m && !found; ++k) {
        found = (set.points.col(k) - mirror).cwiseAbs().maxCoeff() <= tolerance &&
                set.mean_weights(k) == set.mean_weights(j) &&
                set.covariance_weights(k) == set.covariance_weights(j);
      }
      EXPECT_TRUE(found) << "sigma point " << j << " has no mirror image with equal weights";
    }
  }

  template <int N>
  static void check_polynomials() {
    RandomGaussian<N> g;
    const auto set = draw<N>(13, &g);
    const Index n = set.dimension();
    Matrix<N, Scheme::points_at_compile_time(N)> standardised = set.points.colwise() - g.mean;
    g.lower.template triangularView<Eigen::Lower>().solveInPlace(standardised);
    for (const std::vector<int>& powers : multi_indices(n, Scheme::degree)) {
      double expected = 1.0;
      for (Index i = 0; i < n; ++i) expected *= standard_normal_moment(powers[std::size_t(i)]);
      double sum = 0.0;
      double magnitude = 0.0;
      for (Index j = 0; j < set.size(); ++j) {
        double term = set.mean_weights(j);
        for (Index i = 0; i < n; ++i) term *= std::pow(standardised(i, j), powers[std::size_t(i)]);
        sum += term;
        magnitude += std::abs(term);
      }
      EXPECT_NEAR(sum, expected, 1e-11 * (magnitude + 1.0))
          << "monomial exponents " << ::testing::PrintToString(powers);
    }
  }
};

TYPED_TEST_SUITE_P(SigmaPointSchemeConformance);

TYPED_TEST_P(SigmaPointSchemeConformance, PointCountMatchesCompileTimeSize) {
  constexpr int n = TypeParam::dimension;
  const auto scheme = TypeParam::make();
  EXPECT_EQ(scheme.num_points(n), TypeParam::Scheme::points_at_compile_time(n));
  EXPECT_EQ(TypeParam::Scheme::points_at_compile_time(Dynamic), Dynamic);
  EXPECT_EQ((this->template draw<Dynamic>(3).size()), scheme.num_points(n));
}

TYPED_TEST_P(SigmaPointSchemeConformance, MeanWeightsSumToOne) {
  const auto set = this->template draw<TypeParam::dimension>(5);
  EXPECT_NEAR(set.mean_weights.sum(), 1.0, 1e-13 * set.mean_weights.cwiseAbs().sum());
}

TYPED_TEST_P(SigmaPointSchemeConformance, ReproducesMeanAndCovariance) {
  this->template check_moments_reproduced<TypeParam::dimension>();
  this->template check_moments_reproduced<Dynamic>();
}

TYPED_TEST_P(SigmaPointSchemeConformance, SymmetricSetsAreMirrorSymmetric) {
  if constexpr (!TypeParam::Scheme::is_symmetric) {
    GTEST_SKIP() << "the scheme does not claim symmetry";
  } else {
    this->template check_symmetry<TypeParam::dimension>();
    this->template check_symmetry<Dynamic>();
  }
}

TYPED_TEST_P(SigmaPointSchemeConformance, IntegratesPolynomialsUpToItsDegree) {
  this->template check_polynomials<TypeParam::dimension>();
  this->template check_polynomials<Dynamic>();
}

REGISTER_TYPED_TEST_SUITE_P(SigmaPointSchemeConformance, PointCountMatchesCompileTimeSize,
                            MeanWeightsSumToOne, ReproducesMeanAndCovariance,
                            SymmetricSetsAreMirrorSymmetric, IntegratesPolynomialsUpToItsDegree);

}  // namespace twincal::conformance
