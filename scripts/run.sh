#!/usr/bin/env bash
# The main job: install what is missing, build, run the demo of the framework: one episode of the
# paper's protocol on an analytic twin for the baseline, default and w-controllers and three
# one-policy ablations (examples/ablation.cpp).
#   ./scripts/run.sh [seed] [w]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

twincal_install_dependencies
twincal_build "$TWINCAL_ROOT/build" -DCMAKE_BUILD_TYPE=Release
"$TWINCAL_ROOT/build/examples/ablation" "$@"
