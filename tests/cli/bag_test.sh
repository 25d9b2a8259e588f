#!/usr/bin/env bash
# ROS 1 bags through the command line (issue 16): info lists topics, types and counts; map,
# features and odometry read a bag like a log (the fr079 bag's scans are the rebuilt log's); the
# bag flags and --set input.* reach the reader; a missing topic, a bad laser pose, a bag through a
# pipe and a truncated bag get messages naming the bag and the problem.
# Usage: bag_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
shared=${KEYPLACE_SHARED:-$source_dir/../shared}
bag="$shared/data/fr079.orig.bag"
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"

# info: topics with types and counts, as text and JSON.
check "info bag" "$keyplace" info "$bag" --json "$work/info.json"
grep -qE '^  /scan +sensor_msgs/LaserScan +4934$' "$work/out" && ok || fail "info lists /scan"
grep -qE '^  /tf_static +tf2_msgs/TFMessage +1$' "$work/out" && ok || fail "info lists /tf_static"
/usr/bin/python3 - "$work/info.json" <<'PY' && ok || fail "info JSON topics"
import json, sys
j = json.load(open(sys.argv[1]))
topics = {t['topic']: (t['type'], t['messages']) for t in j['topics']}
assert j['format'] == 'ROS 1 bag' and j['scans'] == 4934, j
assert topics == {'/odom': ('nav_msgs/Odometry', 8951), '/scan': ('sensor_msgs/LaserScan', 4934),
                  '/tf': ('tf2_msgs/TFMessage', 8951), '/tf_static': ('tf2_msgs/TFMessage', 1)}, topics
PY

# The bag with the log's beam spacing describes as the log rebuilt from it (the keypoints and
# the map are compared exactly in tests/mapping/bag_map_test.cpp: they need the log's 6-decimal
# poses).
check "info log" "$keyplace" info "$shared/data/fr079-raw.log.gz" --json "$work/log.json"
check "info bag as log" "$keyplace" info "$bag" --json "$work/bag.json" \
  --laser-pose -0.04,0,0 --set input.scan_fov_rad=3.141592653589793
/usr/bin/python3 - "$work/log.json" "$work/bag.json" "$work/info.json" <<'PY' && ok || fail "bag and log describe alike"
import json, sys
log, bag, raw = (json.load(open(p)) for p in sys.argv[1:])
for key in ('scans', 'beams_total', 'no_return_beams', 'invalid_beams', 'field_of_view_deg',
            'odometry_messages'):
    assert log[key] == bag[key], (key, log[key], bag[key])
assert abs(log['path_length_m'] - bag['path_length_m']) < 1e-3, (log['path_length_m'], bag['path_length_m'])
assert abs(raw['field_of_view_deg'] - 180.5) < 0.01, raw['field_of_view_deg']  # pi/359 steps
PY
check "features bag" "$keyplace" features "$bag" --scans 0:200 --tsv "$work/bag.tsv"
[ "$(wc -l <"$work/bag.tsv")" -gt 1000 ] && ok || fail "features of a bag"

# map and odometry run on a bag; the laser pose given is recorded in the map's configuration.
check "map bag" "$keyplace" map "$bag" --scans 0:400 --laser-pose=-0.04,0,0 --json "$work/map.json"
/usr/bin/python3 -c "
import json, sys
j = json.load(open(sys.argv[1]))
assert j['config']['input']['laser_pose'] == '-0.04,0,0' and j['submaps'] > 0, j['config']['input']
" "$work/map.json" && ok || fail "map JSON records input.laser_pose"
check "odometry bag" "$keyplace" odometry "$bag" --scans 0:300 --steps "$work/steps.tsv" \
  --json "$work/odo.json" --out "$work/icp.tsv"
grep -qE '^ICP vs odometry median [0-9.]+ m, [0-9.]+ deg per step' "$work/out" && ok ||
  fail "odometry prints how far ICP and odometry part"
/usr/bin/python3 - "$work/odo.json" "$work/steps.tsv" "$source_dir/scripts" <<'PY' && ok ||
  fail "odometry --steps"
import json, math, statistics, sys
sys.path.insert(0, sys.argv[3])
from replay_steps import between
j = json.load(open(sys.argv[1]))
rows = [l.rstrip('\n').split('\t') for l in open(sys.argv[2]) if not l.startswith('#')]
assert len(rows) == 300 and rows[0][2] == 'first_scan', len(rows)
converged = [float(r[13]) for r in rows if r[2] in ('registered', 'recovered')]
d = j['step_disagreement']
assert d['steps'] == len(converged) > 250, (d, len(converged))
assert abs(d['median_m'] - statistics.median(converged)) < 1e-5, (d, statistics.median(converged))
# The disagreement columns are the ICP step seen from the odometry step (T_odo^-1 * T_icp).
for r in rows[1:]:
    icp, odometry = [float(v) for v in r[7:10]], [float(v) for v in r[10:13]]
    d = between(odometry, icp)
    assert abs(math.hypot(d[0], d[1]) - float(r[13])) < 2e-5, r
    assert abs(abs(math.degrees(d[2])) - float(r[14])) < 2e-3, r
PY
# Replaying the steps as ICP took them gives the ICP trajectory back (in its first pose's frame);
# as the odometry measured them, another one.
replay="$source_dir/scripts/replay_steps.py"
check "replay icp" python3 "$replay" "$work/steps.tsv" --out "$work/replay_icp.tsv"
check "replay odometry" python3 "$replay" "$work/steps.tsv" --rule odometry \
  --out "$work/replay_odometry.tsv"
/usr/bin/python3 - "$work/icp.tsv" "$work/replay_icp.tsv" "$work/replay_odometry.tsv" <<'PY' && ok ||
import math, sys
def poses(path):
    return [tuple(map(float, l.split()[:4])) for l in open(path) if not l.startswith('#')]
icp, replayed, odometry = (poses(p) for p in sys.argv[1:])
t0, x0, y0, a0 = icp[0]
def relative(p):
    dx, dy = p[1] - x0, p[2] - y0
    return (math.cos(a0) * dx + math.sin(a0) * dy, -math.sin(a0) * dx + math.cos(a0) * dy)
assert len(icp) == len(replayed) == 300, (len(icp), len(replayed))
worst = max(math.dist(relative(p), q[1:3]) for p, q in zip(icp, replayed))
assert worst < 1e-3, worst
assert all(p[0] == q[0] for p, q in zip(icp, replayed)), 'stamps'
apart = max(math.dist(p[1:3], q[1:3]) for p, q in zip(replayed, odometry))
assert apart > 0.05, apart
PY
  fail "replayed ICP steps are the ICP trajectory"
head -5 "$work/steps.tsv" >"$work/cut_steps.tsv"
printf '7\t1.0\tregistered\n' >>"$work/cut_steps.tsv"
fails_with "replay names a bad line" "cut_steps.tsv:6: 3 columns" python3 "$replay" \
  "$work/cut_steps.tsv"
fails_with "replay bad rule" "unknown rule" python3 "$replay" "$work/steps.tsv" --rule blend:2
check "dump-config bag flags" "$keyplace" dump-config --scan-topic /base_scan
grep -qF 'scan_topic: /base_scan' "$work/out" && ok || fail "--scan-topic sets input.scan_topic"

# Errors name the bag and the problem.
fails_with "missing topic" "$bag: no topic /base_scan" "$keyplace" map "$bag" --scan-topic /base_scan
grep -qF '/scan (sensor_msgs/LaserScan, 4934)' "$work/err" && ok || fail "missing topic lists topics"
fails_with "wrong type" "topic /tf holds tf2_msgs/TFMessage messages, not sensor_msgs/LaserScan" \
  "$keyplace" info "$bag" --scan-topic /tf
fails_with "bad laser pose" "input.laser_pose" "$keyplace" info "$bag" --laser-pose 1,2
fails_with "bag through a pipe" "a ROS 1 bag through a pipe" \
  "$keyplace" info <(cat "$bag")

# A bag cut off: its complete chunks are read, with a warning naming it.
head -c 1300000 "$bag" >"$work/cut.bag"
check "truncated bag" "$keyplace" info "$work/cut.bag"
grep -qF "$work/cut.bag: the bag's index is missing or damaged" "$work/err" && ok ||
  fail "truncated bag warning"

finish bag_test
