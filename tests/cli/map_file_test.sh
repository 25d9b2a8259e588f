#!/usr/bin/env bash
# keyplace info --check and damaged or hostile map files through the command line (issue 18):
# each is rejected naming the file and the problem, and is never modified by the attempt.
# Usage: map_file_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
log="$source_dir/data/fr079-corrected.log.gz"
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"

sql() {  # sql MAP STATEMENTS: changes a copy of the map as a hostile or careless tool would
  /usr/bin/python3 -c "
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
db.executescript(sys.argv[2])
db.commit()" "$1" "$2"
}

state() {  # state FILE: content hash and mtime, to show that a load left the file as it was
  echo "$(sha256sum <"$1") $(stat -c %Y.%y "$1")"
}

check "info --help shows --check" sh -c "\"$keyplace\" info --help | grep -q -- --check"
check "map" "$keyplace" map "$log" --scans 0:300 --out "$work/map.kpm"

check "check a valid map" "$keyplace" info --check "$work/map.kpm" --json "$work/check.json"
check "check prints each check and ok" sh -c "
  \"$keyplace\" info --check \"$work/map.kpm\" >\"$work/check.txt\" &&
  grep -q 'ok  SQLite integrity_check: ok' \"$work/check.txt\" &&
  grep -q 'ok  content checksum fnv1a64:' \"$work/check.txt\" &&
  grep -q 'ok  format keyplace-map, version 2' \"$work/check.txt\" &&
  test \"\$(tail -1 \"$work/check.txt\")\" = ok"
check "check json" /usr/bin/python3 -c "
import json, sys
j = json.load(open(sys.argv[1]))
assert j['ok'] is True and j['schema_version'] == 2 and j['problem'] == '', j
assert any(c.startswith('content checksum fnv1a64:') for c in j['checks_passed']), j" \
  "$work/check.json"

# One changed value: the checksum no longer matches, for info --check, info and localize.
cp "$work/map.kpm" "$work/changed.kpm"
sql "$work/changed.kpm" "UPDATE poses SET x = x + 1 WHERE rowid = 1"
before=$(state "$work/changed.kpm")
fails_with "check a changed map" "changed.kpm: content checksum mismatch" \
  "$keyplace" info --check "$work/changed.kpm" --json "$work/changed.json"
check "check of a changed map prints failed" test "$(tail -1 "$work/out")" = failed
check "check json of a changed map" /usr/bin/python3 -c "
import json, sys
j = json.load(open(sys.argv[1]))
assert j['ok'] is False and 'content checksum mismatch' in j['problem'], j" "$work/changed.json"
fails_with "info on a changed map" "changed.kpm: content checksum mismatch" \
  "$keyplace" info "$work/changed.kpm"
fails_with "localize on a changed map" "changed.kpm: content checksum mismatch" \
  "$keyplace" localize --map "$work/changed.kpm" --log "$log" --n-pos 5
check "a failed load leaves the map unchanged" test "$(state "$work/changed.kpm")" = "$before"

# The reproducer of the hang: keypoints as a view over an endless recursive query. timeout turns
# a regression into a failure instead of a full temporary folder.
cp "$work/map.kpm" "$work/view.kpm"
sql "$work/view.kpm" "DROP TABLE keypoints;
CREATE VIEW keypoints (submap_id, seq, x, y, orientation, scale, level, scan_index, stability,
  occurrences, descriptor) AS WITH RECURSIVE r(n) AS (SELECT 1 UNION ALL SELECT n + 1 FROM r)
  SELECT 0, n, 0.0, 0.0, 0.0, 1.0, 0, 0, 1.0, 1, zeroblob(192) FROM r;"
before=$(state "$work/view.kpm")
fails_with "check a map whose keypoints are a view" "view.kpm: 'keypoints' is a view" \
  timeout 60 "$keyplace" info --check "$work/view.kpm"
fails_with "localize on a map whose keypoints are a view" "view.kpm: 'keypoints' is a view" \
  timeout 60 "$keyplace" localize --map "$work/view.kpm" --log "$log" --n-pos 5
check "the view map is unchanged" test "$(state "$work/view.kpm")" = "$before"

# A version 1 map (no checksum; still read) whose stored configuration is implausible: validated
# as a user's, the error names the file and the key (0.001 used to exhaust memory in localize).
cp "$work/map.kpm" "$work/v1.kpm"
sql "$work/v1.kpm" "DELETE FROM meta WHERE key = 'content_checksum';
UPDATE meta SET value = '1' WHERE key = 'schema_version';"
check "check a version 1 map" sh -c "
  \"$keyplace\" info --check \"$work/v1.kpm\" | grep -q 'no content checksum: a version 1 map'"
sql "$work/v1.kpm" "UPDATE config SET value = '0.001' WHERE key = 'cell_size_m'"
fails_with "check a map with cell_size_m 0.001" "v1.kpm: table config: MappingConfig.cell_size_m" \
  "$keyplace" info --check "$work/v1.kpm"
fails_with "localize on a map with cell_size_m 0.001" \
  "v1.kpm: table config: MappingConfig.cell_size_m" \
  "$keyplace" localize --map "$work/v1.kpm" --log "$log" --n-pos 5

# A newer version and a file that is no map at all.
cp "$work/map.kpm" "$work/v3.kpm"
sql "$work/v3.kpm" "UPDATE meta SET value = '3' WHERE key = 'schema_version'"
fails_with "check a newer map" "v3.kpm: map schema version 3 is not supported: written by a newer" \
  "$keyplace" info --check "$work/v3.kpm"
fails_with "check a log" "not a keyplace map file (not an SQLite database)" \
  "$keyplace" info --check "$log"

finish map_file_test
