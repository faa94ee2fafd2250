// SquareRootSigmaPointFilter: agreement with the reference runs (both update forms), the
// time update with negative weights, a near-singular case where the standard form fails and the
// square-root form does not, preview/commit, JSON save/restore and allocation-free steps.
#include "twincal/filters/square_root_sigma_point_filter.hpp"

#include <iostream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "allocation_counting.hpp"
#include "golden_runs.hpp"
#include "test_models.hpp"
#include "twincal/filters/fifth_degree_cubature_sigma_points.hpp"
#include "twincal/filters/sigma_point_filter.hpp"
#include "twincal/models/random_walk.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

template <int N, typename Scheme>
test_support::Agreement replay_square_root(const std::string& file, const nlohmann::json& run,
                                           const Scheme& scheme, SquareRootUpdate update) {
  using Filter = SquareRootSigmaPointFilter<RandomWalk<N>, QuadraticQualityMeasurement<N>, Scheme>;
  Filter filter(test_support::process_model<N>(run), test_support::measurement_model<N>(run),
                scheme, test_support::vector<N>(run["x0"]),
                SquareMatrix<N>(test_support::matrix<N, N>(run["P0"])),
                SquareRootFilterOptions{test_support::refresh_of(file, run), update});
  return test_support::replay(filter, run);
}

TEST(SquareRootSigmaPointFilterGolden, AgreesWithTheReferenceRunsInBothUpdateForms) {
  for (const std::string file : {"filter_runs_1.4.5.json", "filter_runs_master.json"}) {
    const nlohmann::json data = test_support::load(file);
    for (const SquareRootUpdate update : {SquareRootUpdate::joseph, SquareRootUpdate::downdate}) {
      const std::string form = update == SquareRootUpdate::joseph ? "joseph" : "downdate";
      double worst = 0.0;
      for (const nlohmann::json& run : data["runs"]) {
        const std::string context = test_support::describe(file, run) + " " + form;
        test_support::with_scheme(run, [&](const auto& scheme) {
          const test_support::Agreement a = replay_square_root<Dynamic>(file, run, scheme, update);
          a.expect_within(1e-8, context);
          worst = std::max(worst, a.worst().first);
          if (run["d"] == 3 && update == SquareRootUpdate::joseph) {
            replay_square_root<3>(file, run, scheme, update).expect_within(1e-8, context);
          }
        });
      }
      std::cout << "[ parity   ] square root (" << form << ") vs " << file
                << ": worst relative error " << worst << '\n';
    }
  }
}

// The fifth-degree rule has negative axis weights for n > 4: the time update then needs
// rank-one downdates after the QR. Both forms agree step by step.
TEST(SquareRootSigmaPointFilter, NegativeWeightsAgreeWithTheStandardForm) {
  const nlohmann::json data = test_support::load("filter_runs_master.json");
  const nlohmann::json& run = data["runs"][8];  // d = 6
  ASSERT_EQ(run["d"], 6);
  using Walk = RandomWalk<6>;
  using Quality = QuadraticQualityMeasurement<6>;
  const FifthDegreeCubatureSigmaPoints scheme;
  SigmaPointFilter<Walk, Quality, FifthDegreeCubatureSigmaPoints> standard(
      test_support::process_model<6>(run), test_support::measurement_model<6>(run), scheme,
      test_support::vector<6>(run["x0"]), test_support::matrix<6, 6>(run["P0"]),
      SigmaPointFilterOptions::filterpy(SigmaPointRefresh::redraw));
  SquareRootSigmaPointFilter<Walk, Quality, FifthDegreeCubatureSigmaPoints> square_root(
      test_support::process_model<6>(run), test_support::measurement_model<6>(run), scheme,
      test_support::vector<6>(run["x0"]), SquareMatrix<6>(test_support::matrix<6, 6>(run["P0"])));
  ASSERT_LT(standard.covariance_weights().minCoeff(), 0.0);
  test_support::Agreement agreement;
  for (std::size_t t = 0; t < run["steps"].size(); ++t) {
    const Quality::Inputs in{test_support::vector<6>(run["inputs"][t]["a"]),
                             test_support::vector<6>(run["inputs"][t]["u"])};
    standard.predict();
    square_root.predict();
    agreement.add("P_prior", square_root.covariance(), standard.covariance());
    standard.update(run["inputs"][t]["z"].get<double>(), in);
    square_root.update(run["inputs"][t]["z"].get<double>(), in);
    agreement.add("x", square_root.state(), standard.state());
    agreement.add("P", square_root.covariance(), standard.covariance());
  }
  agreement.expect_within(1e-8, "fifth degree, d = 6");
}

// --- near-singular covariances -----------------------------------------------------------------

// Dynamic size: GCC 12 reports a false -Warray-bounds in core's rank-one update at fixed size 2.
using Linear = test_support::LinearMeasurement<Dynamic>;
using Walk = RandomWalk<Dynamic>;
using SquareRoot = SquareRootSigmaPointFilter<Walk, Linear, SphericalRadialSigmaPoints>;
using Standard = SigmaPointFilter<Walk, Linear, SphericalRadialSigmaPoints>;

VectorX vec2(double a, double b) {
  VectorX v(2);
  v << a, b;
  return v;
}

// P = I, Q = 0, a measurement of x0 with R = 1e-20 < ε: the standard form's P − K S Kᵀ is
// singular in floating point (tested in sigma_point_filter_test); the Joseph square root keeps
// P⁺ positive definite with P⁺₀₀ of the order of R.
TEST(SquareRootSigmaPointFilter, StaysPositiveDefiniteWhereTheStandardFormFails) {
  const Linear precise{vec2(1.0, 0.0), 1e-20};
  Standard standard(Walk::isotropic(2, 0.0), precise, {}, VectorX(VectorX::Zero(2)),
                    MatrixX(MatrixX::Identity(2, 2)),
                    SigmaPointFilterOptions::filterpy(SigmaPointRefresh::redraw));
  standard.predict();
  EXPECT_THROW(standard.update(0.5, {}), NotPositiveDefiniteError);

  SquareRoot filter(Walk::isotropic(2, 0.0), precise, {}, VectorX(VectorX::Zero(2)),
                    MatrixX(MatrixX::Identity(2, 2)));
  for (int t = 0; t < 20; ++t) {
    filter.predict();
    filter.update(0.5, {});
    EXPECT_GT(filter.factor().diagonal().minCoeff(), 0.0) << "step " << t;
  }
  EXPECT_NEAR(filter.state()(0), 0.5, 1e-12);
  EXPECT_GT(filter.factor()(0, 0), 0.0);
  EXPECT_LT(filter.factor()(0, 0), 1e-7);  // √P⁺₀₀: of the order of √R plus round-off
  EXPECT_NEAR(filter.factor()(1, 1), 1.0, 1e-15);

  // The classic downdate computes 1 − K S Kᵀ/P₀₀ = 0 and reports it, leaving the state as it was.
  SquareRoot downdate(
      Walk::isotropic(2, 0.0), precise, {}, VectorX(VectorX::Zero(2)),
      MatrixX(MatrixX::Identity(2, 2)),
      SquareRootFilterOptions{SigmaPointRefresh::redraw, SquareRootUpdate::downdate});
  downdate.predict();
  const SquareRoot before = downdate;
  EXPECT_THAT([&] { downdate.update(0.5, {}); },
              ::testing::ThrowsMessage<NotPositiveDefiniteError>(HasSubstr("rank-one downdate")));
  EXPECT_EQ(downdate.factor(), before.factor());
  EXPECT_EQ(downdate.state(), before.state());
}

// A covariance whose smallest eigenvalue (1e-20) is below ε·λ_max exists only as a factor:
// formed as L Lᵀ it rounds to a singular matrix the standard form cannot start from.
TEST(SquareRootSigmaPointFilter, CarriesACovarianceTooIllConditionedToFormExplicitly) {
  MatrixX lower(2, 2);
  lower << 1.0, 0.0, 1.0, 1e-10;
  const Linear sum{vec2(1.0, 1.0), 1e-4};
  EXPECT_THROW(Standard(Walk::isotropic(2, 0.0), sum, {}, VectorX(VectorX::Zero(2)),
                        MatrixX(lower * lower.transpose())),
               NotPositiveDefiniteError);
  SquareRoot filter(Walk::isotropic(2, 0.0), sum, {}, VectorX(VectorX::Zero(2)),
                    CholeskyFactor<Dynamic>(lower));
  for (int t = 0; t < 10; ++t) {
    filter.predict();
    filter.update(0.1, {});
    EXPECT_GT(filter.factor().diagonal().minCoeff(), 0.0) << "step " << t;
  }
  // The direction (1, −1)/√2 kept its tiny variance, x0 + x1 was learned.
  const VectorX difference = vec2(1.0 / std::sqrt(2.0), -1.0 / std::sqrt(2.0));
  EXPECT_LT((filter.factor().transpose() * difference).norm(), 1e-9);
  EXPECT_NEAR(filter.state().sum(), 0.1, 1e-3);
}

// --- preview, commit, save and restore ---------------------------------------------------------

template <int N>
using SquareRootUkf = SquareRootSigmaPointFilter<RandomWalk<N>, QuadraticQualityMeasurement<N>,
                                                 MerweScaledSigmaPoints>;

template <int N>
SquareRootUkf<N> make_filter(SquareRootFilterOptions options = {SigmaPointRefresh::reuse_propagated,
                                                                SquareRootUpdate::joseph}) {
  const nlohmann::json data = test_support::load("filter_runs_1.4.5.json");
  const nlohmann::json& run = data["runs"][4];
  return SquareRootUkf<N>(test_support::process_model<N>(run),
                          test_support::measurement_model<N>(run),
                          MerweScaledSigmaPoints{0.1, 2.0, 0.0}, test_support::vector<N>(run["x0"]),
                          SquareMatrix<N>(test_support::matrix<N, N>(run["P0"])), options);
}

template <int N>
typename QuadraticQualityMeasurement<N>::Inputs inputs_at(int t) {
  Vector<N> a = Vector<N>::Constant(3, 0.1 * t);
  Vector<N> u = Vector<N>::Constant(3, 0.3);
  return {a, u};
}

TEST(SquareRootSigmaPointFilter, UpdateIsPreviewThenCommitAndStalePreviewsAreRejected) {
  SquareRootUkf<3> updated = make_filter<3>();
  SquareRootUkf<3> committed = make_filter<3>();
  for (int t = 0; t < 4; ++t) {
    updated.predict();
    committed.predict();
    updated.update(0.25, inputs_at<3>(t));
    const auto preview = committed.preview(inputs_at<3>(t));
    EXPECT_EQ(preview.posterior_covariance,
              preview.posterior_factor * preview.posterior_factor.transpose());
    committed.commit(preview, 0.25);
    EXPECT_EQ(updated.state(), committed.state());
    EXPECT_EQ(updated.factor(), committed.factor());
    EXPECT_EQ(updated.sigma_points(), committed.sigma_points());
  }
  EXPECT_EQ(committed.measurement_model().noise_variance(), 1e-4);
  EXPECT_EQ(committed.state_model().dimension(), 3);
  const auto stale = committed.preview(inputs_at<3>(0));
  committed.predict();
  EXPECT_THAT([&] { committed.commit(stale, 0.2); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  HasSubstr("preview: was computed at filter revision")));
}

TEST(SquareRootSigmaPointFilter, SaveRestoreRoundTripsBitExactly) {
  SquareRootUkf<Dynamic> original = make_filter<Dynamic>();
  for (int t = 0; t < 3; ++t) {
    original.predict();
    original.update(0.25, inputs_at<Dynamic>(t));
  }
  original.predict();
  SquareRootUkf<Dynamic> restored = make_filter<Dynamic>();
  restored.restore(nlohmann::json::parse(original.save().dump()));
  EXPECT_EQ(restored.state(), original.state());
  EXPECT_EQ(restored.factor(), original.factor());
  EXPECT_EQ(restored.sigma_points(), original.sigma_points());
  EXPECT_EQ(restored.update_count(), 3U);
  original.update(0.2, inputs_at<Dynamic>(5));
  restored.update(0.2, inputs_at<Dynamic>(5));
  EXPECT_EQ(restored.factor(), original.factor());

  nlohmann::json upper = original.save();
  upper["factor"][1][0] = 0.5;  // column 1, row 0: above the diagonal
  const SquareRootUkf<Dynamic> before = restored;
  EXPECT_THAT([&] { restored.restore(upper); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  HasSubstr("entry (0, 1) above the diagonal is 0.5")));
  EXPECT_EQ(restored.factor(), before.factor());
}

// --- allocation ------------------------------------------------------------------------------

// Predict + update allocate nothing after the first step at any size, in every refresh and
// update form (Merwe α = 0.1 has a negative centre weight, so predict's downdate runs too);
// a preview into a kept one allocates nothing at fixed size.
TEST(SquareRootSigmaPointFilter, StepsDoNotAllocateAfterTheFirstAtAnySize) {
  if (!test_support::counts_allocations()) {
    GTEST_SKIP() << "malloc is interposed by the sanitizer";
  }
  for (const SigmaPointRefresh refresh :
       {SigmaPointRefresh::redraw, SigmaPointRefresh::reuse_propagated}) {
    for (const SquareRootUpdate update : {SquareRootUpdate::joseph, SquareRootUpdate::downdate}) {
      const SquareRootFilterOptions options{refresh, update};
      SquareRootUkf<3> fixed = make_filter<3>(options);
      SquareRootUkf<Dynamic> dynamic = make_filter<Dynamic>(options);
      const auto fixed_inputs = inputs_at<3>(1);
      const auto dynamic_inputs = inputs_at<Dynamic>(1);
      fixed.predict();  // warm up
      fixed.update(0.25, fixed_inputs);
      dynamic.predict();
      dynamic.update(0.25, dynamic_inputs);
      auto kept = fixed.preview(fixed_inputs);
      EXPECT_EQ(test_support::allocations_in([&] {
                  for (int t = 0; t < 10; ++t) {
                    fixed.predict();
                    fixed.update(0.25 + 0.001 * t, fixed_inputs);
                    fixed.preview(fixed_inputs, kept);
                  }
                }),
                0);
      EXPECT_EQ(test_support::allocations_in([&] {
                  for (int t = 0; t < 10; ++t) {
                    dynamic.predict();
                    dynamic.update(0.25 + 0.001 * t, dynamic_inputs);
                  }
                }),
                0);
    }
  }
}

// A random walk whose Q the test changes between predicts.
struct AdjustableWalk {
  static constexpr int dimension_at_compile_time = Dynamic;
  const Eigen::MatrixXd* noise;
  [[nodiscard]] Index dimension() const { return noise->rows(); }
  [[nodiscard]] const Eigen::VectorXd& propagate(const Eigen::VectorXd& x) const { return x; }
  [[nodiscard]] const Eigen::MatrixXd& process_noise() const { return *noise; }
};

// √Q is cached between predicts; a Q that changes is factored again.
TEST(SquareRootSigmaPointFilter, RefactorsTheProcessNoiseWhenItChanges) {
  using Filter = SquareRootSigmaPointFilter<AdjustableWalk, QuadraticQualityMeasurement<Dynamic>,
                                            MerweScaledSigmaPoints>;
  Eigen::MatrixXd cached = 1e-3 * Eigen::MatrixXd::Identity(3, 3);
  Eigen::MatrixXd fresh = cached;
  const QuadraticQualityMeasurement<Dynamic> measurement(Eigen::MatrixXd::Identity(3, 3), 0.04,
                                                         1e-4);
  const Eigen::VectorXd x0 = Eigen::Vector3d(0.01, -0.02, 0.005);
  const Eigen::MatrixXd p0 = 2e-3 * Eigen::MatrixXd::Identity(3, 3);
  Filter a(AdjustableWalk{&cached}, measurement, MerweScaledSigmaPoints{0.5, 2.0, 0.0}, x0, p0);
  Filter b(AdjustableWalk{&fresh}, measurement, MerweScaledSigmaPoints{0.5, 2.0, 0.0}, x0, p0);
  const nlohmann::json start = a.save();
  a.predict();  // factors √Q of the first Q and keeps it
  const Eigen::MatrixXd with_first_noise = a.factor();
  a.restore(start);
  for (Eigen::MatrixXd* q : {&cached, &fresh}) {
    (*q)(1, 1) = 5e-3;
    (*q)(0, 1) = (*q)(1, 0) = 1e-3;
  }
  a.predict();
  b.predict();
  EXPECT_EQ(a.factor(), b.factor());
  EXPECT_NE(a.factor(), with_first_noise);
}

}  // namespace
}  // namespace twincal
