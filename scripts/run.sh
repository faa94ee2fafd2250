#!/usr/bin/env bash
# The main job: install what is missing, build, run the demo of the framework.
#   ./scripts/run.sh [seed]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

twincal_install_dependencies
twincal_build "$TWINCAL_ROOT/build" -DCMAKE_BUILD_TYPE=Release
"$TWINCAL_ROOT/build/examples/offset_random_walk" "$@"
