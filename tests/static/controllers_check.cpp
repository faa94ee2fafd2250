// Compile-time checks of the controllers' concepts: what each accepts and what it rejects.
#include <Eigen/Core>

#include "twincal/controllers/controller.hpp"
#include "twincal/controllers/expected_quality.hpp"
#include "twincal/controllers/exploitation_loss.hpp"
#include "twincal/controllers/exploration_loss.hpp"
#include "twincal/controllers/log_det_loss.hpp"
#include "twincal/controllers/max_eigenvalue_loss.hpp"
#include "twincal/controllers/nlopt_optimizer.hpp"
#include "twincal/controllers/optimizer.hpp"
#include "twincal/controllers/presets.hpp"
#include "twincal/controllers/quality_filter.hpp"
#include "twincal/controllers/trace_loss.hpp"
#include "twincal/controllers/weighted_trace_loss.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"

namespace twincal::static_checks {

// --- Controller / EstimatingController -------------------------------------------------------
struct ProposesOnly {
  using Assembly = int;
  using ControlVector = VectorX;
  [[nodiscard]] ControlVector propose(const Assembly&) { return {}; }
};
struct Learns : ProposesOnly {
  void observe(const Assembly&, const ControlVector&, double) {}
};
struct LearnsAndEstimates : Learns {
  [[nodiscard]] VectorX offset_estimate() const { return {}; }
  [[nodiscard]] MatrixX offset_covariance() const { return {}; }
};
static_assert(!Controller<ProposesOnly>);  // a controller must take feedback, even to ignore it
static_assert(Controller<Learns> && !EstimatingController<Learns>);
static_assert(EstimatingController<LearnsAndEstimates>);
static_assert(EstimatingController<PaperController<RmsQuadraticTwin, 3>>);
static_assert(EstimatingController<PerComponentPaperController<RmsQuadraticTwin>>);
// Snapshots: the presets have save() and restore(); a controller without them is not one.
static_assert(!SnapshotController<LearnsAndEstimates>);
static_assert(SnapshotController<PaperController<RmsQuadraticTwin, 3>>);
static_assert(SnapshotController<PaperDefaultController<RmsQuadraticTwin, Dynamic>>);
static_assert(SnapshotController<PerComponentPaperController<RmsQuadraticTwin>>);

// --- QualityFilter: the paper's filters qualify, a filter of another measurement does not -----
static_assert(QualityFilter<PaperFilter<RmsQuadraticTwin, 3>>);
static_assert(QualityFilter<CubatureFilter<RmsQuadraticTwin, Dynamic>>);
static_assert(!QualityFilter<int>);

// --- losses -----------------------------------------------------------------------------------
static_assert(ExploitationLoss<ExpectedQuality>);
static_assert(!ExploitationLoss<TraceLoss>);  // a covariance score is not a quality score
static_assert(ExplorationLoss<TraceLoss, 3> && ExplorationLoss<WeightedTraceLoss, Dynamic>);
static_assert(ExplorationLoss<LogDetLoss, 2> && ExplorationLoss<MaxEigenvalueLoss, 2>);
static_assert(!ExplorationLoss<ExpectedQuality, 3>);

// --- Optimizer ------------------------------------------------------------------------------
struct MutatingOptimizer {  // minimize must be callable on a const optimizer
  OptimizationResult minimize(const Objective&, const VectorX&, const VectorX&, const VectorX&) {
    return {};
  }
};
static_assert(Optimizer<NloptOptimizer>);
static_assert(!Optimizer<MutatingOptimizer>);

}  // namespace twincal::static_checks
