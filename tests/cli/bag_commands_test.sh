#!/usr/bin/env bash
# Bags through every command that reads a log (issue 16): localize, relocalize, slam and sweep
# mapping on a committed ROS 2 fixture (tests/data/ros2: the first 150 scans of the raw FR079
# log), each giving answers, and the same answers as on the CARMEN slice the bag was written
# from where the two inputs agree (odometry interpolated alike); --odom-topic with the odometry
# renamed to /wheel_odom (a copy of the sqlite3 fixture, renamed here). The ground truth of the
# raw scans: the bundled corrected log through the first lines of the shared raw -> corrected
# index. Usage: bag_commands_test.sh KEYPLACE_BINARY SOURCE_DIR
set -uo pipefail
keyplace=$1
source_dir=$2
data=$source_dir/tests/data/ros2
bag=$data/mcap-zstd
slice=$data/fr079-raw-first150.log.gz
corrected=$source_dir/data/fr079-corrected.log.gz
shared=${KEYPLACE_SHARED:-$source_dir/../shared}
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"
export KEYPLACE_PROGRESS=0

# The index pairs of the 150 raw scans (an index reaching past the query log is an error).
awk 'NR == 1 || $1 < 150' "$shared/data/fr079-raw-to-corrected.tsv" >"$work/index.tsv"
check "index slice" test "$(wc -l <"$work/index.tsv")" -gt 30
check "map" "$keyplace" map "$corrected" --scans 0:300 --out "$work/map.kpm"

for name in bag slice; do
  if [ "$name" = bag ]; then input=$bag; else input=$slice; fi
  truth=(--truth "$corrected" --index "$work/index.tsv")
  check "$name: localize" "$keyplace" localize --map "$work/map.kpm" --log "$input" --poses icp \
    "${truth[@]}" --n-pos 10 --json "$work/localize-$name.json"
  check "$name: relocalize" "$keyplace" relocalize --map "$work/map.kpm" --log "$input" \
    --poses icp "${truth[@]}" --starts 3 --threads 1 --json "$work/relocalize-$name.json"
  check "$name: slam" "$keyplace" slam "$input" --out "$work/slam-$name" \
    --json "$work/slam-$name.json"
  check "$name: sweep mapping" "$keyplace" sweep mapping --log "$input" --s-min 0.2,0.3 \
    --threads 1 --out "$work/sweep-$name" --json "$work/sweep-$name.json"
done

# Answers on the bag, and the slice's: the bag's odometry is /odom interpolated by our reader, the
# slice's by the converter (and one bag scan lies past the last /odom message), so ICP starts
# from odometry a hair apart and figures that depend on single confidences may differ; counts of
# verified and correct answers and the maps do not.
check "answers on the bag as on the slice" /usr/bin/python3 - "$work" <<'EOF'
import json, os, sys
work = sys.argv[1]
def load(kind, name):
    return json.load(open(os.path.join(work, "%s-%s.json" % (kind, name))))
bag, slice_ = load("localize", "bag"), load("localize", "slice")
assert bag["n_pos"] == 10 and bag["n_acc"] >= 8 and bag["n_cor"] == bag["n_acc"], bag
for key in ("n_pos", "n_acc", "n_cor", "n_verified", "precision", "recall"):
    assert bag[key] == slice_[key], (key, bag[key], slice_[key])
bag, slice_ = load("relocalize", "bag"), load("relocalize", "slice")
assert bag["starts"] == 3 and bag["fixes"] >= 1 and bag["wrong_fixes"] == 0, bag
assert slice_["fixes"] >= 1 and slice_["wrong_fixes"] == 0, slice_
bag, slice_ = load("slam", "bag"), load("slam", "slice")
assert bag["scans"] == 150 and bag["submaps"] >= 5, bag
for key in ("scans", "submaps", "forced_submaps", "loops_detected"):
    assert bag[key] == slice_[key], (key, bag[key], slice_[key])
bag, slice_ = load("sweep", "bag"), load("sweep", "slice")
assert bag["grid_points"] == 2 and len(bag["rows"]) == 2, bag
assert bag["sweep"]["poses"] == "icp", bag["sweep"]
for a, b in zip(bag["rows"], slice_["rows"]):
    assert a["submaps"] >= 5 and a["submaps"] == b["submaps"], (a, b)
EOF

# --odom-topic: the sqlite3 fixture with its odometry topic renamed to /wheel_odom.
renamed=$work/wheel
cp -r "$data/sqlite3" "$renamed"
/usr/bin/python3 - "$renamed/sqlite3_0.db3" <<'EOF'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
db.execute("UPDATE topics SET name = '/wheel_odom' WHERE name = '/odom'")
db.commit()
EOF
sed -i 's#name: /odom$#name: /wheel_odom#' "$renamed/metadata.yaml"
check "renamed fixture" grep -q "name: /wheel_odom" "$renamed/metadata.yaml"
fails_with "no /odom without --odom-topic" "/odom" "$keyplace" map "$renamed"
check "map --odom-topic" "$keyplace" map "$renamed" --odom-topic /wheel_odom \
  --json "$work/map-wheel.json"
check "map of the original" "$keyplace" map "$data/sqlite3" --json "$work/map-odom.json"
check "localize --odom-topic" "$keyplace" localize --map "$work/map.kpm" --log "$renamed" \
  --odom-topic /wheel_odom --poses icp --truth "$corrected" --index "$work/index.tsv" --n-pos 10 \
  --json "$work/localize-wheel.json"
check "slam --odom-topic" "$keyplace" slam "$renamed" --odom-topic /wheel_odom \
  --out "$work/slam-wheel" --json "$work/slam-wheel.json"
check "slam of the original" "$keyplace" slam "$data/sqlite3" --out "$work/slam-odom" \
  --json "$work/slam-odom.json"
# The same messages under another name: the same figures, times and file names aside.
check "--odom-topic gives the original's figures" /usr/bin/python3 - "$work" <<'EOF'
import json, os, sys
work = sys.argv[1]
def load(name):
    j = json.load(open(os.path.join(work, name)))
    return {k: v for k, v in j.items()
            if "seconds" not in k and k not in ("log", "dataset", "config")}
for a, b in (("map-wheel.json", "map-odom.json"), ("slam-wheel.json", "slam-odom.json")):
    x, y = load(a), load(b)
    assert x == y, (a, [k for k in x if x[k] != y.get(k)])
    assert x["submaps"] >= 5, x
wheel = json.load(open(os.path.join(work, "localize-wheel.json")))
assert wheel["n_acc"] >= 8 and wheel["n_cor"] == wheel["n_acc"], wheel
EOF

finish bag_commands
