#pragma once
// Shared set-up of the controller tests: the RMS-quadratic analytic twin behind a counting
// evaluator, the paper's random-walk offset model and quality feedback, and filters of each kind.

#include <cstdint>
#include <stdexcept>

#include "twincal/core/random_stream.hpp"
#include "twincal/filters/cubature_kalman_filter.hpp"
#include "twincal/filters/merwe_scaled_sigma_points.hpp"
#include "twincal/filters/spherical_radial_sigma_points.hpp"
#include "twincal/filters/square_root_sigma_point_filter.hpp"
#include "twincal/filters/unscented_kalman_filter.hpp"
#include "twincal/models/evaluator.hpp"
#include "twincal/models/quality_feedback.hpp"
#include "twincal/models/random_walk.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace twincal::test_support {

using AnalyticTwin = RmsQuadraticTwin;
using CountingTwin = Evaluator<AnalyticTwin>;

inline AnalyticTwin make_twin(Index d, std::uint64_t seed = 5) {
  RmsQuadraticTwinOptions options;
  options.assemblies.dimension = d;
  return AnalyticTwin::generate(options, RandomStream(seed));
}

template <int N>
using Feedback = QualityFeedback<CountingTwin, N>;

// The paper's filter settings (Sec. 2.4): Σu = 1e-3·I, σz² = 1e-4; Merwe points α=1, β=2, κ=0
// (non-negative weights).
inline constexpr double process_variance = 1e-3;
inline constexpr double measurement_variance = 1e-4;
inline MerweScaledSigmaPoints merwe() { return MerweScaledSigmaPoints(1.0, 2.0, 0.0); }

template <int N>
using Ukf = UnscentedKalmanFilter<RandomWalk<N>, Feedback<N>>;
template <int N>
using Ckf = CubatureKalmanFilter<RandomWalk<N>, Feedback<N>>;
template <int N>
using SquareRootUkf =
    SquareRootSigmaPointFilter<RandomWalk<N>, Feedback<N>, MerweScaledSigmaPoints>;

// A filter of type F over `twin` starting from N(x0, p0·I).
template <typename F>
F make_filter(const CountingTwin& twin, const Vector<F::dimension_at_compile_time>& x0, double p0,
              double q = process_variance) {
  constexpr int N = F::dimension_at_compile_time;
  const Index d = twin.control_dimension();
  const SquareMatrix<N> covariance = SquareMatrix<N>::Identity(d, d) * p0;
  if constexpr (std::is_same_v<F, Ckf<N>>) {
    return F(RandomWalk<N>::isotropic(d, q), Feedback<N>(twin, measurement_variance),
             SphericalRadialSigmaPoints{}, x0, covariance);
  } else {
    return F(RandomWalk<N>::isotropic(d, q), Feedback<N>(twin, measurement_variance), merwe(), x0,
             covariance);
  }
}

// The analytic twin as a plain black box: every Twin member forwarded, the known optimum hidden.
class BlackBox {
 public:
  using Assembly = AnalyticTwin::Assembly;
  explicit BlackBox(const AnalyticTwin& inner) : inner_(&inner) {}
  [[nodiscard]] Index control_dimension() const { return inner_->control_dimension(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const {
    return inner_->locator_names();
  }
  [[nodiscard]] const VectorX& lower_bounds() const { return inner_->lower_bounds(); }
  [[nodiscard]] const VectorX& upper_bounds() const { return inner_->upper_bounds(); }
  [[nodiscard]] double quality(const Assembly& x, const Eigen::Ref<const VectorX>& u) const {
    return inner_->quality(x, u);
  }
  void quality_batch(const Assembly& x, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    inner_->quality_batch(x, controls, out);
  }

 protected:
  const AnalyticTwin* inner_;
};

// Like the analytic twin (optimum included), but throws on batches larger than `max_batch`
// controls, to make a controller's scoring batch fail while the filter's own updates still work.
class FailingOnLargeBatches : public BlackBox {
 public:
  FailingOnLargeBatches(const AnalyticTwin& inner, Index max_batch)
      : BlackBox(inner), max_batch_(max_batch) {}
  void quality_batch(const Assembly& x, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    if (controls.cols() > max_batch_) throw std::runtime_error("FEM solver crashed");
    BlackBox::quality_batch(x, controls, out);
  }
  [[nodiscard]] VectorX optimum(const Assembly& x) const { return inner_->optimum(x); }
  [[nodiscard]] double optimal_quality(const Assembly& x) const {
    return inner_->optimal_quality(x);
  }

 private:
  Index max_batch_;
};

// The two-locator analytic twin behind FailingOnLargeBatches(max_batch) in an Evaluator, whose
// failures are therefore TwinErrors, and the UKF over it the failure tests start from.
struct FailingTwinSetup {
  using Checked = Evaluator<FailingOnLargeBatches>;
  using Model = QualityFeedback<Checked, 2>;
  using Filter = UnscentedKalmanFilter<RandomWalk<2>, Model>;

  explicit FailingTwinSetup(Index max_batch) : failing(inner, max_batch), twin(failing) {}
  FailingTwinSetup(const FailingTwinSetup&) = delete;  // the twins refer to each other
  FailingTwinSetup& operator=(const FailingTwinSetup&) = delete;

  [[nodiscard]] Filter filter() const {
    return Filter(RandomWalk<2>::isotropic(2, 1e-3), Model(twin, 1e-4), merwe(),
                  Eigen::Vector2d(0.02, 0.0), Eigen::Matrix2d::Identity() * 1e-3);
  }

  AnalyticTwin inner = make_twin(2);
  FailingOnLargeBatches failing;
  Checked twin;
};

}  // namespace twincal::test_support
