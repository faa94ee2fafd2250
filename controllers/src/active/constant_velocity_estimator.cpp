// The estimator's instantiations that constant_velocity_estimator.hpp declares `extern`.
#include "twincal/controllers/active/constant_velocity_estimator.hpp"

namespace twincal {

template class ConstantVelocityEstimator<Dynamic>;

}  // namespace twincal
