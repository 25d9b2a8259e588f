#!/usr/bin/env bash
# End-to-end checks of the keyplace command line on the bundled log: help texts, outputs, and
# clear errors for bad input. Usage: cli_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
log="$source_dir/data/fr079-corrected.log.gz"
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"

json_value() {  # json_value FILE KEY: a top-level number or string of a JSON file
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2"
}

check "help" "$keyplace" --help
for command in info features odometry map localize slam sweep report dump-config; do
  check "$command --help" "$keyplace" "$command" --help
done

check "info" "$keyplace" info "$log" --json "$work/info.json"
check "info scans" test "$(json_value "$work/info.json" scans)" = 1464
check "info beams" test "$(json_value "$work/info.json" beams_per_scan_max)" = 360
# FLASER lines state no angles: info says how their beams were spread (odd counts first to last).
python3 -c "print('FLASER 181 ' + ' '.join(['2.0'] * 181) + ' 0 0 0 0 0 0 1 h 1')" >"$work/odd.log"
check "info on 181 FLASER beams" "$keyplace" info "$work/odd.log" --json "$work/odd.json"
cp "$work/out" "$work/odd.txt"  # check writes its own command's output to $work/out
check "info names the odd-count spacing" grep -q "beam spacing    step fov/(n-1), first and last beam" "$work/odd.txt"
check "info json spacing rule" python3 -c "
import json,sys; s=json.load(open(sys.argv[1]))['flaser_beam_spacing']
assert s == {'rule': 'fov/(n-1)', 'scans_fov_over_n': 0, 'scans_fov_over_n_minus_1': 1}, s" "$work/odd.json"
check "info json no FLASER spacing for ROBOTLASER1" python3 -c "
import json,sys; assert json.load(open(sys.argv[1]))['flaser_beam_spacing'] is None" "$work/info.json"

check "features" "$keyplace" features "$log" --scans 0:20 --tsv "$work/kp.tsv" --json "$work/kp.json"
check "features tsv header" test "$(head -1 "$work/kp.tsv")" = "$(printf 'scan\tx\ty\torientation\tscale')"
check "features scans" test "$(json_value "$work/kp.json" scans)" = 20
check "features tsv rows = keypoints" test "$(($(wc -l <"$work/kp.tsv") - 1))" = \
  "$(json_value "$work/kp.json" keypoints)"
check "features json keys" python3 -c "
import json,sys
j=json.load(open(sys.argv[1]))
assert j['keypoints_per_scan_mean'] > 5 and j['seconds_per_scan_mean'] > 0" "$work/kp.json"

check "features --set" "$keyplace" features "$log" --scans 0:5 --set features.num_scales=3 \
  --json "$work/kp3.json"
check "features --set json" python3 -c "
import json,sys
j=json.load(open(sys.argv[1]))
assert len(j['keypoints_per_level']) == 3 and j['config']['features']['num_scales'] == '3', j" \
  "$work/kp3.json"

# The bundled log is corrected (no odometry poses): ICP starts from zero motion.
check "odometry" "$keyplace" odometry "$log" --scans 0:100 --set odometry.icp.kernel=huber \
  --local-dt 2 --out "$work/odo.tsv" --steps "$work/steps.tsv" --json "$work/odo.json"
check "odometry json" python3 -c "
import json,sys
j=json.load(open(sys.argv[1]))
assert j['scans'] == 100 and j['scans_in_log'] == 1464 and j['missing_odometry'] == 100, j
# Without odometry there is nothing for ICP to disagree with: no figure, not a zero.
d=j['step_disagreement']
assert d['steps'] == 0 and d['median_m'] is None and d['p99_deg'] is None, d
rows=[l.rstrip('\\n').split('\\t') for l in open(sys.argv[2]) if not l.startswith('#')]
assert len(rows) == 100 and [int(r[0]) for r in rows] == list(range(100)), len(rows)
assert rows[0][2] == 'first_scan', rows[0]
assert sum(r[2] == 'registered' for r in rows) == j['registered'], j['registered']
assert sum(r[2] == 'fallback_not_converged' for r in rows) == j['not_converged']
assert all(r[10:] == ['nan'] * 5 for r in rows), rows[0]
assert j['registered'] + j['recovered'] + j['not_converged'] + j['fallback_correction_too_large'] \
    + j['fallback_too_few_points'] + j['fallback_weak_match'] == 99, j
c=j['config']
assert c['odometry']['icp']['kernel'] == 'huber', c['odometry']
assert float(c['evaluation']['local_relation_max_dt_s']) == 2, c['evaluation']" "$work/odo.json" \
  "$work/steps.tsv"
check "odometry tsv rows" test "$(($(wc -l <"$work/odo.tsv") - 1))" = 100
# Timestamps kept to 6 digits (rounded to 1000 s) cannot order the scans: info says so, odometry
# by time refuses and points to --order file, which works.
zcat "$log" | awk '$1 == "ROBOTLASER1" { if (++n > 60) exit; $NF = int($NF / 1000) * 1000 } { print }' \
  >"$work/coarse.log"
check "info on coarse stamps" "$keyplace" info "$work/coarse.log"
cp "$work/out" "$work/coarse-info.txt"
check "info warns" grep -q "cannot order the scans" "$work/coarse-info.txt"
fails_with "odometry refuses coarse stamps" "--order file" "$keyplace" odometry "$work/coarse.log"
# ... naming the log (issue 31), as slam's refusal does.
fails_with "odometry's refusal names the log" "$work/coarse.log: the logger timestamps cannot order" \
  "$keyplace" odometry "$work/coarse.log"
check "odometry --order file" "$keyplace" odometry "$work/coarse.log" --order file
fails_with "slam refuses coarse stamps" "--order file" "$keyplace" slam "$work/coarse.log"

fails_with "bad odometry --set value" "odometry.icp.kernel" "$keyplace" odometry "$log" \
  --set odometry.icp.kernel=gauss

check "map" "$keyplace" map "$log" --out "$work/map.kpm" --json "$work/map.json" --png "$work/map.png"
check "map json keys" python3 -c "
import json,sys
j=json.load(open(sys.argv[1]))
for k in ['compression','scans_per_submap','keypoints_per_submap','distribution','submaps','seconds_per_submap','seconds_total']:
    assert k in j, k
assert 0 < j['compression'] < 0.5 and j['submaps'] > 50" "$work/map.json"
check "map png" test -s "$work/map.png"
check "info on map" "$keyplace" info "$work/map.kpm" --json "$work/mapinfo.json"
check "info map submaps" test "$(json_value "$work/mapinfo.json" submaps)" = "$(json_value "$work/map.json" submaps)"
check "localize" "$keyplace" localize --map "$work/map.kpm" --log "$log" --n-pos 40 \
  --threads 2 --json "$work/loc.json" --queries "$work/loc.tsv"
# (The same figures at any thread count: cli.determinism.)
check "localize json" python3 -c "
import json,sys
j=json.load(open(sys.argv[1]))
for k in ['precision','recall','n_pos','n_acc','n_cor','scans_mean','seconds_per_query_mean','p_gl','p_cl']:
    assert k in j, k
assert j['n_pos'] == 40 and j['precision'] >= 0.9 and j['recall'] > 0.2, j" "$work/loc.json"
check "localize queries rows" test "$(($(wc -l <"$work/loc.tsv") - 1))" = 40
# TIP-FLIRT accepts on the RANSAC consensus (no gamma check); with the gamma check of the
# submap queries most single-scan neighbours fail (recall about 0.4 on this log).
check "tip-flirt baseline" "$keyplace" localize --baseline tip-flirt --log "$log" --n-pos 20 \
  --json "$work/tip.json"
check "tip-flirt json" python3 -c "
import json,sys
j=json.load(open(sys.argv[1]))
assert float(j['config']['place']['min_gamma']) == 0 and j['rank_by'] == 'consensus', j['config']
assert j['n_pos'] == 20 and j['precision'] >= 0.9 and j['recall'] >= 0.7, j" "$work/tip.json"
printf 'SQLite format 3\0garbage' >"$work/bad.kpm"
fails_with "corrupt map" "bad.kpm" "$keyplace" info "$work/bad.kpm"

printf 'not a log\n' >"$work/text.log"
fails_with "non-log input" "no laser scans" "$keyplace" info "$work/text.log"
printf 'FLASER 3 1.0 2.0 0 0 0 0 0 0 1 h 1\n' >"$work/bad.log"
fails_with "bad beam count" "bad.log:1" "$keyplace" features "$work/bad.log"
fails_with "bad scan range" "--scans" "$keyplace" features "$log" --scans 5:x

# Damaged logs (docs/RELIABILITY.md). A last line cut off by power loss is dropped with a
# warning naming it, and every complete line is used: the first 400 000 bytes of FR101 end in
# the middle of a FLASER line.
fr101="$source_dir/../shared/data/fr101-corrected.log.gz"
if [ -f "$fr101" ]; then
  gzip -dc "$fr101" | head -c 400000 >"$work/cut.log"
  complete_scans=$(head -n -1 "$work/cut.log" | grep -c '^FLASER ')
  cut_line=$(($(wc -l <"$work/cut.log") + 1))
  if "$keyplace" map "$work/cut.log" --json "$work/cut.json" >"$work/cut.out" 2>"$work/cut.err"; then
    ok
  else
    fail "map on a cut-off log"
    sed 's/^/  | /' "$work/cut.err" | head -10
  fi
  check "cut-off log: every complete scan mapped" test "$(json_value "$work/cut.json" scans)" = "$complete_scans"
  check "cut-off log: submaps" python3 -c "
import json,sys
assert json.load(open(sys.argv[1]))['submaps'] > 10" "$work/cut.json"
  check "cut-off log: the warning names the line" \
    grep -qF "cut.log:$cut_line: the last line is incomplete" "$work/cut.err"
else
  echo "skipped the cut-off log checks: $fr101 not found"
fi
# A malformed line elsewhere stops with the named error, which suggests --skip-bad-lines.
{
  gzip -dc "$log" | head -n 600
  echo "ODOM 1 2"
  gzip -dc "$log" | sed -n 601,1200p
} >"$work/damaged.log"
fails_with "malformed line named" "damaged.log:601: ODOM" "$keyplace" info "$work/damaged.log"
fails_with "malformed line: suggestion" "--skip-bad-lines" "$keyplace" map "$work/damaged.log"
check "info --skip-bad-lines" "$keyplace" info "$work/damaged.log" --skip-bad-lines \
  --json "$work/damaged.json"
check "info: skipped line counted" test "$(json_value "$work/damaged.json" skipped_lines)" = 1
check "info: scans around the skipped line" test "$(json_value "$work/damaged.json" scans)" = 600
"$keyplace" map "$work/damaged.log" --skip-bad-lines --json "$work/damaged-map.json" \
  >"$work/damaged.out" 2>"$work/damaged.err"
check "map --skip-bad-lines warns" grep -qF "skipped 1 malformed line (line 601)" "$work/damaged.err"
check "map: skipped line counted" test "$(json_value "$work/damaged-map.json" skipped_lines)" = 1
check "localize --skip-bad-lines" "$keyplace" localize --map "$work/map.kpm" \
  --log "$work/damaged.log" --skip-bad-lines --n-pos 10 --json "$work/damaged-localize.json"
check "localize: skipped line counted" \
  test "$(json_value "$work/damaged-localize.json" skipped_lines)" = 1
check "map: no line skipped" test "$(json_value "$work/map.json" skipped_lines)" = 0
# More queries asked for than the log has starts: capped with a note, no start used twice.
"$keyplace" localize --map "$work/map.kpm" --log "$log" --scans 0:40 --n-pos 500 \
  --json "$work/capped.json" >/dev/null 2>"$work/capped.err"
check "localize: --n-pos capped with a note" grep -qF "keyplace: note: --n-pos 500 capped to the" \
  "$work/capped.err"
check "localize: capped below the scans" test "$(json_value "$work/capped.json" n_pos)" -lt 40
fails_with "missing file" "does not exist" "$keyplace" info "$work/missing.log"
# An output must not be the configuration file it reads, under any command.
"$keyplace" dump-config >"$work/own.yaml"
cp "$work/own.yaml" "$work/own-before.yaml"
fails_with "map --json onto its --config" "would destroy the input" "$keyplace" map "$log" \
  --config "$work/own.yaml" --json "$work/own.yaml"
fails_with "slam --json onto its --config" "would destroy the input" "$keyplace" slam "$log" \
  --config "$work/own.yaml" --json "$work/own.yaml"
check "the configuration file is unchanged" cmp "$work/own.yaml" "$work/own-before.yaml"
fails_with "bad pose source" "--poses" "$keyplace" map "$log" --poses gps
fails_with "bad --set key" "unknown configuration key 'mapping.no_such'" "$keyplace" map "$log" \
  --set mapping.no_such=1
fails_with "bad --set value" "mapping.min_scan_count: 'x' is not an integer" "$keyplace" map "$log" \
  --set mapping.min_scan_count=x

# Configuration as data: dump -> load -> dump is identical, a map built with the dumped defaults
# is byte-identical to one built without, the map and its JSON record the whole configuration.
check "dump-config" "$keyplace" dump-config
"$keyplace" dump-config >"$work/defaults.yaml"
"$keyplace" dump-config --config "$work/defaults.yaml" >"$work/defaults-again.yaml"
check "dump-config round trip" cmp "$work/defaults.yaml" "$work/defaults-again.yaml"
"$keyplace" dump-config --all >"$work/all.yaml"
"$keyplace" dump-config --all --config "$work/all.yaml" >"$work/all-again.yaml"
check "dump-config --all round trip" cmp "$work/all.yaml" "$work/all-again.yaml"
check "dump-config: the essential settings only" test \
  "$(grep -c '  # ' "$work/defaults.yaml")" -lt "$(($(grep -c '  # ' "$work/all.yaml") / 5))"
check "dump-config: says --all" grep -q "keyplace dump-config --all shows every one" \
  "$work/defaults.yaml"
"$keyplace" dump-config --preset paper >"$work/paper.yaml"
check "paper preset differs" grep -q "^  selection: first_verified" "$work/paper.yaml"
# The essential dump of a preset, read on the defaults, is that preset (its differences shown).
"$keyplace" dump-config --all --config "$work/paper.yaml" >"$work/paper-from-file.yaml"
"$keyplace" dump-config --all --preset paper >"$work/paper-all.yaml"
check "dump-config --preset paper as a file is the paper preset" cmp "$work/paper-from-file.yaml" \
  "$work/paper-all.yaml"
# dump-config --json: the configuration the YAML shows, as the "config" object of other commands'
# JSON, --set applied.
check "dump-config --json" "$keyplace" dump-config --set place.ransac.iterations=40 \
  --json "$work/config.json"
check "dump-config --json is the YAML's configuration" /usr/bin/python3 -c "
import json, sys, yaml
j = json.load(open(sys.argv[1]))
assert j['place']['ransac']['iterations'] == '40', j['place']['ransac']
# Values as the YAML writes them (text, as the config object of every --json).
defaults = yaml.load(open(sys.argv[2]), Loader=yaml.BaseLoader)
defaults['place']['ransac']['iterations'] = '40'
assert j == defaults, [k for k in j if j[k] != defaults.get(k)]
" "$work/config.json" "$work/all.yaml"
fails_with "dump-config --json over its --config" "destroy the input" "$keyplace" dump-config \
  --config "$work/defaults.yaml" --json "$work/defaults.yaml"
check "dump-config --set" sh -c "'$keyplace' dump-config --set place.ransac.iterations=40 | grep -q '^    iterations: 40 '"
# (The first 300 scans: the identity holds or not whatever the length, in a fifth of the time.)
check "map of 300 scans" "$keyplace" map "$log" --scans 0:300 --out "$work/map-300.kpm"
check "map with the dumped defaults" "$keyplace" map "$log" --scans 0:300 \
  --config "$work/all.yaml" --out "$work/map-config.kpm"
check "map byte-identical with --config defaults" cmp "$work/map-300.kpm" "$work/map-config.kpm"
check "map json records the configuration" python3 -c "
import json,sys
j=json.load(open(sys.argv[1]))
assert j['config']['mapping']['cell_size_m'] == '0.1' and j['config']['place']['ransac']['iterations'] == '18', j['config']" "$work/map.json"
check "info shows the map's configuration" sh -c "'$keyplace' info '$work/map.kpm' | grep -q '^    inlier_distance_m: 0.1 '"
"$keyplace" map "$log" --scans 0:300 --set mapping.min_overlap=0.7 --out "$work/map-07.kpm" \
  >/dev/null
check "info json of a changed map" python3 -c "
import json,subprocess,sys
subprocess.run([sys.argv[1], 'info', sys.argv[2], '--json', sys.argv[3]], check=True, capture_output=True)
j=json.load(open(sys.argv[3]))
assert j['configuration']['mapping']['min_overlap'] == '0.7', j['configuration']['mapping']" \
  "$keyplace" "$work/map-07.kpm" "$work/map07info.json"
printf 'place:\n  min_pairs: 10\n  no_such: 3\n' >"$work/bad-key.yaml"
fails_with "config unknown key" "bad-key.yaml:3: unknown configuration key 'place.no_such'" \
  "$keyplace" localize --map "$work/map.kpm" --log "$log" --config "$work/bad-key.yaml"
printf 'mapping:\n  min_overlap: high\n' >"$work/bad-type.yaml"
fails_with "config wrong type" "bad-type.yaml:2: mapping.min_overlap: 'high' is not a number" \
  "$keyplace" map "$log" --config "$work/bad-type.yaml"
printf 'mapping:\n  min_overlap: 1.5\n' >"$work/bad-range.yaml"
fails_with "config out of range" "bad-range.yaml:2: mapping.min_overlap" \
  "$keyplace" map "$log" --config "$work/bad-range.yaml"

# A failed run must not clobber an existing output file.
echo precious >"$work/keep.json"
"$keyplace" features "$work/bad.log" --json "$work/keep.json" >/dev/null 2>&1
check "output kept on failure" test "$(cat "$work/keep.json")" = precious

finish cli_test
