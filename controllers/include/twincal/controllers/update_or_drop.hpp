#pragma once
/// @file
/// `update_or_drop`: a filter-based controller's measurement update (eq. 8) under the twin's
/// failure policy. The update evaluates the twin at the filter's sigma points; when the twin
/// cannot answer there (TwinError: a solver that did not converge, a program that died or
/// answered an error), z_t is dropped, as a Kalman filter drops a missing measurement: the
/// estimate stays as predicted, P keeps the process noise of the prediction, and the report
/// says why. Any other error (a non-finite z, a covariance that cannot be factored) still stops
/// the controller: it is not the twin's, and a dropped measurement would hide it.

#include "twincal/controllers/proposal_report.hpp"
#include "twincal/controllers/quality_filter.hpp"
#include "twincal/core/error.hpp"

namespace twincal {

/// filter.update(z, inputs), or, on a TwinError, nothing but report.dropped_measurement = its
/// message (the filter's update changes nothing before its evaluations succeeded).
/// @throws whatever filter.update throws other than a TwinError, the filter unchanged.
template <QualityFilter F>
void update_or_drop(F& filter, double z, const typename F::Inputs& inputs, ProposalReport& report) {
  try {
    filter.update(z, inputs);
  } catch (const TwinError& error) {
    report.dropped_measurement = error.what();
  }
}

}  // namespace twincal
