// AnyTwin (any_twin.hpp): what is not a template.
#include "twincal/experiments/any_twin.hpp"

#include "twincal/core/error.hpp"

namespace twincal {

void AnyTwin::throw_without_scanned_parts() {
  throw InvalidArgumentError("parts",
                             "parts: this twin's assemblies are its own part indices; rule: only "
                             "a twin that takes scanned parts (the external case) accepts them");
}

void AnyTwin::throw_without_deviations() {
  throw InvalidArgumentError("deviations",
                             "deviations: this twin answers only its quality; rule: only a twin "
                             "that answers its key points' deviations (TwinWithDeviations) can");
}

}  // namespace twincal
