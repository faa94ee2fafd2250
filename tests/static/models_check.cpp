// Compile-time checks of the models module's concepts: what each accepts and what it rejects,
// and that QualityFeedback has the filters' MeasurementModel shape (restated here so the check
// does not depend on the filters module).
#include <concepts>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "twincal/external/external_twin.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/bouncing_drift.hpp"
#include "twincal/models/brownian_drift.hpp"
#include "twincal/models/constant_drift.hpp"
#include "twincal/models/contact_nonlinearity.hpp"
#include "twincal/models/deviation_nonlinearity.hpp"
#include "twincal/models/drift.hpp"
#include "twincal/models/evaluator.hpp"
#include "twincal/models/execution.hpp"
#include "twincal/models/kept_assemblies.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/kink_nonlinearity.hpp"
#include "twincal/models/locator_subset.hpp"
#include "twincal/models/no_nonlinearity.hpp"
#include "twincal/models/parallel_execution.hpp"
#include "twincal/models/quality_feedback.hpp"
#include "twincal/models/random_walk.hpp"
#include "twincal/models/rms_quadratic_twin.hpp"
#include "twincal/models/rugged_twin.hpp"
#include "twincal/models/step_drift.hpp"
#include "twincal/models/stiffening_nonlinearity.hpp"
#include "twincal/models/twin.hpp"

namespace twincal::static_checks::models {

// --- Twin ------------------------------------------------------------------------------------
struct TwinWithoutBatch {
  using Assembly = int;
  [[nodiscard]] Index control_dimension() const { return 1; }
  [[nodiscard]] const std::vector<std::string>& locator_names() const { return names; }
  [[nodiscard]] const VectorX& lower_bounds() const { return bounds; }
  [[nodiscard]] const VectorX& upper_bounds() const { return bounds; }
  [[nodiscard]] double quality(int, const Eigen::Ref<const VectorX>&) const { return 0.0; }
  std::vector<std::string> names{"u"};
  VectorX bounds = VectorX::Zero(1);
};
struct MinimalTwin : TwinWithoutBatch {  // the batch is what makes a Twin of the above
  void quality_batch(int, const Eigen::Ref<const MatrixX>&, Eigen::Ref<VectorX>) const {}
};
struct TwinWithMutableQuality : MinimalTwin {  // quality must be callable on a const twin
  [[nodiscard]] double quality(int, const Eigen::Ref<const VectorX>&) { return 0.0; }
};
struct TwinWithoutAssembly {
  [[nodiscard]] Index control_dimension() const { return 1; }
};
static_assert(Twin<MinimalTwin>);
static_assert(!TwinWithOptimum<MinimalTwin>);
static_assert(!Twin<TwinWithoutBatch>);
static_assert(!Twin<TwinWithMutableQuality>);
static_assert(!Twin<TwinWithoutAssembly>);
static_assert(!Twin<int>);
static_assert(TwinWithOptimum<RmsQuadraticTwin>);
static_assert(TwinWithOptimum<RuggedTwin>);
static_assert(TwinWithOptimum<LocatorSubset<RmsQuadraticTwin>>);
static_assert(Twin<ExternalTwin> && !TwinWithOptimum<ExternalTwin>);
// Evaluators are twins themselves, and pass a known optimum through.
static_assert(TwinWithOptimum<Evaluator<RmsQuadraticTwin>>);
static_assert(Twin<Evaluator<MinimalTwin>> && !TwinWithOptimum<Evaluator<MinimalTwin>>);
static_assert(Twin<Evaluator<ExternalTwin, ParallelExecution>>);

// --- TwinWithDeviations ------------------------------------------------------------------------
struct TwinWithDeviationBatch : MinimalTwin {
  [[nodiscard]] Index key_point_count() const { return 2; }
  void deviations_batch(int, const Eigen::Ref<const MatrixX>&, Eigen::Ref<MatrixX>) const {}
};
struct TwinWithoutKeyPointCount : MinimalTwin {  // m is needed to size the deviations
  void deviations_batch(int, const Eigen::Ref<const MatrixX>&, Eigen::Ref<MatrixX>) const {}
};
struct TwinWithMutableDeviations : MinimalTwin {  // callable on a const twin, as quality is
  [[nodiscard]] Index key_point_count() const { return 2; }
  void deviations_batch(int, const Eigen::Ref<const MatrixX>&, Eigen::Ref<MatrixX>) {}
};
struct DeviationsWithoutQuality {  // the deviations come on top of Q, not instead of it
  using Assembly = int;
  [[nodiscard]] Index key_point_count() const { return 2; }
  void deviations_batch(int, const Eigen::Ref<const MatrixX>&, Eigen::Ref<MatrixX>) const {}
};
static_assert(TwinWithDeviations<TwinWithDeviationBatch>);
static_assert(!TwinWithDeviations<MinimalTwin>);
static_assert(!TwinWithDeviations<TwinWithoutKeyPointCount>);
static_assert(!TwinWithDeviations<TwinWithMutableDeviations>);
static_assert(!TwinWithDeviations<DeviationsWithoutQuality>);
static_assert(TwinWithDeviations<KeyPointTwin<NoNonlinearity>>);
static_assert(TwinWithDeviations<KeyPointTwin<ContactNonlinearity>>);
static_assert(!TwinWithDeviations<RmsQuadraticTwin>);
// A program's deviations are known at run time (ExternalTwinOptions::key_points; 0 refuses them).
static_assert(TwinWithDeviations<ExternalTwin>);
static_assert(Twin<Evaluator<Evaluator<MinimalTwin>>>);
// The wrappers pass the deviations on where the twin has them, and only there.
static_assert(TwinWithDeviations<Evaluator<KeyPointTwin<ContactNonlinearity>>>);
static_assert(!TwinWithDeviations<Evaluator<RmsQuadraticTwin>>);
static_assert(TwinWithDeviations<LocatorSubset<KeyPointTwin<NoNonlinearity>>>);
static_assert(!TwinWithDeviations<LocatorSubset<RmsQuadraticTwin>>);

// --- TwinWithKeptAssemblies: value assemblies yes, borrowed ones no, wrappers forward ----------
struct BorrowingTwin : MinimalTwin {
  static constexpr bool borrows_assemblies = true;
};
struct TwinWithUnkeepableAssembly : MinimalTwin {
  struct Handle {  // neither copyable nor default-constructible
    explicit Handle(int) {}
    Handle(const Handle&) = delete;
  };
  using Assembly = Handle;
  [[nodiscard]] double quality(const Handle&, const Eigen::Ref<const VectorX>&) const {
    return 0.0;
  }
  void quality_batch(const Handle&, const Eigen::Ref<const MatrixX>&, Eigen::Ref<VectorX>) const {}
};
static_assert(TwinWithKeptAssemblies<MinimalTwin>);
static_assert(TwinWithKeptAssemblies<RmsQuadraticTwin>);
static_assert(TwinWithKeptAssemblies<ExternalTwin>);
static_assert(Twin<BorrowingTwin> && !TwinWithKeptAssemblies<BorrowingTwin>);
static_assert(Twin<TwinWithUnkeepableAssembly> &&
              !TwinWithKeptAssemblies<TwinWithUnkeepableAssembly>);
static_assert(!TwinWithKeptAssemblies<Evaluator<BorrowingTwin>>);
static_assert(TwinWithKeptAssemblies<LocatorSubset<RmsQuadraticTwin>>);

// --- DeviationNonlinearity and the key-point twins ----------------------------------------------
struct NonlinearityWithoutName {
  void apply(const Eigen::Ref<const VectorX>&, const Eigen::Ref<const VectorX>&,
             const Eigen::Ref<const VectorX>&, Eigen::Ref<VectorX>) const {}
};
struct NonlinearityWithMutableApply {  // apply must be callable on a const policy
  static constexpr std::string_view name() { return "mutable"; }
  void apply(const Eigen::Ref<const VectorX>&, const Eigen::Ref<const VectorX>&,
             const Eigen::Ref<const VectorX>&, Eigen::Ref<VectorX>) {}
};
static_assert(DeviationNonlinearity<NoNonlinearity>);
static_assert(DeviationNonlinearity<ContactNonlinearity>);
static_assert(DeviationNonlinearity<StiffeningNonlinearity>);
static_assert(DeviationNonlinearity<KinkNonlinearity>);
static_assert(!DeviationNonlinearity<NonlinearityWithoutName>);
static_assert(!DeviationNonlinearity<NonlinearityWithMutableApply>);
static_assert(!DeviationNonlinearity<int>);
// The optimum of a nonlinear key-point twin is not known (it is searched); without a
// nonlinearity it is the affine one.
static_assert(TwinWithOptimum<KeyPointTwin<NoNonlinearity>>);
static_assert(Twin<KeyPointTwin<ContactNonlinearity>> &&
              !TwinWithOptimum<KeyPointTwin<ContactNonlinearity>>);

// --- Execution -------------------------------------------------------------------------------
static_assert(Execution<SerialExecution>);
static_assert(Execution<ParallelExecution>);
static_assert(!Execution<int>);

// --- HashableAssembly: what the Evaluator can memoize by --------------------------------------
struct UnhashedAssembly {  // equality alone is not enough: the memo is a hash map
  friend bool operator==(const UnhashedAssembly&, const UnhashedAssembly&) = default;
};
static_assert(HashableAssembly<AssemblyId> && HashableAssembly<Index>);
static_assert(HashableAssembly<std::string>);
static_assert(!HashableAssembly<UnhashedAssembly>);

// --- Drift -----------------------------------------------------------------------------------
struct DriftWithoutAdvance {
  [[nodiscard]] Index dimension() const { return 1; }
  [[nodiscard]] Index time() const { return 0; }
  [[nodiscard]] VectorX offset() const { return VectorX::Zero(1); }
};
static_assert(Drift<BouncingDrift<3>> && Drift<BouncingDrift<Dynamic>>);
static_assert(Drift<BrownianDrift<3>> && Drift<BrownianDrift<Dynamic>>);
static_assert(Drift<StepDrift<3>> && Drift<ConstantDrift<Dynamic>>);
static_assert(!Drift<DriftWithoutAdvance>);

// --- The filters' model shapes (interfaces agreement) -----------------------------------------
template <typename M>
concept MeasurementModelShape = requires {
  typename M::Inputs;
  { M::dimension_at_compile_time } -> std::convertible_to<int>;
}
&&requires(const M& model, const Vector<M::dimension_at_compile_time>& state,
           const typename M::Inputs& inputs, const Eigen::Ref<const MatrixX>& states,
           Eigen::Ref<VectorX> out) {
  { model.measure(state, inputs) } -> std::convertible_to<double>;
  { model.noise_variance() } -> std::convertible_to<double>;
  model.measure_batch(states, inputs, out);
};
template <typename M>
concept StateModelShape = requires(const M& model, const Vector<M::dimension_at_compile_time>& x) {
  { M::dimension_at_compile_time } -> std::convertible_to<int>;
  { model.dimension() } -> std::convertible_to<Index>;
  { model.propagate(x) } -> std::convertible_to<Vector<M::dimension_at_compile_time>>;
  { model.process_noise() } -> std::convertible_to<SquareMatrix<M::dimension_at_compile_time>>;
};
static_assert(MeasurementModelShape<QualityFeedback<RmsQuadraticTwin, 3>>);
static_assert(MeasurementModelShape<QualityFeedback<RmsQuadraticTwin, Dynamic>>);
static_assert(MeasurementModelShape<QualityFeedback<Evaluator<RmsQuadraticTwin>, 3>>);
static_assert(MeasurementModelShape<QualityFeedback<Evaluator<RmsQuadraticTwin>, Dynamic>>);
static_assert(MeasurementModelShape<QualityFeedback<Evaluator<ExternalTwin>, 2>>);
static_assert(MeasurementModelShape<QualityFeedback<LocatorSubset<RuggedTwin>, 1>>);
static_assert(StateModelShape<RandomWalk<3>> && StateModelShape<RandomWalk<Dynamic>>);

}  // namespace twincal::static_checks::models
