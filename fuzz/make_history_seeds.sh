#!/usr/bin/env bash
# Writes the history_replay fuzzer's seeds: small histories of `twincal serve` on the analytic
# twin (d = 3), checkpointed so that the whole history is in the database file. The seeds in
# corpus/history_replay were written by this script (their timestamps differ on every run).
#   fuzz/make_history_seeds.sh build/apps/twincal/twincal
set -euo pipefail
twincal="${1:?usage: make_history_seeds.sh path/to/twincal}"
out="$(cd "$(dirname "$0")" && pwd)/corpus/history_replay"
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$out"

# seed NAME CONTROLLER SNAPSHOT_EVERY OBSERVATIONS [pending]
seed() {
  local name="$1" controller="$2" every="$3" observations="$4" pending="${5:-}"
  {
    for ((i = 1; i <= observations; i++)); do
      echo "{\"op\": \"propose\", \"assembly\": $((i * 7 % 100))}"
      echo "{\"op\": \"observe\", \"request_id\": $i, \"quality\": 0.$((30 + i))}"
    done
    [ -z "$pending" ] || echo "{\"op\": \"propose\", \"assembly\": 5}"
    echo '{"op": "checkpoint"}'
  } | "$twincal" serve --db "$scratch/$name.db" --case analytic --locators all \
        --controller "$controller" --snapshot-every "$every" --durability normal >/dev/null
  cp "$scratch/$name.db" "$out/$name.db"
}
seed active_snapshots active 2 3
seed active_pending active 0 2 pending
seed w1 w=1 1 2
echo "wrote $(ls "$out" | wc -l) seeds to $out"
