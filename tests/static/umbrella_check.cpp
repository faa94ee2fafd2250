// The top-level umbrella (include/twincal/twincal.hpp) compiles on its own, every module's
// umbrella with it, and reaches the concepts and the compiled modules' twins.
#include "twincal/twincal.hpp"

namespace twincal::static_checks::umbrella {

static_assert(Twin<SheetMetalTwin> && Twin<ContactSheetMetalTwin>);
static_assert(TwinWithDeviations<SheetMetalTwin> && TwinWithDeviations<ContactSheetMetalTwin>);
static_assert(Twin<ExternalTwin> && Twin<CalculixTwin>);
static_assert(SigmaPointScheme<MerweScaledSigmaPoints> && Sampler<Sobol>);
static_assert(SnapshotController<PaperController<RmsQuadraticTwin, 3>>);

}  // namespace twincal::static_checks::umbrella
