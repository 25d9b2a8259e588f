#!/usr/bin/env bash
# What a new user meets first, on tiny inputs (seconds, the committed 150-scan slice of the raw
# FR079 log): every configuration source (--config, --set) applied before one validation, whatever
# the order; "did you mean" for commands and keys; hints in the first errors; progress lines off
# a terminal; TUM trajectories.
# Usage: usability_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"
raw=$source_dir/tests/data/ros2/fr079-raw-first150.log.gz  # 150 scans with odometry only
bag=$source_dir/tests/data/ros2/mcap-zstd                   # the same as a ROS 2 bag

# Validated once after every source: settings valid only together pass in either order (the
# default max_range_m is 30 m), from --set and from a file followed by --set.
for order in "min_range_m=40 max_range_m=60" "max_range_m=60 min_range_m=40"; do
  read -r first second <<<"$order"
  check "--set odometry.$first then odometry.$second" sh -c "'$keyplace' dump-config \
    --set odometry.$first --set odometry.$second | grep -q '^  min_range_m: 40 '"
done
printf 'odometry:\n  min_range_m: 40\n' >"$work/min40.yaml"
check "--config min_range_m=40 then --set max_range_m" "$keyplace" dump-config \
  --config "$work/min40.yaml" --set odometry.max_range_m=60
fails_with "min above max names both settings" "odometry.min_range_m=40 from $work/min40.yaml:2" \
  "$keyplace" dump-config --config "$work/min40.yaml" --set odometry.max_range_m=35
fails_with "one invalid setting named with its origin" "--set: mapping.min_overlap" \
  "$keyplace" dump-config --set mapping.min_overlap=1.5

# "Did you mean": a mistyped command or key names the closest ones; nothing close, no guess.
fails_with "mistyped command" "'mpa' is not a keyplace command; did you mean 'map'?" \
  "$keyplace" mpa "$raw"
fails_with "mistyped command, nothing close" "'zzzz' is not a keyplace command (keyplace --help" \
  "$keyplace" zzzz
fails_with "mistyped key" \
  "unknown configuration key 'odometry.max_rang_m'; did you mean 'odometry.max_range_m'?" \
  "$keyplace" dump-config --set odometry.max_rang_m=60
fails_with "key in the wrong section" "did you mean 'mapping.min_overlap'?" \
  "$keyplace" dump-config --set place.min_overlap=0.5
printf 'odometry:\n  min_rang_m: 1\n' >"$work/typo.yaml"
fails_with "mistyped key in a file" \
  "typo.yaml:2: unknown configuration key 'odometry.min_rang_m'; did you mean 'odometry.min_range_m'?" \
  "$keyplace" dump-config --config "$work/typo.yaml"

# Hints in the first errors a new user meets: a raw log (odometry poses only) asked for its
# corrected poses names --poses icp; a bag without the scan topic names its LaserScan topics.
fails_with "raw log without --poses icp" "--poses icp matches its scans from the odometry" \
  "$keyplace" map "$raw" --poses corrected
fails_with "bag without the scan topic" \
  "sensor_msgs/msg/LaserScan on /scan (--scan-topic /scan)" \
  "$keyplace" map "$bag" --scan-topic /base_scan

# Progress: whole lines on stderr when it is not a terminal (the first scan, then every few
# seconds, then the end), none with KEYPLACE_PROGRESS=0, the bar with KEYPLACE_PROGRESS=1.
(unset KEYPLACE_PROGRESS; "$keyplace" features "$raw" --scans 0:30 >/dev/null 2>"$work/lines.err")
check "progress lines off a terminal" /usr/bin/python3 -c "
import re, sys
lines = open(sys.argv[1]).read().split('\n')
assert '\r' not in ''.join(lines), lines
progress = [l for l in lines if l.startswith('keyplace: features  ')]
assert re.fullmatch(r'keyplace: features  1/30  3 %  ETA [0-9]+ s', progress[0]), progress
assert re.fullmatch(r'keyplace: features  30/30  done in [0-9.]+ s', progress[-1]), progress
" "$work/lines.err"
KEYPLACE_PROGRESS=0 "$keyplace" features "$raw" --scans 0:30 >/dev/null 2>"$work/quiet.err"
check "no progress with KEYPLACE_PROGRESS=0" test ! -s "$work/quiet.err"
KEYPLACE_PROGRESS=1 "$keyplace" features "$raw" --scans 0:30 >/dev/null 2>"$work/bar.err"
check "the bar with KEYPLACE_PROGRESS=1" grep -q $'\rfeatures  30/30  done in' "$work/bar.err"

# --trajectory-format tum: odometry --out and slam --trajectory as `stamp x y z qx qy qz qw`, the
# same poses as the TSV (heading from the quaternion).
check "odometry --trajectory-format tum" "$keyplace" odometry "$raw" --scans 0:40 \
  --out "$work/odo.tum" --trajectory-format tum
check "odometry tsv" "$keyplace" odometry "$raw" --scans 0:40 --out "$work/odo.tsv"
check "slam --trajectory-format tum" "$keyplace" slam "$raw" --trajectory "$work/slam.tum" \
  --trajectory-format tum
check "slam tsv" "$keyplace" slam "$raw" --trajectory "$work/slam.tsv"
check "TUM files hold the TSV's poses" /usr/bin/python3 -c "
import math, sys
def rows(path, columns):
    return [[float(v) for v in l.split()] for l in open(path)
            if l.strip() and not l.startswith('#') and not l.startswith('scan_index')]
for tum, tsv, stamp, x, y, theta, count in [(sys.argv[1], sys.argv[2], 0, 1, 2, 3, 40),
                                            (sys.argv[3], sys.argv[4], 1, 2, 3, 4, 150)]:
    a, b = rows(tum, 8), rows(tsv, 0)
    assert len(a) == len(b) == count, (tum, len(a), len(b))
    for r, s in zip(a, b):
        assert len(r) == 8 and r[3] == r[4] == r[5] == 0, r
        assert abs(r[6] ** 2 + r[7] ** 2 - 1) < 1e-12, r
        assert abs(r[0] - s[stamp]) < 1e-6 and abs(r[1] - s[x]) < 1e-6 and abs(r[2] - s[y]) < 1e-6
        d = 2 * math.atan2(r[6], r[7]) - s[theta]
        assert abs(math.atan2(math.sin(d), math.cos(d))) < 1e-6, (r, s)
" "$work/odo.tum" "$work/odo.tsv" "$work/slam.tum" "$work/slam.tsv"
fails_with "unknown trajectory format" "--trajectory-format" "$keyplace" odometry "$raw" \
  --out "$work/x.txt" --trajectory-format kitti

finish usability_test
