#!/usr/bin/env bash
# keyplace relocalize end to end on the bundled corrected FR079 log: the kidnapped-robot benchmark
# under protocol (a) (the map's own log, submaps sharing a scan with the query excluded) and (b)
# (time split: the map from scans 0:700, the starts from 700:), its outputs, the JSON keys scripts
# read, and clear errors. Usage: relocalize_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"
log="$source_dir/data/fr079-corrected.log.gz"

check "relocalize --help" "$keyplace" relocalize --help
check "map" "$keyplace" map "$log" --out "$work/map.kpm"
check "relocalize (a)" "$keyplace" relocalize --map "$work/map.kpm" --log "$log" --starts 12 \
  --threads 2 --json "$work/a.json" --tsv "$work/a.tsv" --figure "$work/a.png" \
  --fixes "$work/a_fixes.tsv" --initialpose "$work/fix.json"
# (The same figures at any thread count: cli.determinism.) The fix as YAML and as JSON from the
# same short run (3 starts in the first 300 scans).
for format in json yaml; do
  check "relocalize --initialpose .$format" "$keyplace" relocalize --map "$work/map.kpm" \
    --log "$log" --scans 0:300 --starts 3 --initialpose "$work/short-fix.$format"
done
check "the YAML fix is the JSON's" /usr/bin/python3 -c "
import json, sys
pose = json.load(open(sys.argv[1]))['pose']['pose']
yaml = open(sys.argv[2]).read()
assert 'frame_id: map' in yaml and 'covariance: [' in yaml, yaml
x = pose['position']['x']
assert repr(x) in yaml or ('x: %r' % x) in yaml, (x, yaml)
" "$work/short-fix.json" "$work/short-fix.yaml"
check "figure" test -s "$work/a.png"
# --initialpose: the first fix of the first start that got one, as a PoseWithCovarianceStamped
# (issue 16), the same in JSON and YAML, at that fix's pose and near its truth.
check "initial pose" /usr/bin/python3 -c "
import csv, json, math, sys
message = json.load(open(sys.argv[1]))
assert message['header']['frame_id'] == 'map', message
pose = message['pose']['pose']
q = pose['orientation']
assert abs(q['x']) == 0 and abs(q['y']) == 0 and abs(q['z']**2 + q['w']**2 - 1) < 1e-9, q
covariance = message['pose']['covariance']
assert len(covariance) == 36, covariance
# Derived from the match (docs/NAVIGATION.md): a symmetric, positive definite (x, y, yaw) block in
# rows/columns 0, 1, 5 with its off-diagonal terms, z, roll and pitch 0; a verified match of
# FLIRT keypoints is good to decimetres and a few degrees, not metres.
import numpy
full = numpy.array(covariance).reshape(6, 6)
block = full[numpy.ix_([0, 1, 5], [0, 1, 5])]
assert numpy.allclose(block, block.T) and numpy.all(numpy.linalg.eigvalsh(block) > 0), block
assert abs(full).sum() == abs(block).sum() and block[0, 1] != 0, full
assert 0.03**2 / 100 < block[0, 0] < 0.5**2 and block[2, 2] < math.radians(10)**2, block
first = [r for r in csv.DictReader(open(sys.argv[2]), delimiter='	') if r['first'] == '1'][0]
x, y = pose['position']['x'], pose['position']['y']
theta = 2 * math.atan2(q['z'], q['w'])
assert abs(x - float(first['est_x'])) < 2e-3 and abs(y - float(first['est_y'])) < 2e-3, (x, first)
assert math.hypot(x - float(first['true_x']), y - float(first['true_y'])) < 0.5, (x, y, first)
" "$work/fix.json" "$work/a_fixes.tsv"
check "TSV: one row per start" test "$(($(wc -l <"$work/a.tsv") - 1))" = 12
check "TSV columns" grep -q $'^start_scan\tend_scan\trevisit\tdistance_to_revisit_m\troom_after_revisit_m\tfixed\tscans_to_fix\tdistance_to_fix_m' \
  "$work/a.tsv"
check "JSON (a)" /usr/bin/python3 -c "
import json,sys
j = json.load(open(sys.argv[1]))
for key in ['starts', 'starts_with_revisit', 'fixed_fraction', 'starts_with_room',
            'fixed_fraction_with_room', 'revisit_room_m', 'wrong_fix_rate',
            'distance_to_fix_median_m', 'distance_to_fix_p90_m', 'update_seconds_mean',
            'update_seconds_max', 'lost_signals']:
    assert key in j, key
assert j['starts'] == 12, j['starts']
assert j['query_log_is_map_log'] and j['exclude_shared_scans'], j
# FR079 is revisited all over: most starts pass a map scan, and nearly all of those get a fix.
assert j['starts_with_revisit'] >= 8, j['starts_with_revisit']
assert j['fixed_fraction'] >= 0.8, j['fixed_fraction']
assert j['wrong_fix_rate'] <= 0.05, j['wrong_fix_rate']
assert 0 < j['distance_to_fix_median_m'] <= j['distance_to_fix_p90_m'] < 50, j
assert 0 < j['update_seconds_mean'] <= j['update_seconds_max'], j
" "$work/a.json"

check "map of scans 0:700" "$keyplace" map "$log" --scans 0:700 --out "$work/first.kpm"
check "relocalize (b)" "$keyplace" relocalize --map "$work/first.kpm" --log "$log" \
  --scans 700: --starts 8 --json "$work/b.json" --tsv "$work/b.tsv"
check "JSON (b)" /usr/bin/python3 -c "
import json,sys
j = json.load(open(sys.argv[1]))
assert j['scans'][0] == 700, j['scans']
assert j['starts'] == 8, j['starts']
assert j['wrong_fix_rate'] <= 0.05, j['wrong_fix_rate']
" "$work/b.json"
check "starts in 700:" /usr/bin/python3 -c "
import csv,sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter='\t'))
assert all(int(r['start_scan']) >= 0 for r in rows)
assert len(rows) == 8
" "$work/b.tsv"

# More starts than scans: every scan once, with a note.
check "starts capped" "$keyplace" relocalize --map "$work/map.kpm" --log "$log" --scans 0:30 \
  --starts 100 --json "$work/capped.json"
cp "$work/err" "$work/capped.err"
check "capped: 30 starts" /usr/bin/python3 -c "
import json,sys
assert json.load(open(sys.argv[1]))['starts'] == 30
" "$work/capped.json"
check "capped: note" grep -q "capped to the 30" "$work/capped.err"

fails_with "no starts" "--starts" "$keyplace" relocalize --map "$work/map.kpm" --log "$log" \
  --starts 0
fails_with "negative threads" "--threads" "$keyplace" relocalize --map "$work/map.kpm" \
  --log "$log" --threads -1
fails_with "bad range" "--scans" "$keyplace" relocalize --map "$work/map.kpm" --log "$log" \
  --scans 5:x
fails_with "bad config key" "localization.fix.nope" "$keyplace" relocalize --map "$work/map.kpm" \
  --log "$log" --set localization.fix.nope=1
fails_with "bad policy" "confirmations" "$keyplace" relocalize --map "$work/map.kpm" \
  --log "$log" --set localization.fix.confirmations=0
# Outputs are checked before any work: not the input (a copy here, the bundled log must survive a
# broken check), in a directory that exists, no two the same.
cp "$log" "$work/copy.log.gz"
fails_with "map --out is the input" "is the input" "$keyplace" map "$work/copy.log.gz" \
  --out "$work/copy.log.gz"
check "input intact" cmp "$log" "$work/copy.log.gz"
fails_with "--json is the map" "--json" "$keyplace" relocalize --map "$work/map.kpm" \
  --log "$log" --json "$work/map.kpm"
fails_with "no such directory" "does not exist" "$keyplace" relocalize --map "$work/map.kpm" \
  --log "$log" --tsv "$work/nowhere/s.tsv"
fails_with "same output twice" "also given to --json" "$keyplace" relocalize \
  --map "$work/map.kpm" --log "$log" --json "$work/x.json" --tsv "$work/x.json"
echo '{"kept": true}' >"$work/keep.json"
fails_with "bad map" "not.kpm" "$keyplace" relocalize --map "$work/not.kpm" --log "$log" \
  --json "$work/keep.json"
check "existing JSON kept" grep -q kept "$work/keep.json"

# Without truth (a raw log of the same building, no --truth): relocalized once from its first
# scan as a robot would be, ICP on its odometry; a row per scan, the first fix, a JSON summary.
raw="$source_dir/tests/data/ros2/fr079-raw-first150.log.gz"
check "relocalize without truth" "$keyplace" relocalize --map "$work/map.kpm" --log "$raw" \
  --fixes "$work/raw-fixes.tsv" --initialpose "$work/raw-fix.yaml" --json "$work/raw.json"
cp "$work/out" "$work/raw.txt"  # check writes its own command's output to $work/out
check "without truth: says so" grep -q "^protocol     no truth" "$work/raw.txt"
check "without truth: a row per scan, the first fix in the JSON" /usr/bin/python3 -c "
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter='\t'))
summary = json.load(open(sys.argv[2]))
assert len(rows) == 150 == summary['scans'], (len(rows), summary['scans'])
assert summary['truth'] is False and summary['pose_source'] == 'icp', summary
first = summary['first_fix']
assert first is not None, summary
fixed = [r for r in rows if r['status'] == 'fixed']
assert fixed and int(fixed[0]['scan']) == first['scan'] and fixed[0]['new_fix'] == '1', fixed[:1]
assert abs(float(fixed[0]['x_m']) - first['x_m']) < 1e-3, (fixed[0], first)
assert all(r['x_m'] == '' for r in rows if r['status'] != 'fixed')
assert sum(r['answered'] == '1' for r in rows) == summary['answers']
" "$work/raw-fixes.tsv" "$work/raw.json"
check "without truth: the first fix as /initialpose" grep -q "frame_id: map" "$work/raw-fix.yaml"
fails_with "without truth: --tsv asks for truth" "--tsv needs the truth" "$keyplace" relocalize \
  --map "$work/map.kpm" --log "$raw" --tsv "$work/raw.tsv"

finish relocalize
