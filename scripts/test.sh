#!/usr/bin/env bash
# Install what is missing, build, and run the whole test suite (ctest).
#   ./scripts/test.sh                       release build in build/ (Clang 14, see common.sh)
#   ./scripts/test.sh --sanitizers address,undefined
#                                           instrumented build in build-sanitizers/: the test
#                                           suites and the fuzzers of fuzz/ (docs/fuzzing.md;
#                                           TWINCAL_FUZZ_SECONDS per search, default 30)
#   ./scripts/test.sh --gcc                 GCC 12 build in build-gcc/ of the libraries and the
#                                           programs twincal and twincal_calculix_twin (no
#                                           tests): what a user's default
#                                           compiler builds stays warning-free
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

build_dir="$TWINCAL_ROOT/build"
options=(-DCMAKE_BUILD_TYPE=Release)
run_tests=1
if [ "${1:-}" = "--sanitizers" ]; then
  [ -n "${2:-}" ] || { twincal_log "--sanitizers needs a list, e.g. address,undefined"; exit 2; }
  build_dir="$TWINCAL_ROOT/build-sanitizers"
  # -O1 keeps the instrumented suite fast; Eigen's assertions stay on (no NDEBUG). No debug
  # information (-g1 cost 13 % of a controllers test batch's instrumented compile, 39 against
  # 34 s): a report still names every function of its stack, from the symbol table; for
  # file:line, rebuild with -DCMAKE_CXX_FLAGS_DEBUG="-g1 -O1".
  # No Python module: CPython is not instrumented, so ASan would have to be preloaded into it.
  options=(-DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O1"
           "-DTWINCAL_SANITIZERS=${2//,/;}" -DTWINCAL_BUILD_BENCHMARKS=OFF
           -DTWINCAL_BUILD_EXAMPLES=OFF -DTWINCAL_BUILD_APPS=OFF -DTWINCAL_BUILD_PYTHON=OFF
           -DTWINCAL_BUILD_FUZZERS=ON)
  # A longer search on request (the default, 30 s per fuzzer, is fuzz/CMakeLists.txt's).
  [ -z "${TWINCAL_FUZZ_SECONDS:-}" ] || options+=("-DTWINCAL_FUZZ_SECONDS=$TWINCAL_FUZZ_SECONDS")
elif [ "${1:-}" = "--gcc" ]; then
  build_dir="$TWINCAL_ROOT/build-gcc"
  TWINCAL_CXX=g++
  # -Og: GCC's front end, which finds what Clang's misses, and the flow analysis behind
  # -Wmaybe-uninitialized, at 28 % less than -O2 on the heaviest file (episodes_merwe.cpp: 103
  # against 143 s, one after the other). -Og gives up -O2's value-range and path analysis
  # (-Warray-bounds, -Wnull-dereference); the instrumented suite checks bounds and null at run time.
  options=(-DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS_RELEASE=-Og -DNDEBUG"
           -DTWINCAL_BUILD_TESTS=OFF -DTWINCAL_BUILD_BENCHMARKS=OFF -DTWINCAL_BUILD_PYTHON=OFF)
  run_tests=0
elif [ $# -gt 0 ]; then
  twincal_log "unknown argument '$1' (usage: scripts/test.sh [--sanitizers LIST | --gcc])"
  exit 2
fi

twincal_install_dependencies
if [ "$run_tests" -eq 1 ]; then
  twincal_build "$build_dir" "${options[@]}"
else
  twincal_build "$build_dir" --target "twincal twincal_calculix_twin" "${options[@]}"
fi
[ "$run_tests" -eq 1 ] || exit 0
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
# One test more than there are cores: many tests spend their time waiting on child processes
# (external twins, ccx, mpiexec, Python) or on a hung twin's timeout (the instrumented suite:
# 254 s with two, 223 s with three on two cores).
ctest --test-dir "$build_dir" --output-on-failure --parallel "$((TWINCAL_JOBS + 1))"
