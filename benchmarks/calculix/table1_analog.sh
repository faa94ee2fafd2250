#!/bin/bash
# The paper's Table 1 in seconds, on the CalculiX twin (docs/benchmarks.md, "Table 1 analog on
# CalculiX"): calls and wall time per assembly of baseline, default, w = 1 and active at 1 and 3
# locators, with 1 and 8 twin worker processes, u0 included.
#
# usage: benchmarks/calculix/table1_analog.sh [OUT_DIR] [WORKERS...]   (from the repository root,
#        after a build; default OUT_DIR /tmp/twincal_table1, WORKERS 1 8)
#        OPTIMUM_METHOD=trust_region for the batched u0 search (default bobyqa; docs/external.md),
#        least_squares or least_squares_speculative on the program's 8 key points' deviations;
#        OPTIMUM_BUDGET=B (default 98); START_TWIN=secant to start each assembly's search from
#        the optimum of the secant influence-coefficient map (optimum_start_command);
#        START_TWIN=secant OPTIMUM_METHOD=least_squares OPTIMUM_BUDGET=28 is the fastest measured
#        (docs/benchmarks.md: 8.5 s per assembly for active at 3 locators with 8 workers)
#
# The lap joint with contact and large displacements (the program's default), 2 x 3 parts (6
# assemblies), the budgeted u0 search of 2 (d + 1)^2 = 98 calls per assembly (OPTIMUM_BUDGET)
# over the six locators, one run of 5 assemblies per controller, episodes one at a time (--threads 1) so
# that a controller's wall time per assembly is its own. The u0 searches of the 6 assemblies
# (one per worker at a time) are the set-up the output reports.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
out="${1:-/tmp/twincal_table1}"
shift || true
workers=("$@")
[ ${#workers[@]} -gt 0 ] || workers=(1 8)
method="${OPTIMUM_METHOD:-bobyqa}"
budget="${OPTIMUM_BUDGET:-98}"
program="$root/build/calculix/twincal_calculix_twin"
parts='"--upper-parts", "2", "--lower-parts", "3"'
extra=""
case "$method" in least_squares*) extra="\"key_points\": 8," ;; esac
case "${START_TWIN:-}" in
  "") ;;
  secant) extra="$extra \"optimum_start_command\": [\"$program\", \"--layout\", \"lap-joint\",
    \"--influence\", \"--linearization\", \"secant\", $parts]," ;;
  *) echo "START_TWIN must be secant or unset, not '$START_TWIN'" >&2; exit 2 ;;
esac
mkdir -p "$out"
for locators in U3 U1,U3,L3; do
  for w in "${workers[@]}"; do
    name="locators-${locators//,/}-workers-$w-$method-$budget${START_TWIN:+-$START_TWIN}"
    cat > "$out/$name.json" <<JSON
{
  "name": "$name",
  "case": "external",
  "external_twin": {
    "command": ["$program", "--layout", "lap-joint", $parts],
    "locators": ["U1", "U2", "U3", "L1", "L2", "L3"],
    "lower_bounds": [-1.0, -1.0, -1.0, -1.0, -1.0, -1.0],
    "upper_bounds": [1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
    "upper_parts": 2,
    "lower_parts": 3,
    "workers": $w,
    "timeout_ms": 600000,
    $extra
    "optimum_budget": $budget,
    "optimum_method": "$method"
  },
  "locators": "$locators",
  "controllers": ["baseline", "default", "w=1", "active"],
  "runs": 1,
  "assemblies": 5
}
JSON
    echo "== $name"
    "$root/build/apps/twincal/twincal" run --config "$out/$name.json" --out "$out/$name" \
      --threads 1 --quiet
  done
done
