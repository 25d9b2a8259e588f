#!/usr/bin/env bash
# Same input, same seed, any thread count: `map`, `localize`, `relocalize`, `sweep mapping` and
# `sweep place` run at 1, 2 and 8 threads (8 is more than CI's cores: --threads runs that many
# anyway) on the first 600 scans of the bundled FR079 log, and every output they write is
# compared with the one-thread run byte for byte. Values that are wall times by nature (keys and
# columns with "seconds" in the name) are the only ones allowed to differ, and only in their value:
# same keys in the same order, same rows in the same order, same columns.
# Usage: determinism_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$(realpath "$1")
source_dir=$(realpath "$2")
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"

# 600 scans (each a VERTEX2 and a ROBOTLASER1 line): revisits enough for answers to compare.
log=$work/fr079-600.log.gz
zcat "$source_dir/data/fr079-corrected.log.gz" | head -1200 | gzip >"$log"

# same_but_times REFERENCE OTHER: byte-identical, or differing only in the values of timing
# fields (JSON keys / TSV and CSV columns named *seconds*); prints the first other difference.
same_but_times() {
  cmp -s "$1" "$2" && return 0
  /usr/bin/python3 - "$1" "$2" <<'EOF'
import json, sys
a_path, b_path = sys.argv[1], sys.argv[2]
timing = lambda name: 'seconds' in name
def walk(a, b, where, timed):
    if timed and isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return None
    if type(a) is not type(b):
        return where
    if isinstance(a, list) and a and isinstance(a[0], tuple):  # an object: key order matters
        if [k for k, _ in a] != [k for k, _ in b]:
            return where + ' (keys)'
        for (k, x), (_, y) in zip(a, b):
            found = walk(x, y, where + '/' + k, timing(k))
            if found: return found
        return None
    if isinstance(a, list):
        if len(a) != len(b):
            return where + ' (length)'
        for i, (x, y) in enumerate(zip(a, b)):
            found = walk(x, y, f'{where}[{i}]', timed)
            if found: return found
        return None
    return None if a == b else where
if a_path.endswith('.json'):
    load = lambda p: json.load(open(p), object_pairs_hook=lambda pairs: pairs or [('', None)])
    found = walk(load(a_path), load(b_path), '', False)
else:
    sep = ',' if a_path.endswith('.csv') else '\t'
    a, b = open(a_path).read().split('\n'), open(b_path).read().split('\n')
    header = a[0].split(sep)
    found = None if a[0] == b[0] and len(a) == len(b) else 'header or row count'
    for line, (x, y) in enumerate(zip(a, b)):
        if found: break
        x, y = x.split(sep), y.split(sep)
        if len(x) != len(y):
            found = f'line {line + 1} (columns)'
        for column, (u, v) in enumerate(zip(x, y)):
            if u != v and not (column < len(header) and timing(header[column])):
                found = f'line {line + 1}, column {header[column] if column < len(header) else column}'
                break
if found:
    print(f'{b_path} differs from {a_path} at {found}')
    sys.exit(1)
EOF
}

# Each thread count in its own directory with the same relative names, since the JSON records the
# paths it was given; each on its own map, so that the whole chain runs at that thread count.
for threads in 1 2 8; do
  mkdir -p "$work/t$threads"
  cd "$work/t$threads" || exit 1
  check "map, $threads threads" "$keyplace" map ../fr079-600.log.gz --threads "$threads" \
    --out map.kpm --json map.json
  check "localize, $threads threads" "$keyplace" localize --map map.kpm --log ../fr079-600.log.gz \
    --n-pos 20 --threads "$threads" --json localize.json --queries queries.tsv --curve curve.tsv \
    --reliability reliability.tsv
  check "relocalize, $threads threads" "$keyplace" relocalize --map map.kpm \
    --log ../fr079-600.log.gz --starts 4 --threads "$threads" --json relocalize.json \
    --tsv starts.tsv --fixes fixes.tsv
  check "sweep mapping, $threads threads" "$keyplace" sweep mapping --log ../fr079-600.log.gz \
    --scans 0:300 --s-min 0.2,0.4 --lg 0.1,0.15 --threads "$threads" --out sweep-mapping
  check "sweep place, $threads threads" "$keyplace" sweep place --map-log ../fr079-600.log.gz \
    --scans 0:300 --n-pos 10 --mu 5,10 --gamma-min 0.2,0.4 --lambda 0.05 --threads "$threads" \
    --out sweep-place
done
cd "$work" || exit 1

outputs=(map.kpm map.json localize.json queries.tsv curve.tsv reliability.tsv relocalize.json
  starts.tsv fixes.tsv sweep-mapping/sweep.json sweep-mapping/results.csv
  sweep-mapping/results.json sweep-place/sweep.json sweep-place/results.csv
  sweep-place/results.json)
for threads in 2 8; do
  # The map file is compared whole: SQLite pages, header counters and all.
  check "map.kpm byte-identical at 1 and $threads threads" cmp "$work/t1/map.kpm" \
    "$work/t$threads/map.kpm"
  for output in "${outputs[@]:1}"; do
    check "$output at 1 and $threads threads" same_but_times "$work/t1/$output" \
      "$work/t$threads/$output"
  done
done

# --cache: the second run reads the ICP poses and keypoints the first one wrote, and its figures
# are those of a run without the cache.
cd "$work/t2" || exit 1
for run in plain first second; do
  cache=()
  [ "$run" = plain ] || cache=(--cache cache)
  check "localize --poses icp ($run)" "$keyplace" localize --map map.kpm \
    --log ../fr079-600.log.gz --poses icp --n-pos 20 --threads 2 "${cache[@]}" \
    --json "icp-$run.json" --queries "icp-$run.tsv"
  cp "$work/err" "icp-$run.err"
done
check "the first --cache run computes" test "$(grep -c 'read from the cache' icp-first.err)" = 0
check "the second --cache run reads the cache" grep -q \
  'poses and keypoints of fr079-600.log.gz read from the cache' icp-second.err
check "the JSON says where the preparation came from" /usr/bin/python3 -c "
import json, sys
assert [json.load(open(p))['preparation_from_cache'] for p in sys.argv[1:]] == [False, True]" \
  icp-plain.json icp-second.json
for run in plain second; do  # that field aside, the figures are the same
  /usr/bin/python3 -c "
import json, sys
j = json.load(open(sys.argv[1]))
del j['preparation_from_cache']
json.dump(j, open(sys.argv[2], 'w'), indent=2)" "icp-$run.json" "icp-$run-figures.json"
done
check "icp-second.json equals the run without cache" same_but_times icp-plain-figures.json \
  icp-second-figures.json
check "icp-second.tsv equals the run without cache" same_but_times icp-plain.tsv icp-second.tsv
cd "$work" || exit 1

# The comparison compares something: answers were given and fixes reported.
check "localize accepted answers" /usr/bin/python3 -c "
import json, sys
j = json.load(open(sys.argv[1]))
assert j['n_acc'] > 0, j['n_acc']" "$work/t1/localize.json"
check "relocalize fixes" test "$(($(wc -l <"$work/t1/fixes.tsv") - 1))" -gt 0
check "sweep rows" test "$(($(wc -l <"$work/t1/sweep-place/results.csv") - 1))" = 4
# ... and a difference outside the timings would be caught.
awk 'BEGIN { FS = OFS = "\t" } NR == 2 { $3 += 1 } 1' "$work/t1/queries.tsv" >"$work/changed.tsv"
if same_but_times "$work/t1/queries.tsv" "$work/changed.tsv" >/dev/null; then
  fail "a changed query row passed the comparison"
else
  ok
fi

finish determinism
