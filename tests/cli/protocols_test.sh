#!/usr/bin/env bash
# The honest protocols of keyplace map / localize (issue 14) on the bundled log (the same file as
# ../shared/data/fr079-corrected.log.gz): (b) the time split, a map of scans 0:700 and queries
# from 700 on, whose file-absolute scan indices make the self-match rule exclude nothing; (d)
# queries from another file, where the rule is off; revisitable recall and the reliability
# diagram. Usage: protocols_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
log="$source_dir/data/fr079-corrected.log.gz"
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"
export KEYPLACE_PROGRESS=0

# (b) Time split.
check "map --scans 0:700" "$keyplace" map "$log" --scans 0:700 --out "$work/first.kpm" \
  --json "$work/first.json"
check "map --scans json" python3 -c "
import json,sys
j=json.load(open(sys.argv[1]))
assert j['scans'] == 700 and j['first_scan'] == 0 and j['scans_in_log'] == 1464, j" \
  "$work/first.json"
# The shared-scan rule, so that any query scan numbered like a map scan would exclude a place.
check "localize --scans 700:" "$keyplace" localize --map "$work/first.kpm" --log "$log" \
  --scans 700: --n-pos 20 --exclude-shared-scans --json "$work/split.json" \
  --queries "$work/split.tsv" --reliability "$work/split-reliability.tsv"
check "time split json" python3 -c "
import json,sys
j=json.load(open(sys.argv[1]))
assert j['first_scan'] == 700 and j['scans'] == 764, j
assert j['truth_is_map_log'] is True and j['self_match'] == 'shared_scan', j
assert j['n_pos'] == 20 and 0 < j['n_revisitable'] <= j['n_pos'], j
assert j['recall_revisitable'] >= j['recall'] > 0, j
assert j['n_cor'] > 0 and j['precision'] >= 0.9, j
bins = j['reliability']
assert len(bins) == 10 and sum(b['count'] for b in bins) == j['n_acc'], bins
for k, b in enumerate(bins):
    assert abs(b['bin_low'] - k / 10) < 1e-12 and abs(b['bin_high'] - (k + 1) / 10) < 1e-12, b
    assert b['count'] == 0 or b['bin_low'] <= b['confidence_mean'] <= b['bin_high'], b
    assert 0 <= b['precision'] <= 1, b" "$work/split.json"
# Map scans are 0..699 and queries 700..1463 of the same file: no map place shares a scan with a
# query, so nothing is excluded (with indices relative to each cut, every query would meet a
# map submap of the same numbers).
check "time split queries" python3 -c "
import csv,json,sys
rows=list(csv.DictReader(open(sys.argv[1]), delimiter='\t'))
j=json.load(open(sys.argv[2]))
assert len(rows) == 20, len(rows)
assert all(int(r['start_scan']) >= 700 and int(r['evaluated_scan']) >= 700 for r in rows), rows[0]
assert all(int(r['places_excluded']) == 0 for r in rows), [r['places_excluded'] for r in rows]
assert sum(int(r['revisitable']) for r in rows) == j['n_revisitable']
revisitable_correct = sum(int(r['revisitable']) * int(r['correct']) for r in rows)
assert abs(j['recall_revisitable'] - revisitable_correct / j['n_revisitable']) < 1e-12, j" \
  "$work/split.tsv" "$work/split.json"
check "reliability tsv" python3 -c "
import csv,json,sys
rows=list(csv.DictReader(open(sys.argv[1]), delimiter='\t'))
bins=json.load(open(sys.argv[2]))['reliability']
assert len(rows) == 10 and [int(r['count']) for r in rows] == [b['count'] for b in bins], rows" \
  "$work/split-reliability.tsv" "$work/split.json"

# The same scans as the map, same file: the paper's rule excludes each query's own submap.
check "localize the map's own scans" "$keyplace" localize --map "$work/first.kpm" --log "$log" \
  --scans 0:350 --n-pos 10 --json "$work/own.json" --queries "$work/own.tsv"
check "own scans are excluded" python3 -c "
import csv,sys
rows=list(csv.DictReader(open(sys.argv[1]), delimiter='\t'))
assert sum(int(r['places_excluded']) for r in rows) > 0, rows" "$work/own.tsv"

# (d) Another file (the same run written out as plain text: other bytes, another name): no
# self-match exclusion, said on stdout; the own submaps are then fair answers.
gzip -dc "$log" >"$work/tuesday.log"
if "$keyplace" localize --map "$work/first.kpm" --log "$work/tuesday.log" --scans 0:350 \
  --n-pos 10 --json "$work/other.json" --queries "$work/other.tsv" >"$work/other.out" \
  2>"$work/other.err"; then
  ok
else
  fail "localize another file"
  sed 's/^/  | /' "$work/other.err" | head -10
fi
check "another file: said once" test "$(grep -c 'another recording' "$work/other.out")" = 1
check "another file: json and queries" python3 -c "
import csv,json,sys
j=json.load(open(sys.argv[1]))
assert j['truth_is_map_log'] is False and j['self_match'] == 'none', j
rows=list(csv.DictReader(open(sys.argv[2]), delimiter='\t'))
assert all(int(r['places_excluded']) == 0 for r in rows), rows
assert j['n_revisitable'] == j['n_pos'] == 10 and j['recall'] >= 0.9, j" \
  "$work/other.json" "$work/other.tsv"
# The map's file name with other contents is more likely a mistake: a warning names both.
mkdir -p "$work/copy"
gzip -dc "$log" | gzip -1 >"$work/copy/fr079-corrected.log.gz"
check "same name, other contents" sh -c "'$keyplace' localize --map '$work/first.kpm' \
  --log '$work/copy/fr079-corrected.log.gz' --scans 0:200 --n-pos 3 2>&1 >/dev/null \
  | grep -q 'built from a file named fr079-corrected.log.gz with other contents'"

# The scale benchmark's maps: the first half's map among copies of the second half's submaps.
check "map --scans 700:" "$keyplace" map "$log" --scans 700: --out "$work/second.kpm"
check "localize among distractors" "$keyplace" localize --map "$work/first.kpm" --log "$log" \
  --scans 0:700 --n-pos 10 --distractors "$work/second.kpm" --distractor-submaps 400 \
  --json "$work/distractors.json"
check "distractors json" python3 -c "
import json,sys
j=json.load(open(sys.argv[1]))
assert j['places'] == 400 and j['n_pos'] == 10 and j['n_acc'] > 0, j" "$work/distractors.json"
fails_with "too few distractor submaps" "must exceed the map's" "$keyplace" localize \
  --map "$work/first.kpm" --log "$log" --distractors "$work/second.kpm" --distractor-submaps 5
fails_with "distractors without a size" "distractor-submaps" "$keyplace" localize \
  --map "$work/first.kpm" --log "$log" --distractors "$work/second.kpm"

fails_with "bad localize --scans" "--scans" "$keyplace" localize --map "$work/first.kpm" \
  --log "$log" --scans 700
fails_with "empty map --scans" "no scan in the range" "$keyplace" map "$log" --scans 2000:

finish protocols_test
