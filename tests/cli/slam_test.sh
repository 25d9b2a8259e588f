#!/usr/bin/env bash
# keyplace slam end to end on the first 1300 scans of the raw FR079 log (loops close from scan
# ~1050 on): every output file, the JSON keys of issue 7, loops that ground truth confirms, and
# clear errors for bad input. Usage: slam_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
shared=${KEYPLACE_SHARED:-$source_dir/../shared}
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"

scans=1300
raw="$work/fr079-raw-part.log"
zcat "$shared/data/fr079-raw.log.gz" |
  awk -v n="$scans" '$1 == "FLASER" { if (++lasers > n) exit } { print }' >"$raw"
awk -v n="$scans" 'NR == 1 || $1 < n' "$shared/data/fr079-raw-to-corrected.tsv" >"$work/index.tsv"

json_value() {  # json_value FILE KEY[.KEY]: a number or string of a JSON file
  python3 -c "
import json,sys
value = json.load(open(sys.argv[1]))
for key in sys.argv[2].split('.'): value = value[key]
print(value)" "$1" "$2"
}

check "slam --help" "$keyplace" slam --help
check "slam" "$keyplace" slam "$raw" --out "$work/map.kpm" --trajectory "$work/traj.tsv" \
  --truth "$shared/data/fr079-corrected.log.gz" --index "$work/index.tsv" \
  --relations "$shared/data/fr079.relations" --json "$work/slam.json" --loops "$work/loops.tsv" \
  --figures "$work/figures" --grid "$work/grid.yaml"
for key in loops_detected loops_used precision_overlap_10 precision_overlap_30 \
           precision_overlap_30_common_area ate_rmse_m relations.translation_mean_m \
           relations.rotation_mean_deg submaps compression; do
  check "json key $key" json_value "$work/slam.json" "$key"
done
loops=$(json_value "$work/slam.json" loops_detected)
check "loops closed" test "$loops" -ge 2
check "loops TSV: one row per loop" test "$(($(wc -l <"$work/loops.tsv") - 1))" = "$loops"
check "loops TSV columns" grep -q $'^query_submap\tquery_first_scan\treference_submap.*\toverlap_common$' \
  "$work/loops.tsv"
check "trajectory: one row per scan" test "$(($(wc -l <"$work/traj.tsv") - 1))" = "$scans"
# Every loop is checked against ground truth; every loop the graph uses is correct, and the
# gate stops the wrong ones (here, since the front end's grid refinement, two matches of a
# corridor seen from its other end, 180 deg off), which are at most a tenth of those detected.
check "loops checked against truth" test "$(json_value "$work/slam.json" loops_truth_evaluated)" = "$loops"
check "used loops correct, wrong ones stopped by the gate" python3 -c "
import csv,sys
rows = list(csv.DictReader(open(sys.argv[1]), delimiter='\t'))
used = [r for r in rows if r['used'] == '1']
wrong = [r for r in rows if r['truth_correct'] != '1']
assert used and all(r['truth_correct'] == '1' for r in used), [r['query_submap'] for r in used]
assert all(r['accepted'] == '0' for r in wrong), [r['query_submap'] for r in wrong]
assert 10 * len(wrong) <= len(rows), (len(wrong), len(rows))
" "$work/loops.tsv"
check "common-area precision" python3 -c "
import json,sys
j = json.load(open(sys.argv[1]))
assert j['precision_overlap_30_common_area'] == 1.0, j['precision_overlap_30_common_area']
assert j['ate_rmse_m'] < j['ate_icp_rmse_m'], (j['ate_rmse_m'], j['ate_icp_rmse_m'])
assert j['relations']['translation_mean_m'] < 0.1, j['relations']
# The whole configuration is recorded (section -> key -> value), defaults here.
assert j['config']['slam']['gate_base_m'] == '2', j['config']['slam']
assert j['config']['evaluation']['truth_max_gap_scans'] == '50', j['config']['evaluation']
" "$work/slam.json"
for figure in trajectory overlap_histogram overlap_histogram_common_area rpe ate; do
  check "figure $figure" test -s "$work/figures/$figure.png"
done
check "map readable" "$keyplace" info "$work/map.kpm"
# The occupancy grid for map_server (issue 16), checked against the corrected-pose grid.
check "grid files" python3 -c "
import json,sys,os
work = sys.argv[1]
yaml = open(work + '/grid.yaml').read()
assert 'image: \"grid.pgm\"' in yaml and 'resolution: 0.05' in yaml and 'mode: trinary' in yaml, yaml
pgm = open(work + '/grid.pgm', 'rb').read()
header = pgm.split(b'\\n', 3)
assert header[0] == b'P5', header[:3]
width, height = map(int, header[2].split())
assert len(header[3]) == len(b'255\\n') + width * height, (len(header[3]), width, height)
pixels = set(header[3][4:])
assert pixels <= {0, 205, 254} and {0, 254} <= pixels, pixels
g = json.load(open(work + '/slam.json'))['grid_agreement']
assert g['tolerance_m'] == 0.1 and g['occupied'] > 1000 and g['occupied_reference'] > 1000, g
assert g['occupied_matched'] > 0.85 and g['reference_matched'] > 0.85, g
assert g['occupied_on_free'] < 0.05, g
" "$work"
# With --truth the grid is checked without --grid too (issue 34: the global-consistency check
# beside the relation errors), with the same figures.
check "grid check without --grid" "$keyplace" slam "$raw" \
  --truth "$shared/data/fr079-corrected.log.gz" --index "$work/index.tsv" \
  --json "$work/slam-check.json"
cp "$work/out" "$work/check.out"
check "grid check printed" grep -q "^grid vs corrected-pose grid: " "$work/check.out"
check "grid check as with --grid" python3 -c "
import json,sys
a = json.load(open(sys.argv[1]))['grid_agreement']
b = json.load(open(sys.argv[2]))['grid_agreement']
assert a == b, (a, b)
" "$work/slam.json" "$work/slam-check.json"
# A grid too large for grid.max_cells only skips the check when --grid was not asked for.
check "grid check skipped" "$keyplace" slam "$raw" \
  --truth "$shared/data/fr079-corrected.log.gz" --index "$work/index.tsv" \
  --set grid.max_cells=10000 --json "$work/slam-nocheck.json"
cp "$work/out" "$work/nocheck.out"
check "grid check skip said" grep -q "^grid agreement     not computed: .*grid.max_cells" \
  "$work/nocheck.out"
check "no grid check in the JSON" python3 -c "
import json,sys
assert 'grid_agreement' not in json.load(open(sys.argv[1]))
" "$work/slam-nocheck.json"
fails_with "--grid equal to --out" "--grid" "$keyplace" slam "$raw" --out "$work/same.yaml" \
  --grid "$work/same.yaml"
fails_with "grid config checked" "grid.free_thresh" "$keyplace" slam "$raw" \
  --grid "$work/bad.yaml" --set grid.free_thresh=0.9

# Issue 17: no loops is "no loops" and null precisions, never 0.000; a relation file of another
# log gives no relation error and says why.
head -c 200000 "$raw" | sed '$d' >"$work/short.log"  # ~100 scans along a corridor, no revisit
check "slam without loops" "$keyplace" slam "$work/short.log" \
  --relations "$shared/data/intel.relations" --json "$work/short.json"
cp "$work/out" "$work/short.out"
check "no loops printed" grep -q "^loop precision     no loops$" "$work/short.out"
check "relations of another log refused" grep -q \
  "^relations: no relation error, no relation lies within the trajectory's time span" \
  "$work/short.out"
check "null precisions and relation errors" python3 -c "
import json,sys
j = json.load(open(sys.argv[1]))
assert j['loops_detected'] == 0, j['loops_detected']
for key in ['precision_overlap_10', 'precision_overlap_30', 'precision_overlap_30_common_area',
            'precision_overlap_30_used', 'precision_overlap_30_matched_ransac']:
    assert j[key] is None, (key, j[key])
r = j['relations']
assert r['translation_mean_m'] is None and r['all'] is None, r
assert 'another log' in r['refusal'] and r['matched'] == 0, r
" "$work/short.json"

# Bad input names the file and the line; an existing output is left as it was.
cp "$work/slam.json" "$work/slam.before.json"
printf 'raw_index\tcorrected_index\n0\tzero\n' >"$work/bad-index.tsv"
fails_with "bad index line" "bad-index.tsv:2" "$keyplace" slam "$raw" \
  --truth "$shared/data/fr079-corrected.log.gz" --index "$work/bad-index.tsv" --json "$work/slam.json"
check "json kept" cmp "$work/slam.json" "$work/slam.before.json"
fails_with "truth without index" "--index" "$keyplace" slam "$raw" \
  --truth "$shared/data/fr079-corrected.log.gz"
fails_with "missing log" "no-such.log" "$keyplace" slam "$work/no-such.log"
# Tuning goes through --set section.key=value; unknown keys and the old flags are errors.
fails_with "bad --set key" "no_such" "$keyplace" slam "$raw" --set slam.no_such=1
fails_with "removed flag" "--no-gate" "$keyplace" slam "$raw" --no-gate

finish "slam_test"
