// twincal's UKF and square-root UKF against mherb/kalman's (github.com/mherb/kalman) on the same
// problem: a random
// walk (Q = 1e-3·I) measured by z = sqrt(q0 + eᵀHe), e = u − a − x, whose sensor inputs (a, u)
// cycle through 16 positions and z through 61 values; Merwe α = 1, β = 2, κ = 0; one
// predict + update per iteration.
// Built only when TWINCAL_COMPARE_MHERB_KALMAN_DIR names a checkout of mherb/kalman (its include/
// directory is used; nothing of it is vendored). Both libraries give the same estimates (checked
// once per benchmark before timing), so the difference is overhead.
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <kalman/MeasurementModel.hpp>
#include <kalman/SquareRootUnscentedKalmanFilter.hpp>
#include <kalman/SystemModel.hpp>
#include <kalman/UnscentedKalmanFilter.hpp>

#include "twincal/filters/merwe_scaled_sigma_points.hpp"
#include "twincal/filters/quadratic_quality_measurement.hpp"
#include "twincal/filters/sigma_point_filter.hpp"
#include "twincal/filters/square_root_sigma_point_filter.hpp"

namespace twincal::benchmarks {
namespace {

constexpr int positions = 16;
constexpr double offset = 0.04;
constexpr double measurement_variance = 1e-4;
constexpr double process_variance = 1e-3;

// The 16 sensor positions: deterministic, spread over [-0.3, 0.3] per coordinate.
template <int N>
std::array<typename QuadraticQualityMeasurement<N>::Inputs, positions> sensor_positions() {
  std::array<typename QuadraticQualityMeasurement<N>::Inputs, positions> inputs;
  for (int k = 0; k < positions; ++k) {
    Vector<N> a(N);
    Vector<N> u(N);
    for (int i = 0; i < N; ++i) {
      a(i) = 0.3 * std::sin(0.7 * (k + 1) + 1.3 * i);
      u(i) = 0.3 * std::cos(1.1 * (k + 1) - 0.4 * i);
    }
    inputs[static_cast<std::size_t>(k)] = {a, u};
  }
  return inputs;
}

// z_k: a plausible sequence, the same for both, read from a table made before timing. A sin()
// per step inside the timed loop cost 4–12 ns of libm time that overlapped differently with the
// two libraries' code (twincal's n = 1 and 3 ratios were 0.06–0.10 higher with it). 61 is prime,
// so the (position, z) pairs repeat only every 976 steps.
constexpr int measurement_period = 61;

double measured(int k) {
  static const std::array<double, measurement_period> table = [] {
    std::array<double, measurement_period> values{};
    for (std::size_t i = 0; i < values.size(); ++i) {
      values[i] = 0.25 + 0.01 * std::sin(0.37 * static_cast<double>(i));
    }
    return values;
  }();
  return table[static_cast<std::size_t>(k % measurement_period)];
}

// --- mherb/kalman's side ---------------------------------------------------------------------
template <int N>
struct State : Kalman::Vector<double, N> {
  KALMAN_VECTOR(State, double, N)
};
struct NoControl : Kalman::Vector<double, 1> {
  KALMAN_VECTOR(NoControl, double, 1)
};
struct Quality : Kalman::Vector<double, 1> {
  KALMAN_VECTOR(Quality, double, 1)
};

template <int N, template <class> class Base = Kalman::StandardBase>
class Walk : public Kalman::SystemModel<State<N>, NoControl, Base> {
 public:
  Walk() {
    if constexpr (std::is_same_v<Base<State<N>>, Kalman::StandardBase<State<N>>>) {
      this->setCovariance(Kalman::Covariance<State<N>>::Identity() * process_variance);
    } else {
      this->setCovarianceSquareRoot(Kalman::Covariance<State<N>>::Identity() *
                                    std::sqrt(process_variance));
    }
  }
  State<N> f(const State<N>& x, const NoControl&) const override { return x; }
};

template <int N, template <class> class Base = Kalman::StandardBase>
class Sensor : public Kalman::MeasurementModel<State<N>, Quality, Base> {
 public:
  Sensor() {
    if constexpr (std::is_same_v<Base<Quality>, Kalman::StandardBase<Quality>>) {
      this->setCovariance(Kalman::Covariance<Quality>::Identity() * measurement_variance);
    } else {
      this->setCovarianceSquareRoot(Kalman::Covariance<Quality>::Identity() *
                                    std::sqrt(measurement_variance));
    }
  }
  void place(const typename QuadraticQualityMeasurement<N>::Inputs& inputs) { inputs_ = inputs; }
  Quality h(const State<N>& x) const override {
    const Vector<N> e = inputs_.control - inputs_.assembly - x;
    const Vector<N> weighted = weight_ * e;  // eᵀHe with H = I as a matrix, as twincal's model
    Quality z;
    z(0) = std::sqrt(offset + e.dot(weighted));
    return z;
  }

 private:
  SquareMatrix<N> weight_ = SquareMatrix<N>::Identity();
  typename QuadraticQualityMeasurement<N>::Inputs inputs_;
};

// --- twincal's side --------------------------------------------------------------------------
template <int N>
class RandomWalkModel {
 public:
  static constexpr int dimension_at_compile_time = N;
  [[nodiscard]] Index dimension() const { return N; }
  [[nodiscard]] const Vector<N>& propagate(const Vector<N>& x) const { return x; }
  [[nodiscard]] const SquareMatrix<N>& process_noise() const { return q_; }

 private:
  SquareMatrix<N> q_ = SquareMatrix<N>::Identity() * process_variance;
};

template <int N>
using TwincalUkf =
    SigmaPointFilter<RandomWalkModel<N>, QuadraticQualityMeasurement<N>, MerweScaledSigmaPoints>;
template <int N>
using TwincalSquareRootUkf =
    SquareRootSigmaPointFilter<RandomWalkModel<N>, QuadraticQualityMeasurement<N>,
                               MerweScaledSigmaPoints>;

template <int N>
QuadraticQualityMeasurement<N> twincal_measurement() {
  return QuadraticQualityMeasurement<N>(SquareMatrix<N>::Identity(), offset, measurement_variance);
}

template <int N>
TwincalUkf<N> make_twincal(SigmaPointRefresh refresh, bool symmetrize) {
  SigmaPointFilterOptions options;
  options.refresh = refresh;
  options.symmetrize = symmetrize;
  return TwincalUkf<N>(RandomWalkModel<N>{}, twincal_measurement<N>(),
                       MerweScaledSigmaPoints{1.0, 2.0, 0.0}, Vector<N>::Constant(0.01),
                       SquareMatrix<N>::Identity() * 1e-2, options);
}

template <int N>
TwincalSquareRootUkf<N> make_twincal_square_root() {
  return TwincalSquareRootUkf<N>(
      RandomWalkModel<N>{}, twincal_measurement<N>(), MerweScaledSigmaPoints{1.0, 2.0, 0.0},
      Vector<N>::Constant(0.01), SquareMatrix<N>(SquareMatrix<N>::Identity() * 1e-2),
      SquareRootFilterOptions{SigmaPointRefresh::reuse_propagated, SquareRootUpdate::downdate});
}

// mherb/kalman's filter for a covariance base: the standard UKF or the square-root UKF.
template <int N, template <class> class Base>
using MherbUkf = std::conditional_t<std::is_same_v<Base<State<N>>, Kalman::StandardBase<State<N>>>,
                                    Kalman::UnscentedKalmanFilter<State<N>>,
                                    Kalman::SquareRootUnscentedKalmanFilter<State<N>>>;

template <int N, template <class> class Base>
MherbUkf<N, Base> make_mherb() {
  MherbUkf<N, Base> ukf(1.0, 2.0, 0.0);
  ukf.init(State<N>(Vector<N>::Constant(0.01)));
  ukf.setCovariance(Kalman::Covariance<State<N>>::Identity() * 1e-2);
  return ukf;
}

// One predict + update of mherb's filter at step k.
template <int N, template <class> class Base>
void mherb_step(MherbUkf<N, Base>& ukf, const Walk<N, Base>& walk, Sensor<N, Base>& sensor,
                const typename QuadraticQualityMeasurement<N>::Inputs& inputs, int k) {
  sensor.place(inputs);
  Quality z;
  z(0) = measured(k);
  ukf.predict(walk);
  ukf.update(sensor, z);
}

// mherb/kalman draws the update's points from the propagated ones (twincal's reuse_propagated)
// and does not symmetrize: twincal's filter so configured (`ours`) must agree with mherb's of
// the same base before anything is timed.
template <int N, template <class> class Base, typename Ours>
void require_same_estimates(Ours ours) {
  MherbUkf<N, Base> theirs = make_mherb<N, Base>();
  const Walk<N, Base> walk;
  Sensor<N, Base> sensor;
  const auto inputs = sensor_positions<N>();
  for (int k = 0; k < 3 * positions; ++k) {
    const auto& in = inputs[static_cast<std::size_t>(k % positions)];
    ours.predict();
    ours.update(measured(k), in);
    mherb_step<N, Base>(theirs, walk, sensor, in, k);
  }
  const double difference = (ours.state() - Vector<N>(theirs.getState())).cwiseAbs().maxCoeff();
  if (!(difference <= 1e-12)) {
    throw std::runtime_error(fmt::format(
        "n = {}: twincal's and mherb/kalman's filters disagree by {} after {} steps; rule: "
        "<= 1e-12",
        N, difference, 3 * positions));
  }
}

template <int N, template <class> class Base>
void mherb_ukf(benchmark::State& state) {
  if constexpr (std::is_same_v<Base<State<N>>, Kalman::StandardBase<State<N>>>) {
    require_same_estimates<N, Base>(make_twincal<N>(SigmaPointRefresh::reuse_propagated, false));
  } else {
    require_same_estimates<N, Base>(make_twincal_square_root<N>());
  }
  MherbUkf<N, Base> ukf = make_mherb<N, Base>();
  const Walk<N, Base> walk;
  Sensor<N, Base> sensor;
  const auto inputs = sensor_positions<N>();
  int k = 0;
  for (auto _ : state) {
    mherb_step<N, Base>(ukf, walk, sensor, inputs[static_cast<std::size_t>(k % positions)], k);
    benchmark::DoNotOptimize(ukf.getState().data());
    ++k;
  }
}

template <int N, typename Filter>
void twincal_steps(benchmark::State& state, Filter ukf) {
  const auto inputs = sensor_positions<N>();
  int k = 0;
  for (auto _ : state) {
    ukf.predict();
    ukf.update(measured(k), inputs[static_cast<std::size_t>(k % positions)]);
    benchmark::DoNotOptimize(ukf.state().data());
    ++k;
  }
}

template <int N, SigmaPointRefresh Refresh, bool Symmetrize>
void twincal_ukf(benchmark::State& state) {
  twincal_steps<N>(state, make_twincal<N>(Refresh, Symmetrize));
}

template <int N>
void twincal_square_root_ukf(benchmark::State& state) {
  twincal_steps<N>(state, make_twincal_square_root<N>());
}

template <int... Ns>
void register_sizes() {
  (benchmark::RegisterBenchmark(fmt::format("mherb_kalman/ukf/{}", Ns).c_str(),
                                &mherb_ukf<Ns, Kalman::StandardBase>),
   ...);
  (benchmark::RegisterBenchmark(fmt::format("twincal/ukf_points_reused/{}", Ns).c_str(),
                                &twincal_ukf<Ns, SigmaPointRefresh::reuse_propagated, false>),
   ...);
  (benchmark::RegisterBenchmark(fmt::format("twincal/ukf_defaults/{}", Ns).c_str(),
                                &twincal_ukf<Ns, SigmaPointRefresh::redraw, true>),
   ...);
  (benchmark::RegisterBenchmark(fmt::format("mherb_kalman/square_root_ukf/{}", Ns).c_str(),
                                &mherb_ukf<Ns, Kalman::SquareRootBase>),
   ...);
  (benchmark::RegisterBenchmark(fmt::format("twincal/square_root_ukf_downdate/{}", Ns).c_str(),
                                &twincal_square_root_ukf<Ns>),
   ...);
}

const bool registered = [] {
  register_sizes<1, 3, 6, 12>();
  return true;
}();

}  // namespace
}  // namespace twincal::benchmarks
