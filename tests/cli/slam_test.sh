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
  --figures "$work/figures"
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
# Every loop is checked against ground truth and is correct, and agrees with the other submap
# where both looked.
check "loops checked against truth" test "$(json_value "$work/slam.json" loops_truth_evaluated)" = "$loops"
check "loops correct" test "$(json_value "$work/slam.json" loops_truth_correct)" = "$loops"
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
