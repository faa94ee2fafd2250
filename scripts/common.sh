# Shared by scripts/run.sh and scripts/test.sh: install what is missing, configure, build.
# Sourced, not run. Everything here is idempotent and quick when nothing changed.

TWINCAL_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
TWINCAL_JOBS="${TWINCAL_JOBS:-$(nproc 2>/dev/null || echo 2)}"
# The compiler of every build the scripts configure: Clang 14 compiles the template-heavy test
# and benchmark TUs 2.4× faster than GCC 12 at -O3 (the square-root filter test: 59 s against
# 143 s). `scripts/test.sh --gcc` keeps GCC, Debian's default, warning-free. A build directory
# keeps the compiler it was configured with; set TWINCAL_CXX to choose another for a new one.
TWINCAL_CXX="${TWINCAL_CXX:-clang++-14}"

# ccache (when installed) keys objects by paths relative to the checkout, so a fresh clone in
# another folder reuses them (also those built with -g1, whose key would otherwise hold the build
# folder); the precompiled test headers need the sloppiness to be cached.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$TWINCAL_ROOT}"
export CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-1}"
export CCACHE_SLOPPINESS="${CCACHE_SLOPPINESS:-pch_defines,time_macros,include_file_mtime,include_file_ctime}"

twincal_log() { printf '\033[1m[twincal]\033[0m %s\n' "$*" >&2; }

# Installs the Debian packages of scripts/debian-packages.txt that are not installed yet.
twincal_install_dependencies() {
  local wanted missing=()
  mapfile -t wanted < <(grep -Ev '^\s*(#|$)' "$TWINCAL_ROOT/scripts/debian-packages.txt")
  for package in "${wanted[@]}"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q 'install ok installed' \
      || missing+=("$package")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    return 0
  fi
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { twincal_log "need root or sudo to install: ${missing[*]}"; return 1; }
    sudo=(sudo)
  fi
  twincal_log "installing ${missing[*]}"
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
}

# twincal_build <build-dir> [--target "T…"] [cmake -D options...]: configures once, then builds
# incrementally — everything, or only the targets T… (blank-separated) and what they need.
twincal_build() {
  local build_dir="$1"
  shift
  local target=()
  if [ "${1:-}" = "--target" ]; then
    local names=()
    read -ra names <<<"$2"
    target=(--target "${names[@]}")
    shift 2
  fi
  local launcher=()
  if command -v ccache >/dev/null; then
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  fi
  if [ ! -f "$build_dir/CMakeCache.txt" ]; then
    twincal_log "configuring $build_dir"
    cmake -S "$TWINCAL_ROOT" -B "$build_dir" -G Ninja "-DCMAKE_CXX_COMPILER=$TWINCAL_CXX" \
      "${launcher[@]}" "$@" >/dev/null
  else
    cmake "$build_dir" "$@" >/dev/null
  fi
  twincal_log "building $build_dir with $TWINCAL_JOBS jobs"
  cmake --build "$build_dir" --parallel "$TWINCAL_JOBS" "${target[@]}"
}
