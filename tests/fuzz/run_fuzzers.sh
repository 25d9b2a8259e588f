#!/usr/bin/env bash
# Runs the libFuzzer programs of a KEYPLACE_FUZZ build (make fuzz), FUZZ_JOBS at a time, each for
# SECONDS on a fixed SEED, on a scratch copy of its seed corpus and regression inputs (generated
# inputs never land in the repository), with its dictionary, a time limit per input and memory
# limits. Prints one line per harness; exits 1 when any harness found something, whose input is
# then kept in FUZZ_DIR/findings/NAME/ (docs/RELIABILITY.md, Fuzzing: what to do with it).
#
# Usage: tests/fuzz/run_fuzzers.sh FUZZ_DIR SECONDS SEED [NAME...]   (default: every NAME_fuzz)
# Extra libFuzzer options (e.g. -runs=1000000 for a long run) come from FUZZ_OPTIONS.
set -euo pipefail

if [ $# -lt 3 ]; then
  echo "usage: $0 FUZZ_DIR SECONDS SEED [NAME...]" >&2
  exit 2
fi
fuzz_dir=$(cd "$1" && pwd)
seconds=$2
seed=$3
shift 3
here=$(cd "$(dirname "$0")" && pwd)
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for program in "$fuzz_dir"/tests/fuzz/*_fuzz; do
    names+=("$(basename "$program" _fuzz)")
  done
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/keyplace-fuzz.XXXXXX")
trap 'rm -rf "$work"' EXIT

# Leaks are findings too; system libraries' are suppressed as in make test-sanitize.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:check_initialization_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$here/../sanitizers/lsan.supp:print_suppressions=0}

# run_one NAME: fuzzes one harness; its summary line goes to $work/NAME.line, and NAME to
# $work/NAME.failed when it found something.
run_one() {
  local name=$1
  local program=$fuzz_dir/tests/fuzz/${name}_fuzz
  local corpus=$work/$name
  local findings=$fuzz_dir/findings/$name
  mkdir -p "$corpus" "$findings"
  cp "$here/corpus/$name"/* "$corpus"/
  if [ -d "$here/regressions/$name" ]; then cp "$here/regressions/$name"/* "$corpus"/; fi
  # -timeout: an input taking 10 s is a hang; -malloc_limit_mb: one allocation of 1 GiB from a
  # small input is a finding, as is a process growing beyond 2 GiB.
  local options=(-seed="$seed" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048
                 -malloc_limit_mb=1024 -print_final_stats=1 -artifact_prefix="$findings/")
  if [ -f "$here/dict/$name.dict" ]; then options+=(-dict="$here/dict/$name.dict"); fi
  # shellcheck disable=SC2206  # FUZZ_OPTIONS is a list of options
  options+=(${FUZZ_OPTIONS:-})
  local log=$fuzz_dir/findings/$name.log
  local start_ns status=ok
  start_ns=$(date +%s%N)
  "$program" "${options[@]}" "$corpus" >"$log" 2>&1 || status=FINDING
  local wall_ms=$((($(date +%s%N) - start_ns) / 1000000))
  local runs coverage
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  coverage=$(grep -oE 'cov: [0-9]+ ft: [0-9]+' "$log" | tail -1 || true)
  printf 'fuzz %-12s %-7s %10s runs %5d.%01d s %s\n' "$name" "$status" "${runs:-?}" \
    $((wall_ms / 1000)) $((wall_ms % 1000 / 100)) "${coverage:-}" >"$work/$name.line"
  if [ "$status" != ok ]; then
    {
      grep -E 'ERROR|SUMMARY|fuzz finding|Test unit written|deadly signal' "$log" | head -20 || true
      echo "full log: $log; inputs: $findings/"
    } >"$work/$name.failed"
  fi
}

# FUZZ_JOBS harnesses at a time (default: one per core): each is one single-threaded process, so
# on CI's 2 cores the stage takes half the time of one after the other.
jobs=${FUZZ_JOBS:-$(nproc)}
for name in "${names[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
  run_one "$name" &
done
wait

failed=()
for name in "${names[@]}"; do
  cat "$work/$name.line"
  if [ -f "$work/$name.failed" ]; then
    failed+=("$name")
    cat "$work/$name.failed" >&2
  fi
done

if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in ${failed[*]} (keep each input in tests/fuzz/regressions/NAME/ with its fix)" >&2
  exit 1
fi
