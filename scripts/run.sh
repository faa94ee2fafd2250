#!/usr/bin/env bash
# The main job: install what is missing, build, and run the paper's study on the open FEM twin —
# both cases ('body', 'door') × locator sets A, B, C, ABC × baseline, default and the eleven
# w-controllers × 10 seeded runs of 100 assemblies — then draw its figures and print the summary.
#   ./scripts/run.sh [results-dir] [twincal paper options, e.g. --runs 3 --seed 7]
# Results (CSV, JSON) and figures (PNG, SVG, Table 1) go to results-dir (default results/paper);
# rerunning resumes: finished episodes are kept, not recomputed — by the same build only (a
# twincal rebuilt from other code stops and says so: give another results-dir, or remove it).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

out="${1:-$TWINCAL_ROOT/results/paper}"
[ $# -gt 0 ] && shift

twincal_install_dependencies
# Only the program and its libraries: the tests and benchmarks are scripts/test.sh's.
twincal_build "$TWINCAL_ROOT/build" --target twincal -DCMAKE_BUILD_TYPE=Release
cli="$TWINCAL_ROOT/build/apps/twincal/twincal"
"$cli" paper --out "$out" "$@"
"$cli" plot --results "$out" --out "$out/figures"
