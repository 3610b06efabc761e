#!/usr/bin/env bash
# Runs the fuzz targets of a GRAVCAL_FUZZ build.
#   fuzz/run_fuzz.sh <build dir> <target|all> <seconds per target>
# With FUZZ_SEED=<n>, libFuzzer's random choices start from that seed (CI
# uses 1: the same inputs in the same order on every machine, so a finding
# is found again here, though a time budget may stop earlier or later on a
# slower machine). With FUZZ_RUNS=<n>, each target runs n inputs from seed
# 1 instead of a time (exactly reproducible).
# Targets named in FUZZ_REGRESSIONS_ONLY (space separated) only run their
# regression inputs.
# Each target first runs its regression inputs (fuzz/regressions/<target>/,
# inputs that once crashed or broke an invariant, kept after the fix), then
# fuzzes for the given time from the seed corpus (fuzz/corpus/<target>/ and
# the test data named in fuzz/CMakeLists.txt), with a working corpus in
# <build dir>/fuzz/corpus_run/<target>. New crashes land in
# <build dir>/fuzz/crashes/<target>/ and fail the run.
set -euo pipefail
build=$1
which=$2
seconds=$3
here="$(cd "$(dirname "$0")" && pwd)"
# all: every fuzz_<name> executable the build made.
if [ "$which" = all ]; then
  targets=$(cd "$build/fuzz" && ls fuzz_* | sed -n 's/^fuzz_\([a-z0-9_]*\)$/\1/p')
else
  targets=$which
fi
# With FUZZ_JOBS=<n>, n targets run at once (CI: 2, one per core); each
# target's failure leaves a mark in <build dir>/fuzz/failed/.
failed="$build/fuzz/failed"
rm -rf "$failed"
mkdir -p "$failed"
run_target() {
  local t=$1
  local exe="$build/fuzz/fuzz_$t"
  local work="$build/fuzz/corpus_run/$t"
  local crashes="$build/fuzz/crashes/$t"
  mkdir -p "$work" "$crashes"
  if [ -d "$here/regressions/$t" ] && [ -n "$(ls -A "$here/regressions/$t")" ]; then
    "$exe" -runs=0 "$here/regressions/$t"/* >/dev/null 2>&1 || {
      echo "fuzz: $t fails on a regression input"
      touch "$failed/$t"
    }
  fi
  case " ${FUZZ_REGRESSIONS_ONLY:-} " in *" $t "*)
    echo "fuzz: $t ran its regression inputs only"
    return
    ;;
  esac
  local start=$SECONDS
  local budget=(-max_total_time="$seconds")
  if [ -n "${FUZZ_SEED:-}" ]; then budget+=(-seed="$FUZZ_SEED"); fi
  if [ -n "${FUZZ_RUNS:-}" ]; then budget=(-runs="$FUZZ_RUNS" -seed=1); fi
  if ! "$exe" "${budget[@]}" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
    -artifact_prefix="$crashes/" -print_final_stats=1 "$work" "$build/fuzz/seeds/$t" \
    >"$build/fuzz/$t.log" 2>&1; then
    echo "fuzz: $t FOUND A PROBLEM (see $build/fuzz/$t.log, input in $crashes)"
    tail -30 "$build/fuzz/$t.log"
    touch "$failed/$t"
  fi
  local runs
  runs=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$build/fuzz/$t.log" | awk '{print $2}')
  echo "fuzz: $t ran $((SECONDS - start)) s, ${runs:-?} inputs"
}
for t in $targets; do
  while [ "$(jobs -rp | wc -l)" -ge "${FUZZ_JOBS:-1}" ]; do wait -n || true; done
  run_target "$t" &
done
wait
[ -z "$(ls -A "$failed")" ]
