#!/usr/bin/env bash
# Runs examples/python/map_and_localize.py into a scratch folder and checks what it writes, so
# that the example cannot rot. Usage: run_example.sh PYTHON SOURCE_DIR (PYTHONPATH set by ctest).
set -euo pipefail
python=$1
source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$python" "$source_dir/examples/python/map_and_localize.py" "$work" 250 | tee "$work/out.txt"
grep -Eq "^map: [0-9]+ submaps" "$work/out.txt"
grep -Eq "^streaming: [1-9][0-9]* fixes" "$work/out.txt"
grep -Eq "^localize: precision (0\.9|1\.0)" "$work/out.txt"
"$python" - "$work" <<'PYTHON'
import sys
import keyplace
import matplotlib.image

work = sys.argv[1]
assert keyplace.load_map(f"{work}/map.kpm").submap_count > 50
image = matplotlib.image.imread(f"{work}/map_and_localize.png")
assert image.shape[0] > 300 and image.shape[1] > 600, image.shape
# Not a blank canvas: the drawing covers a good part of it.
assert (image[:, :, :3].mean(axis=2) < 0.9).mean() > 0.02
print("example: map and figure checked")
PYTHON
