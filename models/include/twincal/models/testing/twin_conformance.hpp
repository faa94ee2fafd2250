#pragma once
/// @file
/// The conformance suite every Twin passes, as a GoogleTest typed test suite that users
/// instantiate for their own twins (include it from a test, not from library code):
///
///     struct MyCase {
///       using Twin = MyTwin;
///       static Twin make() { return MyTwin{...}; }  // built once for the whole suite
///       static std::vector<MyTwin::Assembly> assemblies() { return {...}; }  // >= 1 to test
///       // Optional: the relative difference allowed between two evaluations of the same
///       // (x, u); without it they must be bit-identical, as twincal's twins are.
///       static constexpr double tolerance = 1e-12;
///     };
///     namespace twincal::conformance {  // the suite's namespace
///     INSTANTIATE_TYPED_TEST_SUITE_P(Mine, TwinConformance, ::testing::Types<MyCase>);
///     }
///
/// What the controllers and evaluators rely on, checked at seeded controls inside the bounds
/// (uniform draws, the two extreme corners and the centre): d >= 1 distinct, non-empty locator
/// names and d finite bounds with lower < upper; quality(x, u) equals a batch of that one
/// control and its entry in a larger batch (the batch is only the unit of work); permuting the
/// controls of a batch permutes its qualities (no column depends on its neighbours); const calls
/// from four threads at once, for at least 100 ms, give the serial results (evaluators spread
/// batches over threads; a race shows only while the threads really run at once, so this is a
/// smoke test — ThreadSanitizer is the proof); Q is finite and >= 0 inside the bounds (an RMS
/// deviation); a control or batch of the wrong shape throws DimensionMismatchError
/// (require_control, require_control_batch).

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <latch>
#include <numeric>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/models/twin.hpp"

namespace twincal::conformance {

template <typename Case>
class TwinConformance : public ::testing::Test {
 protected:
  using TwinType = typename Case::Twin;
  using Assembly = typename TwinType::Assembly;
  static_assert(Twin<TwinType>, "Case::Twin must satisfy twincal::Twin");

  /// Threads of the concurrency check.
  static constexpr int thread_count = 4;
  /// Each thread evaluates every assembly's controls at least rounds times and for at least
  /// minimum_duration: a race shows only while threads really run at once, and a fast analytic
  /// twin would otherwise finish within one scheduler time slice.
  static constexpr std::size_t rounds = 3;
  static constexpr std::chrono::milliseconds minimum_duration{100};
  /// Random controls per assembly, besides the two corners and the centre.
  static constexpr Index random_controls = 13;

  /// The case's twin, built once: a FEM twin's precomputation is the expensive part.
  static const TwinType& twin() {
    static const TwinType instance = Case::make();
    return instance;
  }

  /// The relative difference allowed between two evaluations of the same (x, u).
  static constexpr double tolerance() {
    if constexpr (requires { Case::tolerance; }) {
      return Case::tolerance;
    } else {
      return 0.0;
    }
  }

  static bool same(double expected, double actual) {
    return std::abs(expected - actual) <= tolerance() * std::max(1.0, std::abs(expected));
  }

  /// d × (random_controls + 3) controls: the lower corner, the upper corner, the centre and
  /// uniform draws in the box, from `seed`.
  static MatrixX controls(std::uint64_t seed) {
    const VectorX& lower = twin().lower_bounds();
    const VectorX& upper = twin().upper_bounds();
    const Index d = twin().control_dimension();
    MatrixX u(d, random_controls + 3);
    u.col(0) = lower;
    u.col(1) = upper;
    u.col(2) = 0.5 * (lower + upper);
    RandomStream stream(seed);
    for (Index j = 3; j < u.cols(); ++j) {
      for (Index k = 0; k < d; ++k) u(k, j) = lower(k) + (upper(k) - lower(k)) * stream.uniform();
    }
    return u;
  }

  static VectorX batch(const Assembly& assembly, const MatrixX& u) {
    VectorX out(u.cols());
    twin().quality_batch(assembly, u, out);
    return out;
  }

  static VectorX singles(const Assembly& assembly, const MatrixX& u) {
    VectorX out(u.cols());
    for (Index j = 0; j < u.cols(); ++j) out(j) = twin().quality(assembly, u.col(j));
    return out;
  }

  /// Every assembly's batch qualities then single qualities, one after the other.
  static std::vector<VectorX> evaluate_all(const std::vector<Assembly>& assemblies,
                                           const MatrixX& u) {
    std::vector<VectorX> results;
    for (const Assembly& assembly : assemblies) {
      results.push_back(batch(assembly, u));
      results.push_back(singles(assembly, u));
    }
    return results;
  }

  /// What one thread of the concurrency check saw.
  struct ThreadReport {
    std::size_t rounds = 0;
    std::size_t mismatches = 0;
    std::string first_mismatch;
    std::exception_ptr failure;
  };

  /// Thread `t` of the concurrency check: rounds of batch then single calls over every assembly,
  /// starting at assembly t so that the threads evaluate different values at the same moment,
  /// each compared with `serial` (evaluate_all's). At least rounds rounds and minimum_duration,
  /// and on until every
  /// thread has done its share (`behind` counts those that have not), so the threads' calls
  /// overlap however late a thread starts.
  static void run_concurrently(int t, const std::vector<Assembly>& assemblies, const MatrixX& u,
                               const std::vector<VectorX>& serial, std::atomic<int>& behind,
                               ThreadReport& report) {
    const std::size_t n = assemblies.size();
    const auto compare = [&](const VectorX& values, std::size_t a, bool single) {
      const VectorX& expected = serial[2 * a + (single ? 1 : 0)];
      for (Index j = 0; j < values.size(); ++j) {
        if (same(expected(j), values(j))) continue;
        if (report.mismatches++ == 0) {
          std::ostringstream what;
          what.precision(17);
          what << "round " << report.rounds << ", assembly " << a << (single ? " single" : " batch")
               << ", control " << j << ": " << values(j) << ", serially " << expected(j);
          report.first_mismatch = what.str();
        }
      }
    };
    const auto deadline = std::chrono::steady_clock::now() + minimum_duration;
    bool done = false;
    try {
      while (!done || behind.load() > 0) {
        for (std::size_t i = 0; i < n; ++i) {
          const std::size_t a = (i + static_cast<std::size_t>(t)) % n;
          compare(batch(assemblies[a], u), a, false);
          compare(singles(assemblies[a], u), a, true);
        }
        ++report.rounds;
        if (!done && report.rounds >= rounds && std::chrono::steady_clock::now() >= deadline) {
          done = true;
          behind.fetch_sub(1);
        }
      }
    } catch (...) {
      report.failure = std::current_exception();
      if (!done) behind.fetch_sub(1);  // the others need not wait for it
    }
  }

  static std::vector<Assembly> assemblies() {
    std::vector<Assembly> all = Case::assemblies();
    EXPECT_FALSE(all.empty()) << "Case::assemblies() must name at least one assembly";
    return all;
  }
};

TYPED_TEST_SUITE_P(TwinConformance);

TYPED_TEST_P(TwinConformance, NamesAndBoundsDescribeTheControls) {
  const auto& twin = this->twin();
  const Index d = twin.control_dimension();
  ASSERT_GE(d, 1);
  const std::vector<std::string>& names = twin.locator_names();
  EXPECT_EQ(static_cast<Index>(names.size()), d);
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size())
      << "locator names repeat: " << ::testing::PrintToString(names);
  for (const std::string& name : names) EXPECT_FALSE(name.empty());
  const VectorX& lower = twin.lower_bounds();
  const VectorX& upper = twin.upper_bounds();
  ASSERT_EQ(lower.size(), d);
  ASSERT_EQ(upper.size(), d);
  for (Index k = 0; k < d; ++k) {
    EXPECT_TRUE(std::isfinite(lower(k)) && std::isfinite(upper(k)) && lower(k) < upper(k))
        << "locator " << k << ": bounds [" << lower(k) << ", " << upper(k) << "]";
  }
}

TYPED_TEST_P(TwinConformance, QualityEqualsTheBatchOfOneAndItsEntryInALargerBatch) {
  const MatrixX u = this->controls(1);
  for (const auto& assembly : this->assemblies()) {
    const VectorX whole = this->batch(assembly, u);
    for (Index j = 0; j < u.cols(); ++j) {
      const double single = this->twin().quality(assembly, u.col(j));
      const double of_one = this->batch(assembly, u.col(j))(0);
      EXPECT_TRUE(this->same(single, of_one))
          << "control " << j << ": quality " << single << ", batch of one " << of_one;
      EXPECT_TRUE(this->same(single, whole(j)))
          << "control " << j << ": quality " << single << ", batch entry " << whole(j);
    }
  }
}

TYPED_TEST_P(TwinConformance, PermutingTheControlsPermutesTheQualities) {
  const MatrixX u = this->controls(2);
  std::vector<Index> order(static_cast<std::size_t>(u.cols()));
  std::iota(order.begin(), order.end(), Index{0});
  std::reverse(order.begin(), order.end());
  RandomStream stream(3);
  for (std::size_t i = order.size() - 1; i > 0; --i) {  // Fisher–Yates on top of the reversal
    std::swap(order[i], order[stream.uniform_int<std::size_t>(0, i)]);
  }
  MatrixX permuted(u.rows(), u.cols());
  for (Index k = 0; k < u.cols(); ++k) permuted.col(k) = u.col(order[static_cast<std::size_t>(k)]);
  for (const auto& assembly : this->assemblies()) {
    const VectorX original = this->batch(assembly, u);
    const VectorX reordered = this->batch(assembly, permuted);
    for (Index k = 0; k < u.cols(); ++k) {
      const double expected = original(order[static_cast<std::size_t>(k)]);
      EXPECT_TRUE(this->same(expected, reordered(k)))
          << "position " << k << " holds control " << order[static_cast<std::size_t>(k)] << ": "
          << reordered(k) << " in the permuted batch, " << expected << " in the original";
    }
  }
}

TYPED_TEST_P(TwinConformance, ConcurrentConstCallsGiveTheSerialResults) {
  const MatrixX u = this->controls(4);
  const std::vector<typename TestFixture::Assembly> assemblies = this->assemblies();
  const std::vector<VectorX> serial = this->evaluate_all(assemblies, u);
  constexpr int threads = TestFixture::thread_count;
  std::vector<typename TestFixture::ThreadReport> reports(threads);
  std::latch start(threads);
  std::atomic<int> behind(threads);
  {
    std::vector<std::jthread> workers;
    for (int t = 0; t < threads; ++t) {
      workers.emplace_back([&, t] {
        start.arrive_and_wait();  // every thread begins at once
        this->run_concurrently(t, assemblies, u, serial, behind,
                               reports[static_cast<std::size_t>(t)]);
      });
    }
  }  // the jthreads join here
  for (int t = 0; t < threads; ++t) {
    const auto& report = reports[static_cast<std::size_t>(t)];
    if (report.failure) {
      try {
        std::rethrow_exception(report.failure);
      } catch (const std::exception& error) {
        ADD_FAILURE() << "thread " << t << " threw: " << error.what();
      } catch (...) {
        ADD_FAILURE() << "thread " << t << " threw a non-standard exception";
      }
    }
    EXPECT_EQ(report.mismatches, 0U)
        << "thread " << t << ": " << report.mismatches << " qualities of " << report.rounds
        << " rounds differ from the serial ones, first " << report.first_mismatch;
  }
}

TYPED_TEST_P(TwinConformance, QualityIsFiniteAndNonNegativeInsideTheBounds) {
  const MatrixX u = this->controls(5);
  for (const auto& assembly : this->assemblies()) {
    const VectorX from_batch = this->batch(assembly, u);
    const VectorX from_singles = this->singles(assembly, u);
    for (Index j = 0; j < u.cols(); ++j) {
      EXPECT_TRUE(std::isfinite(from_batch(j)) && from_batch(j) >= 0.0)
          << "control " << j << ": batch quality " << from_batch(j);
      EXPECT_TRUE(std::isfinite(from_singles(j)) && from_singles(j) >= 0.0)
          << "control " << j << ": quality " << from_singles(j);
    }
  }
}

TYPED_TEST_P(TwinConformance, WrongShapesThrowDimensionMismatchError) {
  const auto& twin = this->twin();
  const Index d = twin.control_dimension();
  const auto assembly = this->assemblies().front();
  EXPECT_THROW((void)twin.quality(assembly, VectorX::Zero(d + 1)), DimensionMismatchError);
  EXPECT_THROW((void)twin.quality(assembly, VectorX::Zero(d - 1)), DimensionMismatchError);
  VectorX out(2);
  EXPECT_THROW(twin.quality_batch(assembly, MatrixX::Zero(d + 1, 2), out), DimensionMismatchError);
  // Three admissible controls, room for two qualities.
  const MatrixX centre = (0.5 * (twin.lower_bounds() + twin.upper_bounds())).replicate(1, 3);
  EXPECT_THROW(twin.quality_batch(assembly, centre, out), DimensionMismatchError);
}

REGISTER_TYPED_TEST_SUITE_P(TwinConformance, NamesAndBoundsDescribeTheControls,
                            QualityEqualsTheBatchOfOneAndItsEntryInALargerBatch,
                            PermutingTheControlsPermutesTheQualities,
                            ConcurrentConstCallsGiveTheSerialResults,
                            QualityIsFiniteAndNonNegativeInsideTheBounds,
                            WrongShapesThrowDimensionMismatchError);

}  // namespace twincal::conformance
