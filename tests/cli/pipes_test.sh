#!/usr/bin/env bash
# Logs through pipes, /dev/fd/N and named FIFOs (issue 18): read once, completely, with the same
# results and fingerprint as the file; a map file through a pipe is refused naming it. Every
# command runs under `timeout`, so a reader that blocks on a FIFO fails the test, not CI.
# Usage: pipes_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
log="$source_dir/data/fr079-corrected.log.gz"
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"
limit=120  # seconds: far beyond what each command takes on the bundled log

same_log() {  # same_log A.json B.json KEYS...: the given keys of two `info --json` equal
  /usr/bin/python3 - "$@" <<'EOF'
import json, sys
a, b = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
for key in sys.argv[3:]:
    if a[key] != b[key]:
        print(key, a[key], b[key])
        sys.exit(1)
EOF
}

same_but() {  # same_but A.json B.json KEYS...: equal but for times and the given top-level keys
  /usr/bin/python3 - "$@" <<'EOF'
import json, sys
def load(path):
    j = json.load(open(path))
    return {k: v for k, v in j.items() if k not in sys.argv[3:] and 'seconds' not in k}
a, b = load(sys.argv[1]), load(sys.argv[2])
if a != b:
    print('differ at', sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k)))
    sys.exit(1)
EOF
}

# The name of the input decides only what names it: the data set (and the paper's numbers
# printed beside ours) is recognised from the file name, which /dev/fd/63 is not.
named="log dataset paper"
all_figures="scans lines beams_total beams_per_scan_max field_of_view_deg line_counts
  duration_s path_length_m invalid_beams no_return_beams"
# shellcheck disable=SC2086
{
  check "info of the file" timeout $limit "$keyplace" info "$log" --json "$work/file.json"

  # Formerly 1460 of 1464 scans: the SQLite sniff took the first 8 KiB of the pipe.
  check "info of decompressed text through a pipe" \
    timeout $limit "$keyplace" info <(gzip -dc "$log") --json "$work/text_pipe.json"
  check "  every scan and line" same_log "$work/file.json" "$work/text_pipe.json" $all_figures

  # Formerly "no laser scans": a .gz through a pipe was not decompressed.
  check "info of a .gz through a pipe" \
    timeout $limit "$keyplace" info <(cat "$log") --json "$work/gz_pipe.json"
  check "  every scan and the file's fingerprint" same_log "$work/file.json" "$work/gz_pipe.json" \
    $all_figures fingerprint file_bytes

  # Formerly hung: the FIFO was opened a second time after its writer had gone.
  mkfifo "$work/log.fifo"
  cat "$log" >"$work/log.fifo" &
  writer=$!
  check "info of a named FIFO" timeout $limit "$keyplace" info "$work/log.fifo" \
    --json "$work/fifo.json"
  kill "$writer" 2>/dev/null
  wait "$writer" 2>/dev/null
  check "  every scan and the file's fingerprint" same_log "$work/file.json" "$work/fifo.json" \
    $all_figures fingerprint file_bytes

  # map read the log, then read it again for the fingerprint it records (source_hash).
  check "map of the file" timeout $limit "$keyplace" map "$log" --scans 0:200 \
    --out "$work/file.kpm" --json "$work/map_file.json"
  check "map through a pipe" timeout $limit "$keyplace" map <(cat "$log") --scans 0:200 \
    --out "$work/pipe.kpm" --json "$work/map_pipe.json"
  check "  the same map figures" same_but "$work/map_file.json" "$work/map_pipe.json" $named
  check "info of both maps" sh -c "
    timeout $limit \"$keyplace\" info \"$work/file.kpm\" --json \"$work/file_kpm.json\" &&
    timeout $limit \"$keyplace\" info \"$work/pipe.kpm\" --json \"$work/pipe_kpm.json\""
  check "  the pipe's map records the log's fingerprint" \
    same_log "$work/file_kpm.json" "$work/pipe_kpm.json" source_hash submaps stable_keypoints source_scans config

  # localize takes the log's fingerprint to recognise the map's own log (self-match rule): a
  # second read of a pipe gave the fingerprint of nothing.
  check "localize with the log through a FIFO" sh -c "
    mkfifo \"$work/query.fifo\" && { cat \"$log\" >\"$work/query.fifo\" & } &&
    timeout $limit \"$keyplace\" localize --map \"$work/file.kpm\" --log \"$work/query.fifo\" \
      --scans 0:200 --n-pos 20 --json \"$work/localize_fifo.json\" >\"$work/localize_fifo.txt\""
  check "localize with the log as a file" timeout $limit "$keyplace" localize \
    --map "$work/file.kpm" --log "$log" --scans 0:200 --n-pos 20 --json "$work/localize_file.json"
  check "  the same results" same_but "$work/localize_file.json" "$work/localize_fifo.json" \
    $named
  check "  and no 'another recording' note" sh -c "! grep -q 'another recording' \
    \"$work/localize_fifo.txt\""

  check "features through a pipe" timeout $limit "$keyplace" features <(gzip -dc "$log") \
    --scans 0:40 --json "$work/features_pipe.json"
  check "features of the file" timeout $limit "$keyplace" features "$log" --scans 0:40 \
    --json "$work/features_file.json"
  check "  the same keypoints" same_but "$work/features_file.json" "$work/features_pipe.json" \
    $named

  # A map file needs seeking (SQLite) and is checked before it is read: refused through a pipe.
  fails_with "info of a map through a pipe" "map files must be regular files" \
    timeout $limit "$keyplace" info <(cat "$work/file.kpm")
  fails_with "info --check of a map through a pipe" "map files must be regular files" \
    timeout $limit "$keyplace" info --check <(cat "$work/file.kpm")
  fails_with "localize with a map through a pipe" "map files must be regular files" \
    timeout $limit "$keyplace" localize --map <(cat "$work/file.kpm") --log "$log" --n-pos 5
  fails_with "a map given as the log of map" "an SQLite database (a keyplace map file or" \
    timeout $limit "$keyplace" map "$work/file.kpm" --out "$work/other.kpm"

  # The relation and index files are read once, front to back: through pipes they give the
  # file's figures (the raw log, its relations and its index to the corrected log are shared data).
  shared="$source_dir/../shared/data"
  if [ -f "$shared/fr079-raw.log.gz" ]; then
    odometry=("$keyplace" odometry "$shared/fr079-raw.log.gz" --scans 0:300
      --corrected "$shared/fr079-corrected.log.gz")
    check "odometry with relations and index files" timeout $limit "${odometry[@]}" \
      --relations "$shared/fr079.relations" \
      --raw-to-corrected "$shared/fr079-raw-to-corrected.tsv" --json "$work/odo_file.json"
    check "odometry with relations and index through pipes" timeout $limit "${odometry[@]}" \
      --relations <(cat "$shared/fr079.relations") \
      --raw-to-corrected <(cat "$shared/fr079-raw-to-corrected.tsv") --json "$work/odo_pipe.json"
    check "  the same relation errors and drift" /usr/bin/python3 - "$work/odo_file.json" \
      "$work/odo_pipe.json" <<'EOF'
import json, sys
a, b = (json.load(open(path)) for path in sys.argv[1:3])
assert a["icp"]["matched"] > 50 and a["icp"] == b["icp"], (a["icp"], b["icp"])
drift = [{k: v for k, v in j["drift"].items() if k != "index_file"} for j in (a, b)]
assert drift[0] == drift[1] and drift[0]["icp"]["consecutive"]["count"] > 50, drift
EOF
  else
    echo "skipped the relation and index pipes: $shared/fr079-raw.log.gz not found"
  fi

  # Bags need seeking too: refused through a pipe with the reason, not read as a text log.
  ros2="$source_dir/tests/data/ros2"
  fails_with "an MCAP bag through a pipe" "a ROS 2 MCAP file through a pipe or device" \
    timeout $limit "$keyplace" info <(cat "$ros2/mcap-zstd/mcap-zstd_0.mcap")
  fails_with "an sqlite3 bag through a pipe" "map files must be regular files (bags too)" \
    timeout $limit "$keyplace" info <(cat "$ros2/sqlite3/sqlite3_0.db3")
}

finish cli.pipes
