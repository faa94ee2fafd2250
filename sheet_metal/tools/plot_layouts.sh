#!/usr/bin/env bash
# Regenerates docs/images/{body,door}_layout.png from the layouts in the code.
# usage: sheet_metal/tools/plot_layouts.sh [build-dir]   (run from the repository root)
set -euo pipefail
build=${1:-build}
cmake --build "$build" --target twincal_export_layout
python=""
for candidate in "${TWINCAL_PYTHON:-}" /usr/bin/python3 python3; do
  if [[ -n "$candidate" ]] && "$candidate" -c "import matplotlib" 2>/dev/null; then
    python=$candidate
    break
  fi
done
if [[ -z "$python" ]]; then
  echo "plot_layouts.sh: no Python with matplotlib (tried \$TWINCAL_PYTHON, /usr/bin/python3," \
    "python3); install python3-matplotlib or set TWINCAL_PYTHON" >&2
  exit 1
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for which in body door; do
  "$build/sheet_metal/twincal_export_layout" "$which" > "$tmp/$which.json"
  "$python" sheet_metal/tools/plot_layout.py "$tmp/$which.json" "docs/images/${which}_layout.png"
done
