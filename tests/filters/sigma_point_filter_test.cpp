// SigmaPointFilter: filterpy parity on every stored run (both releases' sigma-point policies, the
// UKF's Merwe and Julier points, the CKF), preview/commit, evaluation counts, the strong
// guarantee, the safeguards, JSON save/restore and allocation-free steps.
#include "twincal/filters/sigma_point_filter.hpp"

#include <iostream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "allocation_counting.hpp"
#include "golden_runs.hpp"
#include "test_models.hpp"
#include "twincal/filters/cubature_kalman_filter.hpp"
#include "twincal/filters/fifth_degree_cubature_sigma_points.hpp"
#include "twincal/filters/unscented_kalman_filter.hpp"
#include "twincal/models/random_walk.hpp"

namespace twincal {
namespace {

using ::testing::HasSubstr;

// --- filterpy parity -------------------------------------------------------------------------

template <int N, typename Scheme>
test_support::Agreement replay_standard(const std::string& file, const nlohmann::json& run,
                                        const Scheme& scheme) {
  using Filter = SigmaPointFilter<RandomWalk<N>, QuadraticQualityMeasurement<N>, Scheme>;
  Filter filter(test_support::process_model<N>(run), test_support::measurement_model<N>(run),
                scheme, test_support::vector<N>(run["x0"]), test_support::matrix<N, N>(run["P0"]),
                SigmaPointFilterOptions::filterpy(test_support::refresh_of(file, run)));
  return test_support::replay(filter, run);
}

TEST(SigmaPointFilterGolden, ReproducesEveryStoredNumberOfBothFilterpyReleases) {
  for (const std::string file : {"filter_runs_1.4.5.json", "filter_runs_master.json"}) {
    const nlohmann::json data = test_support::load(file);
    double worst = 0.0;
    std::string worst_where;
    for (const nlohmann::json& run : data["runs"]) {
      const std::string context = test_support::describe(file, run);
      test_support::with_scheme(run, [&](const auto& scheme) {
        const test_support::Agreement dynamic = replay_standard<Dynamic>(file, run, scheme);
        dynamic.expect_within(1e-9, context + " (Dynamic)");
        if (dynamic.worst().first >= worst) {
          worst = dynamic.worst().first;
          worst_where = context + " " + dynamic.worst().second;
        }
        if (run["d"] == 3) {  // the fixed-size path gives the same numbers
          replay_standard<3>(file, run, scheme).expect_within(1e-9, context + " (fixed 3)");
        }
      });
    }
    std::cout << "[ parity   ] " << file << ": worst relative error " << worst << " ("
              << worst_where << ")\n";
  }
}

// --- a filter for the behavioural tests, fixed size and Dynamic --------------------------------

template <int N>
using Ukf = UnscentedKalmanFilter<RandomWalk<N>, QuadraticQualityMeasurement<N>>;

template <int N>
Ukf<N> make_ukf(SigmaPointFilterOptions options = {}) {
  SquareMatrix<N> h(3, 3);
  h << 1.0, 0.2, 0.0, 0.2, 0.8, 0.1, 0.0, 0.1, 0.5;
  SquareMatrix<N> p0(3, 3);
  p0 << 2e-3, 1e-4, 0.0, 1e-4, 1e-3, -2e-4, 0.0, -2e-4, 1.5e-3;
  Vector<N> x0(3);
  x0 << 0.01, -0.02, 0.005;
  return Ukf<N>(RandomWalk<N>::isotropic(3, 1e-3), QuadraticQualityMeasurement<N>(h, 0.04, 1e-4),
                MerweScaledSigmaPoints{0.5, 2.0, 0.0}, x0, p0, options);
}

template <int N>
typename QuadraticQualityMeasurement<N>::Inputs make_inputs(double shift) {
  Vector<N> a(3);
  a << 0.3, -0.1, 0.2;
  Vector<N> u(3);
  u << 0.25 + shift, -0.05, 0.1 - shift;
  return {a, u};
}

template <typename Filter>
void expect_identical(const Filter& a, const Filter& b) {
  EXPECT_EQ(a.state(), b.state());
  EXPECT_EQ(a.covariance(), b.covariance());
  EXPECT_EQ(a.sigma_points(), b.sigma_points());
  EXPECT_EQ(a.update_count(), b.update_count());
  EXPECT_EQ(a.last_update().innovation, b.last_update().innovation);
  EXPECT_EQ(a.last_update().gain, b.last_update().gain);
  EXPECT_EQ(a.last_update().log_likelihood(), b.last_update().log_likelihood());
}

template <typename Filter>
void expect_unchanged(const Filter& filter, const Filter& before) {
  expect_identical(filter, before);
  EXPECT_EQ(filter.revision(), before.revision());
}

template <typename Size>
class SigmaPointFilterTest : public ::testing::Test {};
using FilterDimensions =
    ::testing::Types<std::integral_constant<int, 3>, std::integral_constant<int, Dynamic>>;
TYPED_TEST_SUITE(SigmaPointFilterTest, FilterDimensions);

TYPED_TEST(SigmaPointFilterTest, UpdateIsPreviewThenCommit) {
  constexpr int N = TypeParam::value;
  Ukf<N> updated = make_ukf<N>();
  Ukf<N> committed = make_ukf<N>();
  for (int t = 0; t < 5; ++t) {
    const auto inputs = make_inputs<N>(0.01 * t);
    const double z = 0.2 + 0.003 * t;
    updated.predict();
    committed.predict();
    updated.update(z, inputs);
    committed.commit(committed.preview(inputs), z);
    expect_identical(updated, committed);
  }
  EXPECT_EQ(updated.update_count(), 5U);
}

TYPED_TEST(SigmaPointFilterTest, PreviewChangesNothingAndEqualsTheUpdate) {
  constexpr int N = TypeParam::value;
  Ukf<N> filter = make_ukf<N>();
  filter.predict();
  const Ukf<N> before = filter;
  const auto inputs = make_inputs<N>(0.02);
  const typename Ukf<N>::Preview preview = filter.preview(inputs);
  expect_unchanged(filter, before);

  // The controller's path: its own batch of values at sigma_points() gives the same preview.
  Vector<Ukf<N>::points_at_compile_time> values(filter.num_points());
  for (Index i = 0; i < filter.num_points(); ++i) {
    values(i) = filter.measurement_model().measure(filter.sigma_points().col(i), inputs);
  }
  const typename Ukf<N>::Preview external = filter.preview(values);
  EXPECT_EQ(external.measurements, preview.measurements);
  EXPECT_EQ(external.posterior_covariance, preview.posterior_covariance);
  EXPECT_EQ(external.gain, preview.gain);
  EXPECT_EQ(external.innovation_variance, preview.innovation_variance);

  filter.commit(preview, 0.21);
  EXPECT_EQ(filter.covariance(), preview.posterior_covariance);
  EXPECT_EQ(filter.last_update().innovation_variance, preview.innovation_variance);
  EXPECT_EQ(filter.last_update().innovation, 0.21 - preview.predicted_measurement);
  EXPECT_DOUBLE_EQ(preview.innovation_variance, preview.measurement_variance + 1e-4);
}

TYPED_TEST(SigmaPointFilterTest, RejectsAStalePreview) {
  constexpr int N = TypeParam::value;
  Ukf<N> filter = make_ukf<N>();
  const auto preview = filter.preview(make_inputs<N>(0.0));
  filter.predict();
  const Ukf<N> before = filter;
  try {
    filter.commit(preview, 0.2);
    FAIL() << "no throw";
  } catch (const InvalidArgumentError& e) {
    EXPECT_EQ(e.argument(), "preview");
    EXPECT_THAT(e.what(), HasSubstr("preview: was computed at filter revision 0, the filter is "
                                    "at revision 1; rule: commit only a preview of the current "
                                    "state"));
  }
  expect_unchanged(filter, before);
}

TYPED_TEST(SigmaPointFilterTest, NonFiniteMeasurementOrValuesLeaveTheFilterUnchanged) {
  constexpr int N = TypeParam::value;
  Ukf<N> filter = make_ukf<N>();
  filter.predict();
  const Ukf<N> before = filter;
  try {
    filter.update(std::nan(""), make_inputs<N>(0.0));
    FAIL() << "no throw";
  } catch (const NonFiniteError& e) {
    EXPECT_EQ(e.argument(), "z");
    EXPECT_THAT(e.what(), HasSubstr("z: value is nan; rule: must be finite"));
  }
  expect_unchanged(filter, before);

  Vector<Ukf<N>::points_at_compile_time> values =
      Vector<Ukf<N>::points_at_compile_time>::Constant(filter.num_points(), 0.2);
  values(2) = std::numeric_limits<double>::infinity();
  try {
    (void)filter.preview(values);
    FAIL() << "no throw";
  } catch (const NonFiniteError& e) {
    EXPECT_THAT(e.what(), HasSubstr("measurements: value at sigma point 2 is inf; rule: the "
                                    "measurement function must return finite values"));
  }
  try {
    (void)filter.preview(VectorX::Constant(filter.num_points() + 1, 0.2));
    FAIL() << "no throw";
  } catch (const DimensionMismatchError& e) {
    EXPECT_THAT(e.what(), HasSubstr("measurements: size is 8; rule: must equal 7"));
  }
  expect_unchanged(filter, before);
}

TYPED_TEST(SigmaPointFilterTest, SaveRestoreRoundTripsBitExactly) {
  constexpr int N = TypeParam::value;
  SigmaPointFilterOptions options;
  options.refresh = SigmaPointRefresh::reuse_propagated;  // points are state beyond (x, P)
  Ukf<N> original = make_ukf<N>(options);
  for (int t = 0; t < 3; ++t) {
    original.predict();
    original.update(0.2 + 0.01 * t, make_inputs<N>(0.01 * t));
  }
  original.predict();
  const std::string text = original.save().dump();

  Ukf<N> restored = make_ukf<N>(options);
  restored.restore(nlohmann::json::parse(text));
  EXPECT_EQ(restored.state(), original.state());
  EXPECT_EQ(restored.covariance(), original.covariance());
  EXPECT_EQ(restored.sigma_points(), original.sigma_points());
  EXPECT_EQ(restored.update_count(), 3U);

  original.update(0.23, make_inputs<N>(0.05));
  restored.update(0.23, make_inputs<N>(0.05));
  EXPECT_EQ(restored.state(), original.state());
  EXPECT_EQ(restored.covariance(), original.covariance());
}

TYPED_TEST(SigmaPointFilterTest, RestoreRejectsForeignOrBrokenStatesAndKeepsItsOwn) {
  constexpr int N = TypeParam::value;
  Ukf<N> filter = make_ukf<N>();
  filter.predict();
  const Ukf<N> before = filter;
  nlohmann::json saved = filter.save();

  nlohmann::json foreign = saved;
  foreign["format"] = "something else";
  EXPECT_THAT([&] { filter.restore(foreign); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  HasSubstr("format: is \"something else\"; rule: must be "
                            "\"twincal.sigma_point_filter\"")));
  nlohmann::json broken = saved;
  broken["state"][1] = nullptr;  // what a NaN becomes in JSON
  EXPECT_THAT([&] { filter.restore(broken); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  HasSubstr("state[1]: is null (null); rule: must be a number")));
  nlohmann::json indefinite = saved;
  indefinite["covariance"][0][0] = -1.0;
  EXPECT_THROW(filter.restore(indefinite), NotPositiveDefiniteError);
  nlohmann::json missing = saved;
  missing.erase("sigma_points");
  EXPECT_THAT([&] { filter.restore(missing); }, ::testing::ThrowsMessage<InvalidArgumentError>(
                                                    HasSubstr("sigma_points: field is missing")));
  nlohmann::json larger = saved;
  larger["dimension"] = 4;
  EXPECT_THAT([&] { filter.restore(larger); },
              ::testing::ThrowsMessage<DimensionMismatchError>(
                  HasSubstr("dimension: size is 4; rule: must equal 3")));
  expect_unchanged(filter, before);
}

// --- evaluations -----------------------------------------------------------------------------

template <typename Scheme, bool batch>
void expect_one_evaluation_per_sigma_point(const Scheme& scheme) {
  using Measurement = test_support::CountingMeasurement<3, batch>;
  EvaluationCounter counter;
  SigmaPointFilter<RandomWalk<3>, Measurement, Scheme> filter(
      RandomWalk<3>::isotropic(3, 1e-3),
      Measurement{QuadraticQualityMeasurement<3>(Eigen::Matrix3d::Identity(), 0.04, 1e-4),
                  &counter},
      scheme, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity() * 1e-3);
  const Eigen::Vector3d a(0.3, -0.1, 0.2);
  const Eigen::Vector3d u(0.25, 0.0, 0.1);
  for (int t = 0; t < 4; ++t) {
    filter.predict();
    const EvaluationStats before = counter.stats();
    filter.update(0.2, {a, u});
    const EvaluationStats step = counter.stats() - before;
    EXPECT_EQ(step.evaluations, static_cast<std::uint64_t>(filter.num_points()));
    EXPECT_EQ(step.calls, batch ? 1U : static_cast<std::uint64_t>(filter.num_points()));
  }
  // A preview evaluates as much as an update; its commit evaluates nothing.
  filter.predict();
  const EvaluationStats before = counter.stats();
  const auto preview = filter.preview({a, u});
  filter.commit(preview, 0.2);
  EXPECT_EQ((counter.stats() - before).evaluations,
            static_cast<std::uint64_t>(filter.num_points()));
}

TEST(SigmaPointFilter, EvaluatesTheMeasurementOncePerSigmaPoint) {
  expect_one_evaluation_per_sigma_point<MerweScaledSigmaPoints, false>({0.1, 2.0, 0.0});
  expect_one_evaluation_per_sigma_point<MerweScaledSigmaPoints, true>({0.1, 2.0, 0.0});
  expect_one_evaluation_per_sigma_point<SphericalRadialSigmaPoints, true>({});
  expect_one_evaluation_per_sigma_point<FifthDegreeCubatureSigmaPoints, false>({});
}

// --- construction and models -------------------------------------------------------------------

TEST(SigmaPointFilter, ConstructorNamesWhatIsWrong) {
  const auto walk = RandomWalk<Dynamic>::isotropic(2, 1e-3);
  const QuadraticQualityMeasurement<Dynamic> quality(MatrixX::Identity(2, 2), 0.04, 1e-4);
  const VectorX x0 = VectorX::Zero(2);
  const auto make = [&](const MatrixX& p0, SigmaPointFilterOptions options = {}) {
    return Ukf<Dynamic>(walk, quality, MerweScaledSigmaPoints{0.1, 2.0, 0.0}, x0, p0, options);
  };
  MatrixX indefinite(2, 2);
  indefinite << 1.0, 2.0, 2.0, 1.0;
  EXPECT_THAT([&] { (void)make(indefinite); },
              ::testing::ThrowsMessage<NotPositiveDefiniteError>(
                  HasSubstr("initial_covariance: Cholesky factorization failed (repair policy: "
                            "none): smallest eigenvalue is -1")));
  MatrixX asymmetric(2, 2);
  asymmetric << 1.0, 0.5, 0.0, 1.0;
  EXPECT_THAT([&] { (void)make(asymmetric); },
              ::testing::ThrowsMessage<InvalidArgumentError>(
                  HasSubstr("initial_covariance: relative asymmetry")));
  EXPECT_THAT([&] { (void)make(MatrixX::Identity(3, 3)); },
              ::testing::ThrowsMessage<DimensionMismatchError>(
                  HasSubstr("initial_covariance: is 3x3; rule: must be 2x2")));
  SigmaPointFilterOptions bad;
  bad.factorization.jitter_growth = 0.5;
  EXPECT_THAT(
      [&] { (void)make(MatrixX::Identity(2, 2), bad); },
      ::testing::ThrowsMessage<InvalidArgumentError>(HasSubstr(
          "options: factorization.jitter_growth: value is 0.5; rule: must be finite and > 1")));
  EXPECT_THAT(
      [&] {
        (void)Ukf<Dynamic>(walk, quality, MerweScaledSigmaPoints(1.0, 2.0, -2.0), x0,
                           MatrixX::Identity(2, 2));
      },
      ::testing::ThrowsMessage<InvalidArgumentError>(
          HasSubstr("kappa: n + kappa is 0 (n = 2, kappa = -2)")));
  EXPECT_THAT(
      [&] {
        (void)Ukf<Dynamic>(
            walk, QuadraticQualityMeasurement<Dynamic>(MatrixX::Identity(3, 3), 0.04, 1e-4),
            MerweScaledSigmaPoints(1.0, 2.0, 0.0), x0, MatrixX::Identity(2, 2));
      },
      ::testing::ThrowsMessage<DimensionMismatchError>(
          HasSubstr("measurement_model.dimension(): size is 3; rule: must equal 2")));
}

TEST(SigmaPointFilter, NonFiniteModelOutputsLeaveTheFilterUnchanged) {
  using Walk = test_support::ExplodingWalk<2>;
  using Nan = test_support::NanAboveThreshold<2>;
  SigmaPointFilter<Walk, Nan, SphericalRadialSigmaPoints> filter(
      Walk{Eigen::Matrix2d::Identity() * 1e-3}, Nan{0.5}, {}, Eigen::Vector2d(0.4, 0.0),
      Eigen::Matrix2d::Identity() * 0.01);
  const auto before = filter;
  EXPECT_THAT([&] { filter.predict(); },
              ::testing::ThrowsMessage<NonFiniteError>(HasSubstr(
                  "propagated sigma points: entry 0 of sigma point 0 is nan; rule: the state "
                  "model must return finite states")));
  // Points 0.4 ± √2·0.1: the first, 0.541, is above the threshold.
  EXPECT_THAT([&] { filter.update(0.4, {}); }, ::testing::ThrowsMessage<NonFiniteError>(HasSubstr(
                                                   "measurements: value at sigma point 0 is nan")));
  expect_unchanged(filter, before);
}

// --- safeguards: a near-singular update ----------------------------------------------------------
// P = I, Q = 0 and a measurement of x0 with R = 1e-20: S = 1 + R rounds to 1, so P − K S Kᵀ loses
// R completely and P⁺ is singular in floating point.

using NearSingular =
    SigmaPointFilter<RandomWalk<2>, test_support::LinearMeasurement<2>, SphericalRadialSigmaPoints>;

NearSingular near_singular(SigmaPointFilterOptions options) {
  return NearSingular(RandomWalk<2>::isotropic(2, 0.0),
                      test_support::LinearMeasurement<2>{Eigen::Vector2d(1.0, 0.0), 1e-20}, {},
                      Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity(), options);
}

TEST(SigmaPointFilterSafeguards, PlainFormReportsTheLostDefiniteness) {
  NearSingular filter = near_singular(SigmaPointFilterOptions::filterpy(SigmaPointRefresh::redraw));
  filter.predict();
  const NearSingular before = filter;
  EXPECT_THAT([&] { filter.update(0.5, {}); },
              ::testing::ThrowsMessage<NotPositiveDefiniteError>(HasSubstr(
                  "posterior covariance: Cholesky factorization failed (repair policy: none)")));
  expect_unchanged(filter, before);
}

TEST(SigmaPointFilterSafeguards, JitterRepairsAndReportsIt) {
  SigmaPointFilterOptions options;
  options.factorization.repair = CovarianceRepair::jitter;
  NearSingular filter = near_singular(options);
  filter.predict();
  const auto preview = filter.preview(test_support::LinearMeasurement<2>::Inputs{});
  EXPECT_EQ(preview.factorization.applied, CovarianceRepair::jitter);
  EXPECT_GT(preview.factorization.jitter, 0.0);
  filter.commit(preview, 0.5);
  EXPECT_GT(filter.covariance()(0, 0), 0.0);
  EXPECT_EQ(filter.covariance(), preview.posterior_covariance);  // P and its points agree
}

TEST(SigmaPointFilterSafeguards, JosephFormStaysPositiveDefinite) {
  SigmaPointFilterOptions options;
  options.joseph_form = true;
  NearSingular filter = near_singular(options);
  filter.predict();
  filter.update(0.5, {});
  EXPECT_NEAR(filter.state()(0), 0.5, 1e-12);
  EXPECT_GT(smallest_eigenvalue(filter.covariance()), 0.0);
  EXPECT_LT(filter.covariance()(0, 0), 1e-14);  // of the order of R plus round-off
  EXPECT_NEAR(filter.covariance()(1, 1), 1.0, 1e-15);
}

TEST(SigmaPointFilterSafeguards, JosephFormAndSymmetrizationAgreeWithThePlainForm) {
  const nlohmann::json data = test_support::load("filter_runs_master.json");
  const nlohmann::json& run = data["runs"][4];  // UKF, Merwe α = 0.1, d = 3
  ASSERT_EQ(run["d"], 3);
  const std::string file = "filter_runs_master.json";
  for (const bool joseph : {false, true}) {
    SigmaPointFilterOptions options;
    options.joseph_form = joseph;
    options.symmetrize = true;
    Ukf<3> filter(test_support::process_model<3>(run), test_support::measurement_model<3>(run),
                  MerweScaledSigmaPoints{0.1, 2.0, 0.0}, test_support::vector<3>(run["x0"]),
                  test_support::matrix<3, 3>(run["P0"]), options);
    test_support::replay(filter, run).expect_within(1e-9, joseph ? "joseph" : "symmetrized");
    EXPECT_EQ(filter.covariance(), filter.covariance().transpose());
  }
}

// --- allocation ------------------------------------------------------------------------------

// Allocations in 10 predict + update steps after a first one, and (with_previews) in a preview
// into a kept one after each: a controller's loop over candidates.
template <typename Filter, typename Inputs>
long allocations_in_steps(Filter& filter, const Inputs& inputs, bool with_previews = true) {
  filter.predict();  // warm up
  filter.update(0.2, inputs);
  typename Filter::Preview kept = filter.preview(inputs);
  return test_support::allocations_in([&] {
    for (int t = 0; t < 10; ++t) {
      filter.predict();
      filter.update(0.2 + 0.001 * t, inputs);
      if (with_previews) filter.preview(inputs, kept);
    }
  });
}

TEST(SigmaPointFilter, StepsDoNotAllocateAfterTheFirstAtAnySize) {
  if (!test_support::counts_allocations()) GTEST_SKIP() << "malloc is interposed by the sanitizer";
  SigmaPointFilterOptions reuse;
  reuse.refresh = SigmaPointRefresh::reuse_propagated;
  SigmaPointFilterOptions joseph;
  joseph.joseph_form = true;
  const auto fixed_inputs = make_inputs<3>(0.01);
  const auto dynamic_inputs = make_inputs<Dynamic>(0.01);
  for (const SigmaPointFilterOptions& options : {SigmaPointFilterOptions{}, reuse}) {
    Ukf<3> fixed = make_ukf<3>(options);
    EXPECT_EQ(allocations_in_steps(fixed, fixed_inputs), 0);
    Ukf<Dynamic> dynamic = make_ukf<Dynamic>(options);
    EXPECT_EQ(allocations_in_steps(dynamic, dynamic_inputs), 0);
  }
  Ukf<3> fixed_joseph = make_ukf<3>(joseph);
  EXPECT_EQ(allocations_in_steps(fixed_joseph, fixed_inputs), 0);
  // The Joseph form's steps work in the filter's buffers at Dynamic size too; a const preview
  // has none of its own, and the counter sees it size its scratch.
  Ukf<Dynamic> dynamic_joseph = make_ukf<Dynamic>(joseph);
  EXPECT_EQ(allocations_in_steps(dynamic_joseph, dynamic_inputs, /*with_previews=*/false), 0);
  EXPECT_GT(allocations_in_steps(dynamic_joseph, dynamic_inputs), 0);
}

// cholesky() validates its options on every call (a controller factors P per step, a log-det
// loss per candidate): options that pass must not allocate the sentence of a rule they keep.
TEST(SigmaPointFilterOptions, OptionsThatPassValidateWithoutAllocating) {
  if (!test_support::counts_allocations()) GTEST_SKIP() << "malloc is interposed by the sanitizer";
  bool valid = true;
  EXPECT_EQ(test_support::allocations_in([&] {
              valid = !CholeskyOptions{}.validate() && !SigmaPointFilterOptions{}.validate();
            }),
            0);
  EXPECT_TRUE(valid);
  // The counter sees a broken rule's sentence, so the zero above is not for want of counting.
  EXPECT_GT(test_support::allocations_in(
                [&] { valid = !CholeskyOptions{.jitter_growth = 0.5}.validate(); }),
            0);
  EXPECT_FALSE(valid);
}

}  // namespace
}  // namespace twincal
