#!/usr/bin/env bash
# keyplace merge (issue 16) on the bundled log: the first half and the second half, each mapped in
# its own frame (--start-at-origin), are merged; the recovered transform is checked against the
# corrected poses of the log; a map of another building (shared Intel log) is refused with the reason, and nothing
# is written. Usage: merge_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
log="$source_dir/data/fr079-corrected.log.gz"
shared=${KEYPLACE_SHARED:-$source_dir/../shared}
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"
export KEYPLACE_PROGRESS=0

check "merge --help" "$keyplace" merge --help
check "map first half" "$keyplace" map "$log" --scans 0:732 --start-at-origin --out "$work/a.kpm"
check "map second half" "$keyplace" map "$log" --scans 732: --start-at-origin --out "$work/b.kpm"
check "merge" "$keyplace" merge "$work/a.kpm" "$work/b.kpm" --out "$work/ab.kpm" \
  --json "$work/merge.json"
cp "$work/err" "$work/merge.err"
# Truth: B's frame is the corrected pose of scan 732 seen from that of scan 0 (A's frame).
check "transform against the corrected poses" python3 -c "
import gzip, json, math, sys
poses = []
for line in gzip.open(sys.argv[1], 'rt'):
    f = line.split()
    if f and f[0] == 'ROBOTLASER1':
        n = int(f[8]); m = int(f[9 + n])
        poses.append(tuple(map(float, f[9 + n + 1 + m + 3:9 + n + 1 + m + 6])))
(x0, y0, t0), (x1, y1, t1) = poses[0], poses[732]
c, s = math.cos(-t0), math.sin(-t0)
truth = (c * (x1 - x0) - s * (y1 - y0), s * (x1 - x0) + c * (y1 - y0), t1 - t0)
j = json.load(open(sys.argv[2]))
T = j['T_a_b']
error_m = math.hypot(T['x_m'] - truth[0], T['y_m'] - truth[1])
error_deg = abs(math.degrees(math.remainder(T['theta_rad'] - truth[2], 2 * math.pi)))
print('translation error %.3f m, rotation error %.3f deg' % (error_m, error_deg))
assert error_m < 0.1 and error_deg < 0.5, (T, truth)
assert j['agreeing'] >= 3 and j['agreeing'] <= j['recognised'] <= j['submaps_queried'], j
assert sum(r['agrees'] for r in j['recognitions']) == j['agreeing'], j
" "$log" "$work/merge.json"
check "merge --help mentions the progress line" grep -q "KEYPLACE_PROGRESS" <("$keyplace" merge --help)
# Progress: none on stderr when it is not a terminal (KEYPLACE_PROGRESS=0 above stands for that);
# with KEYPLACE_PROGRESS=1 the line of the other commands, counting B's submaps, ending with all
# of them done.
check "merge quiet" test ! -s "$work/merge.err"
KEYPLACE_PROGRESS=1 "$keyplace" merge "$work/a.kpm" "$work/b.kpm" --out "$work/ab2.kpm" \
  >/dev/null 2>"$work/progress.err"
check "merge progress line" python3 -c "
import json, re, sys
text = open(sys.argv[1]).read()
queried = json.load(open(sys.argv[2]))['submaps_queried']
assert re.search(r'submaps of B  %d/%d  done in [0-9.]+ s' % (queried, queried), text), text
" "$work/progress.err" "$work/merge.json"
check "merged map readable" "$keyplace" info "$work/ab.kpm" --json "$work/ab.json"
check "merged map holds both" python3 -c "
import json, sys
j = json.load(open(sys.argv[1])); m = json.load(open(sys.argv[2]))
assert j['submaps'] == m['submaps_merged'], (j['submaps'], m)
" "$work/ab.json" "$work/merge.json"
# The merged map is in A's frame (scan 0's pose), not the log's: localize says so instead of
# scoring against the log's poses without a word.
"$keyplace" localize --map "$work/ab.kpm" --log "$log" --n-pos 5 >"$work/loc.out" 2>"$work/loc.err"
check "localize warns about the frame" grep -q "first-scan frame" "$work/loc.err"

# Refusals: another building (the Intel lab, shared data) and different mapping settings.
# Nothing is written.
check "map intel" "$keyplace" map "$shared/data/intel-corrected.log.gz" --scans 0:600 \
  --start-at-origin --out "$work/intel.kpm"
fails_with "another building refused" "no reliable overlap" "$keyplace" merge "$work/a.kpm" \
  "$work/intel.kpm" --out "$work/refused.kpm"
check "nothing written when refused" test ! -e "$work/refused.kpm"
check "map other settings" "$keyplace" map "$log" --scans 732: --out "$work/coarse.kpm" \
  --set mapping.cell_size_m=0.2
fails_with "other settings refused" "different mapping settings" "$keyplace" merge \
  "$work/a.kpm" "$work/coarse.kpm" --out "$work/refused.kpm"
fails_with "--out required" "--out" "$keyplace" merge "$work/a.kpm" "$work/b.kpm"
fails_with "bad merge setting" "merge.min_agreeing" "$keyplace" merge "$work/a.kpm" \
  "$work/b.kpm" --out "$work/x.kpm" --set merge.min_agreeing=0

finish merge
