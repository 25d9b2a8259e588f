#!/usr/bin/env bash
# keyplace sweep: an interrupted sweep (a --stop-after hook, and a real kill -9 half-way) resumes
# without redoing finished points and ends with the same table as an uninterrupted run on another
# thread count; each interruption is checked to have come before the sweep finished (some rows
# written, not all), else the resume would test nothing; a different sweep in the same directory
# is refused; bad value lists give clear errors. The place sweep evaluates the points of one
# lambda together (one recognition per query for every mu and gamma_min), so its rows come in
# groups. Usage: sweep_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
log="$source_dir/data/fr079-corrected.log.gz"
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"

# The table without the timing column (the last one), rows sorted: what must not depend on
# interruptions, thread count or completion order.
table() { cut -d, -f1-"$(($(head -1 "$1" | tr ',' '\n' | wc -l) - 1))" "$1" | sort; }
rows() { echo $(($(wc -l <"$1") - 1)); }

place_args=(sweep place --map-log "$log" --scans 0:300 --n-pos 40 --mu 5,10 --gamma-min 0:0.8:0.2
  --lambda 0.05,0.1)
place_group=10  # points per lambda: 2 mu x 5 gamma_min
mapping_args=(sweep mapping --log "$log" --scans 0:300 --s-min 0.1:0.5:0.1 --lg 0.05,0.1,0.15)

for kind in place mapping; do
  if [ "$kind" = place ]; then args=("${place_args[@]}"); else args=("${mapping_args[@]}"); fi
  # Uninterrupted reference, one thread.
  if "$keyplace" "${args[@]}" --threads 1 --out "$work/$kind-ref" >"$work/out" 2>&1; then ok; else
    fail "$kind: reference run"
    cat "$work/out"
  fi
  total=$(rows "$work/$kind-ref/results.csv")
  # Stopped after 4 points, then resumed on 2 threads. Exactly the points started finish (no
  # kill): 4 of the mapping sweep, the first group (one lambda) of the place sweep; the grid must
  # be larger than that.
  "$keyplace" "${args[@]}" --threads 2 --stop-after 4 --out "$work/$kind-cut" >"$work/out1" 2>&1
  first=$(rows "$work/$kind-cut/results.csv")
  if [ "$kind" = place ]; then started=$place_group; else started=4; fi
  if [ "$first" -eq "$started" ] && [ "$first" -lt "$total" ]; then ok; else
    fail "$kind: --stop-after 4 left $first of $total rows, expected $started"
  fi
  "$keyplace" "${args[@]}" --threads 2 --out "$work/$kind-cut" --json "$work/$kind.json" \
    >"$work/out2" 2>&1
  if grep -q "points, $first done before" "$work/out2"; then ok; else
    fail "$kind: resume did not skip the $first finished points"
    head -3 "$work/out2"
  fi
  if [ "$(grep -c '^\[' "$work/out2")" = "$((total - first))" ]; then ok; else
    fail "$kind: resume computed $(grep -c '^\[' "$work/out2") points, expected $((total - first))"
  fi
  if grep -q "^$total rows in .*($total grid points, $((total - first)) computed now)" \
    "$work/out2"; then ok; else
    fail "$kind: resume summary is not '$total rows ... $((total - first)) computed now'"
    tail -1 "$work/out2"
  fi
  if diff <(table "$work/$kind-ref/results.csv") <(table "$work/$kind-cut/results.csv") \
    >"$work/diff"; then ok; else
    fail "$kind: resumed table differs from the uninterrupted one"
    head -10 "$work/diff"
  fi
  # results.json holds every row, sorted by point.
  if python3 - "$work/$kind-cut/results.json" "$total" <<'EOF'; then ok; else fail "$kind: results.json"; fi
import json, sys
j = json.load(open(sys.argv[1]))
keys = [tuple(r[p] for p in j["parameters"]) for r in j["rows"]]
assert len(keys) == int(sys.argv[2]), (len(keys), sys.argv[2])
assert keys == sorted(keys), "rows not sorted"
EOF
  # --json: the same rows as results.json, with what this run did (the resume: total - first).
  if python3 - "$work/$kind-cut/results.json" "$work/$kind.json" "$total" "$first" \
    "$work/$kind-cut" <<'EOF'; then ok; else fail "$kind: --json"; fi
import json, sys
results, j = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
total, first = int(sys.argv[3]), int(sys.argv[4])
for key in ("sweep", "parameters", "columns", "rows"):
    assert j[key] == results[key], key
assert j["grid_points"] == total and j["computed_now"] == total - first, j
assert j["out"] == sys.argv[5] and j["seconds_total"] > 0, j
EOF
done

# A real interruption: kill -9 half-way through a place sweep, then resume. Its three groups (one
# per lambda) of the whole log take seconds each on one thread; the kill must hit the sweep while
# it runs (kill succeeds, the exit status is SIGKILL's) and leave rows missing.
kill_args=(sweep place --map-log "$log" --n-pos 60 --mu 5,10 --gamma-min 0:0.8:0.4
  --lambda 0.05,0.1,0.15)
"$keyplace" "${kill_args[@]}" --threads 1 --out "$work/killed" >/dev/null 2>&1 &
pid=$!
total=18
for _ in $(seq 1 2400); do  # up to 2 minutes on a loaded machine; half-way takes ~10 s alone
  [ -f "$work/killed/results.csv" ] && [ "$(rows "$work/killed/results.csv")" -ge $((total / 2)) ] && break
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.05
done
if kill -9 "$pid" 2>/dev/null; then killed=yes; else killed=no; fi
wait "$pid" 2>/dev/null
status=$?
before=$(rows "$work/killed/results.csv")
echo "killed with $before of $total rows written (kill succeeded: $killed, exit status $status)"
if [ "$killed" = yes ] && [ "$status" -eq 137 ]; then ok; else
  fail "kill -9 did not hit a running sweep (kill succeeded: $killed, exit status $status)"
fi
if [ "$before" -ge 1 ] && [ "$before" -lt "$total" ]; then ok; else
  fail "kill -9 left $before of $total rows: it must come after the first row, before the last"
fi
if "$keyplace" "${kill_args[@]}" --threads 2 --out "$work/killed" >"$work/out" 2>&1; then ok; else
  fail "resume after kill -9"
  cat "$work/out"
fi
# The resume keeps every row written before the kill and computes only the missing points.
if grep -q "$total points, $before done before" "$work/out" &&
  [ "$(grep -c '^\[' "$work/out")" = "$((total - before))" ] &&
  grep -q "^$total rows in .*($total grid points, $((total - before)) computed now)" "$work/out"
then ok; else
  fail "resume after kill -9 at $before of $total rows: not just the $((total - before)) missing"
  grep -v '^\[' "$work/out"
fi
"$keyplace" "${kill_args[@]}" --threads 2 --out "$work/unkilled" >/dev/null 2>&1
if diff <(table "$work/unkilled/results.csv") <(table "$work/killed/results.csv") >/dev/null; then
  ok
else fail "table after kill -9 at $before of $total rows differs from an uninterrupted run"; fi

# Another sweep in the same directory is refused, naming what differs.
if "$keyplace" sweep place --map-log "$log" --scans 0:200 --n-pos 40 --out "$work/place-ref" \
  >"$work/out" 2>&1; then fail "a different sweep was resumed"; elif
  grep -q "holds a different sweep ('scans'" "$work/out"; then ok; else
  fail "refusal message"
  cat "$work/out"
fi

# --json onto one of the sweep's own files (its resume identity) is refused before any work, and
# the file stays as it was.
cp "$work/mapping-ref/sweep.json" "$work/identity-before.json"
for own in sweep.json results.csv results.json; do
  if "$keyplace" sweep mapping --log "$log" --scans 0:50 --s-min 0.2 --out "$work/mapping-ref" \
    --json "$work/mapping-ref/$own" >"$work/out" 2>&1; then fail "--json $own in --out accepted"; elif
    grep -q "is the sweep's own file" "$work/out"; then ok; else
    fail "--json $own: refusal message"
    cat "$work/out"
  fi
done
if [ -f "$work/identity-before.json" ]; then
  if cmp -s "$work/mapping-ref/sweep.json" "$work/identity-before.json"; then ok; else
    fail "the refused --json changed the sweep's identity"
  fi
fi

# Bad value lists.
for bad in "0:1" "0:1:0" "1:0:0.1" "0.1,x" "" "0.1,0.1"; do
  if "$keyplace" sweep mapping --log "$log" --scans 0:50 --s-min "$bad" --out "$work/bad" \
    >"$work/out" 2>&1; then fail "--s-min '$bad' accepted"; elif
    grep -q -- "--s-min" "$work/out"; then ok; else
    fail "--s-min '$bad': error does not name the option"
    cat "$work/out"
  fi
done

finish sweep_test
