#!/usr/bin/env bash
# ROS 2 bags through the command line (issue 16): info lists topics, types and counts of a rosbag2
# directory and describes it as the CARMEN slice it was written from; map and features read it
# like a log; a .db3 is a log, not a map; errors name the bag and the problem. Reads the committed
# fixtures of tests/data/ros2 (no ../shared needed).
# Usage: ros2_bag_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
data=$source_dir/tests/data/ros2
bag=$data/mcap-zstd
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"

check "info ros2 bag" "$keyplace" info "$bag" --json "$work/info.json"
grep -qE '^  /scan +sensor_msgs/msg/LaserScan +150$' "$work/out" && ok || fail "info lists /scan"
grep -qE '^  /tf_static +tf2_msgs/msg/TFMessage +1$' "$work/out" && ok || fail "info lists /tf_static"
check "info slice" "$keyplace" info "$data/fr079-raw-first150.log.gz" --json "$work/log.json"
/usr/bin/python3 - "$work/log.json" "$work/info.json" <<'PY' && ok || fail "bag and log describe alike"
import json, sys
log, bag = (json.load(open(p)) for p in sys.argv[1:])
assert bag['format'] == 'ROS 2 bag' and bag['scans'] == 150, bag
topics = {t['topic']: (t['type'], t['messages']) for t in bag['topics']}
assert topics['/odom'] == ('nav_msgs/msg/Odometry', log['odometry_messages']), topics
for key in ('scans', 'beams_total', 'no_return_beams', 'invalid_beams', 'odometry_messages'):
    assert log[key] == bag[key], (key, log[key], bag[key])
assert abs(log['path_length_m'] - bag['path_length_m']) < 1e-4, (log['path_length_m'], bag['path_length_m'])
PY

# A .db3 is an SQLite file but a bag, not a map.
check "info db3" "$keyplace" info "$data/sqlite3/sqlite3_0.db3"
grep -qF 'ROS 2 bag' "$work/out" && ok || fail "info .db3 is a bag"
check "map ros2 bag" "$keyplace" map "$bag" --json "$work/map.json" --out "$work/bag.kpm"
/usr/bin/python3 -c "
import json, sys
j = json.load(open(sys.argv[1]))
assert j['submaps'] > 0, j
" "$work/map.json" && ok || fail "map of a ROS 2 bag has submaps"
check "features metadata.yaml" "$keyplace" features "$data/sqlite3/metadata.yaml" --scans 0:20

fails_with "missing topic" "$bag: no topic /base_scan" "$keyplace" info "$bag" --scan-topic /base_scan
fails_with "no metadata" "$work: a directory without metadata.yaml" "$keyplace" map "$work"
head -c 40000 "$bag/mcap-zstd_0.mcap" >"$work/cut.mcap"
check "cut mcap" "$keyplace" info "$work/cut.mcap"
grep -qF "$work/cut.mcap: cut off at byte" "$work/err" && ok || fail "cut MCAP warning"

finish ros2_bag_test
