#!/usr/bin/env bash
# keyplace merge (issue 16) on the bundled log: the first half and the second half, each mapped in
# its own frame (--start-at-origin), are merged; the recovered transform is checked against the
# corrected poses of the log. Then the real case on the raw FR079 log (shared data): two slices
# mapped from ICP poses, each in its own odometry frame, merged, and the error of the transform
# reported by merge --log/--truth/--index checked against a computation of its own here. A map of
# another building (shared Intel log) is refused with the reason, and nothing is written.
# Usage: merge_test.sh KEYPLACE_BINARY SOURCE_DIR
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
# The real case: raw odometry (FR079_r, shared data), each slice mapped from ICP poses (map's
# default for a raw log) starting at the origin of its own frame: raw scans 0:874 and 874:1674
# (corrected scans 0:250 and 250:500; the second slice walks back through the first's rooms).
raw="$shared/data/fr079-raw.log.gz"
corrected="$shared/data/fr079-corrected.log.gz"
index="$shared/data/fr079-raw-to-corrected.tsv"
check "map raw first slice" "$keyplace" map "$raw" --scans 0:874 --start-at-origin \
  --out "$work/raw-a.kpm" --json "$work/raw-a.json"
check "map raw second slice" "$keyplace" map "$raw" --scans 874:1674 --start-at-origin \
  --out "$work/raw-b.kpm"
check "raw slices use icp poses" python3 -c "
import json, sys
assert json.load(open(sys.argv[1]))['pose_source'] == 'icp'
" "$work/raw-a.json"
check "merge raw slices with the truth" "$keyplace" merge "$work/raw-a.kpm" "$work/raw-b.kpm" \
  --out "$work/raw-ab.kpm" --log "$raw" --truth "$corrected" --index "$index" \
  --json "$work/raw-merge.json"
cp "$work/out" "$work/raw-merge.out"
check "merge prints the errors" grep -q "error at the origins .* m, .* deg" "$work/raw-merge.out"
# Truth here, from the files alone: raw scans 0 and 874 are corrected scans 0 and 250 and the
# slices' first scans, so each map's frame is that scan's pose (identity in its own map) and the
# true frame of B in A is C(0)^-1 C(250).
check "raw merge error against the corrected poses" python3 -c "
import gzip, json, math, sys
poses = []
for line in gzip.open(sys.argv[1], 'rt'):
    f = line.split()
    if f and f[0] == 'ROBOTLASER1':
        n = int(f[8]); m = int(f[9 + n])
        poses.append(tuple(map(float, f[9 + n + 1 + m + 3:9 + n + 1 + m + 6])))
pairs = dict(tuple(map(int, l.split())) for l in open(sys.argv[2]) if l.split()[0].isdigit())
assert pairs[0] == 0 and pairs[874] == 250, 'index file changed'
(x0, y0, t0), (x1, y1, t1) = poses[0], poses[250]
c, s = math.cos(-t0), math.sin(-t0)
truth = (c * (x1 - x0) - s * (y1 - y0), s * (x1 - x0) + c * (y1 - y0), t1 - t0)
j = json.load(open(sys.argv[3]))
T = j['T_a_b']
error_m = math.hypot(T['x_m'] - truth[0], T['y_m'] - truth[1])
error_deg = abs(math.degrees(math.remainder(T['theta_rad'] - truth[2], 2 * math.pi)))
e = j['evaluation']
o = e['at_origins']
assert (o['scan_a'], o['scan_b']) == (0, 874), o
t = o['true_T_a_scan_b']
assert abs(t['x_m'] - truth[0]) < 1e-6 and abs(t['y_m'] - truth[1]) < 1e-6, (t, truth)
assert abs(math.remainder(t['theta_rad'] - truth[2], 2 * math.pi)) < 1e-6, (t, truth)
assert abs(o['translation_error_m'] - error_m) < 1e-6, (o, error_m)
assert abs(o['rotation_error_deg'] - error_deg) < 1e-6, (o, error_deg)
print('raw FR079 slices: at the origins %.3f m, %.3f deg' % (error_m, error_deg))
# Both ICP trajectories drift over ~100 m: the frames agree to within a metre and 5 degrees.
assert error_m < 1.0 and error_deg < 5.0, (error_m, error_deg)
r = e['at_recognitions']
assert r['count'] == j['agreeing'] >= 3 and r['without_truth'] == 0, r
assert len(r['items']) == r['count']
# Each recognition alone is accurate (the place recognition); the one rigid transform for all of
# B is not as accurate everywhere (drift along B), but better than at the origins on average.
a = e['recognitions_alone']
assert a['translation_mean_m'] < 0.1 and a['rotation_mean_deg'] < 1.0, a
assert a['translation_mean_m'] < r['translation_mean_m'] < 1.0, (a, r)
" "$corrected" "$index" "$work/raw-merge.json"
fails_with "--truth without --log" "need --log" "$keyplace" merge "$work/raw-a.kpm" \
  "$work/raw-b.kpm" --out "$work/x.kpm" --truth "$corrected" --index "$index"
fails_with "maps of another log" "was made from fr079-raw.log.gz" "$keyplace" merge \
  "$work/raw-a.kpm" "$work/raw-b.kpm" --out "$work/x.kpm" --log "$log"
check "nothing written when the truth is refused" test ! -e "$work/x.kpm"

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
