// Compile-time checks of the controllers' concepts: what each accepts and what it rejects.
#include <Eigen/Core>

#include "twincal/controllers/active/information_probe.hpp"
#include "twincal/controllers/active/probe_design.hpp"
#include "twincal/controllers/active/thompson_probe.hpp"
#include "twincal/controllers/batch_optimizer.hpp"
#include "twincal/controllers/controller.hpp"
#include "twincal/controllers/expected_quality.hpp"
#include "twincal/controllers/exploitation_loss.hpp"
#include "twincal/controllers/exploration_loss.hpp"
#include "twincal/controllers/least_squares_search.hpp"
#include "twincal/controllers/log_det_loss.hpp"
#include "twincal/controllers/max_eigenvalue_loss.hpp"
#include "twincal/controllers/nlopt_optimizer.hpp"
#include "twincal/controllers/optimizer.hpp"
#include "twincal/controllers/presets.hpp"
#include "twincal/controllers/quality_filter.hpp"
#include "twincal/controllers/sampler_state.hpp"
#include "twincal/controllers/searched_optimum_twin.hpp"
#include "twincal/controllers/trace_loss.hpp"
#include "twincal/controllers/trust_region_search.hpp"
#include "twincal/controllers/weighted_trace_loss.hpp"
#include "twincal/models/contact_nonlinearity.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/no_nonlinearity.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"
#include "twincal/samplers/halton.hpp"
#include "twincal/samplers/latin_hypercube.hpp"
#include "twincal/samplers/pseudo_random.hpp"
#include "twincal/samplers/sobol.hpp"

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
// Snapshots of a filter: the sigma-point filters save and restore their state.
static_assert(SnapshotFilter<PaperFilter<RmsQuadraticTwin, 3>>);
static_assert(SnapshotFilter<CubatureFilter<RmsQuadraticTwin, Dynamic>>);
static_assert(!SnapshotFilter<int>);

// --- ProbeDesign / SnapshotProbe: the active controller's probes ------------------------------
struct ProbeWithoutDesign {
  void propose(const ProbeContext<3>&, Vector<3>&) {}
};
struct ProbeWithoutRestore {  // a design whose state cannot be restored is no SnapshotProbe
  void design(const ProbeContext<3>&, Vector<3>&) {}
  [[nodiscard]] nlohmann::json save() const { return {}; }
};
static_assert(ProbeDesign<NoProbe<3>, 3> && ProbeDesign<InformationProbe<Dynamic>, Dynamic>);
static_assert(ProbeDesign<ThompsonProbe<3>, 3>);
static_assert(!ProbeDesign<ProbeWithoutDesign, 3>);
static_assert(ProbeDesign<ProbeWithoutRestore, 3> && !SnapshotProbe<ProbeWithoutRestore>);
static_assert(SnapshotProbe<NoProbe<3>> && SnapshotProbe<InformationProbe<Dynamic>>);
static_assert(SnapshotProbe<ThompsonProbe<Dynamic>>);

// --- SnapshotSampler: every sampler of the project saves its position --------------------------
static_assert(SnapshotSampler<Sobol> && SnapshotSampler<Halton>);
static_assert(SnapshotSampler<PseudoRandom> && SnapshotSampler<LatinHypercube>);
static_assert(!SnapshotSampler<int>);

// --- TwinWithSearchStart: a twin that knows where to start the search for u0 ------------------
static_assert(TwinWithSearchStart<KeyPointTwin<NoNonlinearity>>);
static_assert(Twin<RmsQuadraticTwin> && !TwinWithSearchStart<RmsQuadraticTwin>);

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

// --- BatchOptimizer -------------------------------------------------------------------------
struct ScalarResultOptimizer {  // a result without argmin / minimum / evaluations
  double minimize(const BatchObjective&, const VectorX&, const VectorX&, const VectorX&) const {
    return 0.0;
  }
};
static_assert(BatchOptimizer<TrustRegionSearch>);
static_assert(!BatchOptimizer<NloptOptimizer>);  // it asks for one control at a time
static_assert(!Optimizer<TrustRegionSearch>);
static_assert(!BatchOptimizer<ScalarResultOptimizer>);
// The least-squares search asks for deviations, not qualities: it is not a BatchOptimizer.
static_assert(!BatchOptimizer<LeastSquaresSearch> && !Optimizer<LeastSquaresSearch>);

// --- SearchedOptimumTwin passes the deviations of the twin it wraps through ----------------------
static_assert(TwinWithDeviations<SearchedOptimumTwin<KeyPointTwin<ContactNonlinearity>>>);
static_assert(TwinWithOptimum<SearchedOptimumTwin<RmsQuadraticTwin>> &&
              !TwinWithDeviations<SearchedOptimumTwin<RmsQuadraticTwin>>);

}  // namespace twincal::static_checks
