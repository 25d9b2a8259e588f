#!/usr/bin/env bash
# The main job on the bundled data set: describe the log, extract its FLIRT keypoints and build
# its map of stable keypoints, printing each result beside the paper's.
# Usage: scripts/demo.sh KEYPLACE_BINARY LOG OUT_DIR
set -euo pipefail
keyplace=$1
log=$2
out=$3
mkdir -p "$out"

echo "== Data set: $log"
"$keyplace" info "$log" --json "$out/info.json"
echo
echo "== FLIRT keypoints of every scan"
"$keyplace" features "$log" --json "$out/features.json" --tsv "$out/keypoints.tsv"
echo "(FLIRTLib finds 24.01 keypoints per scan on this log, in 27.5 ms per scan on this machine.)"
echo
echo "== Map of stable keypoints, overlap criterion only (the paper's Table II)"
"$keyplace" map "$log" --overlap-only --json "$out/map-table2.json"
echo
echo "== Map of stable keypoints, all completion criteria (used for place recognition)"
"$keyplace" map "$log" --out "$out/map.kpm" --png "$out/map.png" --json "$out/map.json"
echo
echo "== Global localization against that map (paper Algorithm 4, Table III)"
"$keyplace" localize --map "$out/map.kpm" --log "$log" --json "$out/localize.json" \
  --queries "$out/localize-queries.tsv" --curve "$out/localize-curve.tsv"
echo
echo "== The same log streamed scan by scan through the library's GlobalLocalizer"
echo "   (examples/localize_stream.cpp: what a robot program calls; first fixes and the count."
echo "   Its map holds these very scans, so this shows the API, not accuracy: the table above"
echo "   excludes self-matches)"
stream="$(dirname "$keyplace")/localize_stream"
"$stream" "$out/map.kpm" "$log" --truth >"$out/localize-stream.txt"
head -3 "$out/localize-stream.txt"
echo "..."
tail -1 "$out/localize-stream.txt"
echo
echo "== Kidnapped robot on a map recorded earlier: the map of the first half of the log, 12 starts"
echo "   in the second half; the Relocalizer fixes when answers agree (two, one accepted, or three"
echo "   weak ones along 10 m), answers of keypoints or of a search of the whole map by the beams"
echo "   of the last 5 m (keyplace relocalize; the search's own time on the 'search' line)"
"$keyplace" map "$log" --scans 0:732 --out "$out/map-first-half.kpm" >/dev/null
"$keyplace" relocalize --map "$out/map-first-half.kpm" --log "$log" --scans 732: --starts 12 \
  --json "$out/relocalize.json" --figure "$out/relocalize.png" | sed -n '3,13p'
echo
echo "== A robot's own log, no truth: the first 150 raw scans of the same run with their wheel"
echo "   odometry (the first 37 corrected scans), relocalized as a robot would be on the map of"
echo "   the log's second half, which the robot reaches again; the first fix becomes /initialpose"
raw="$(dirname "$0")/../tests/data/ros2/fr079-raw-first150.log.gz"
"$keyplace" map "$log" --scans 732: --out "$out/map-second-half.kpm" >/dev/null
"$keyplace" relocalize --map "$out/map-second-half.kpm" --log "$raw" \
  --fixes "$out/robot-fixes.tsv" --initialpose "$out/robot-initialpose.yaml" | sed -n '3,6p'
echo
echo "Outputs in $out: info.json, features.json, keypoints.tsv, map-table2.json, map.kpm, map.png,"
echo "map.json, localize.json, localize-queries.tsv, localize-curve.tsv, localize-stream.txt,"
echo "map-first-half.kpm, relocalize.json, relocalize.png, map-second-half.kpm, robot-fixes.tsv,"
echo "robot-initialpose.yaml"
