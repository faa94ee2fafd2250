// Compile-time checks of the filters module's concepts: StateModel, MeasurementModel (with and
// without the batch hook), SigmaPointScheme, and the constraints of SigmaPointFilter.
#include <optional>

#include "twincal/filters/filters.hpp"
#include "twincal/models/random_walk.hpp"

namespace twincal::static_checks {

// --- StateModel ----------------------------------------------------------------------------------
struct WalkWithoutNoise {
  static constexpr int dimension_at_compile_time = 2;
  [[nodiscard]] Index dimension() const { return 2; }
  [[nodiscard]] Vector<2> propagate(const Vector<2>& x) const { return x; }
};
struct WalkWithWrongSize {  // propagates into another dimension
  static constexpr int dimension_at_compile_time = 2;
  [[nodiscard]] Index dimension() const { return 2; }
  [[nodiscard]] Vector<3> propagate(const Vector<2>&) const { return Vector<3>::Zero(); }
  [[nodiscard]] SquareMatrix<2> process_noise() const { return SquareMatrix<2>::Identity(); }
};
static_assert(StateModel<RandomWalk<3>>);
static_assert(StateModel<RandomWalk<Dynamic>>);
static_assert(!StateModel<WalkWithoutNoise>);
static_assert(!StateModel<WalkWithWrongSize>);
static_assert(!StateModel<int>);

// --- MeasurementModel ----------------------------------------------------------------------------
struct MeasurementWithoutInputs {
  static constexpr int dimension_at_compile_time = 2;
  [[nodiscard]] double measure(const Vector<2>&) const { return 0.0; }
  [[nodiscard]] double noise_variance() const { return 1.0; }
};
struct MeasurementWithoutNoise {
  static constexpr int dimension_at_compile_time = 2;
  struct Inputs {};
  [[nodiscard]] double measure(const Vector<2>&, const Inputs&) const { return 0.0; }
};
struct MutableMeasurement {  // measure must be callable on a const model
  static constexpr int dimension_at_compile_time = 2;
  struct Inputs {};
  double measure(const Vector<2>&, const Inputs&) { return 0.0; }
  [[nodiscard]] double noise_variance() const { return 1.0; }
};
static_assert(MeasurementModel<QuadraticQualityMeasurement<3>>);
static_assert(BatchMeasurementModel<QuadraticQualityMeasurement<Dynamic>>);
static_assert(MeasurementModel<MeasurementWithoutNoise> == false);
static_assert(!MeasurementModel<MeasurementWithoutInputs>);
static_assert(!MeasurementModel<MutableMeasurement>);
struct ScalarOnly {
  static constexpr int dimension_at_compile_time = 2;
  struct Inputs {};
  [[nodiscard]] double measure(const Vector<2>&, const Inputs&) const { return 0.0; }
  [[nodiscard]] double noise_variance() const { return 1.0; }
};
static_assert(MeasurementModel<ScalarOnly> && !BatchMeasurementModel<ScalarOnly>);

// --- SigmaPointScheme ----------------------------------------------------------------------------
static_assert(SigmaPointScheme<MerweScaledSigmaPoints>);
static_assert(SigmaPointScheme<JulierSigmaPoints>);
static_assert(SigmaPointScheme<SimplexSigmaPoints>);
static_assert(SigmaPointScheme<SphericalRadialSigmaPoints>);
static_assert(SigmaPointScheme<FifthDegreeCubatureSigmaPoints>);
struct SchemeWithoutDegree {
  static constexpr int points_at_compile_time(int n) { return size_sum(n, 1); }
  static constexpr bool is_symmetric = false;
  [[nodiscard]] Index num_points(Index n) const { return n + 1; }
  void weights(Index, Eigen::Ref<VectorX>, Eigen::Ref<VectorX>) const {}
  template <typename A, typename B, typename C>
  void generate(const Eigen::MatrixBase<A>&, const Eigen::MatrixBase<B>&,
                Eigen::MatrixBase<C>&) const {}
};
static_assert(!SigmaPointScheme<SchemeWithoutDegree>);
static_assert(MerweScaledSigmaPoints::points_at_compile_time(3) == 7);
static_assert(SphericalRadialSigmaPoints::points_at_compile_time(3) == 6);
static_assert(SimplexSigmaPoints::points_at_compile_time(3) == 4);
static_assert(FifthDegreeCubatureSigmaPoints::points_at_compile_time(3) == 19);
static_assert(FifthDegreeCubatureSigmaPoints::points_at_compile_time(Dynamic) == Dynamic);
// Merwe's α, β, κ have no defaults.
static_assert(!std::is_default_constructible_v<MerweScaledSigmaPoints>);
static_assert(!std::is_default_constructible_v<JulierSigmaPoints>);

// --- the filter's constraints --------------------------------------------------------------------
template <typename SM, typename MM, typename S>
concept FilterInstantiable = requires {
  typename SigmaPointFilter<SM, MM, S>;
};
static_assert(
    FilterInstantiable<RandomWalk<3>, QuadraticQualityMeasurement<3>, MerweScaledSigmaPoints>);
static_assert(
    !FilterInstantiable<RandomWalk<2>, QuadraticQualityMeasurement<3>, MerweScaledSigmaPoints>);
static_assert(!FilterInstantiable<RandomWalk<3>, QuadraticQualityMeasurement<3>, int>);
static_assert(std::is_same_v<UnscentedKalmanFilter<RandomWalk<3>, QuadraticQualityMeasurement<3>>,
                             SigmaPointFilter<RandomWalk<3>, QuadraticQualityMeasurement<3>,
                                              MerweScaledSigmaPoints>>);
static_assert(
    CubatureKalmanFilter<RandomWalk<3>, QuadraticQualityMeasurement<3>>::points_at_compile_time ==
    6);
static_assert(ValidatableOptions<SigmaPointFilterOptions>);
static_assert(ValidatableOptions<SquareRootFilterOptions>);

}  // namespace twincal::static_checks
