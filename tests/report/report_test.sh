#!/usr/bin/env bash
# keyplace report on a small fixture: the first 300 scans of the bundled FR079 log, --quick.
# Checks that the page holds every section, table and figure (the raw-log sections marked "not
# computed", since the fixture has no raw log), that a rerun reuses every artefact, that --no-run
# renders from the work directory alone, and that bad input gives errors naming the file/option.
# Usage: report_test.sh KEYPLACE_BINARY SOURCE_DIR [KEEP_DIR]
#   KEEP_DIR: where to leave the report (for the Chromium check); default: a temporary directory.
set -uo pipefail
keyplace=$1
source_dir=$2
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"
out=${3:-$work/report}
rm -rf "$out"
expect() {  # expect PATTERN FILE DESCRIPTION
  if grep -q -- "$1" "$2"; then ok; else fail "$3 (no '$1' in $2)"; fi
}

mkdir -p "$work/data"
# 300 scans (each a VERTEX2 and a ROBOTLASER1 line); the name keeps the data set recognisable.
zcat "$source_dir/data/fr079-corrected.log.gz" | head -600 | gzip >"$work/data/fr079-corrected.log.gz"

run=("$keyplace" report --data "$work/data" --datasets fr079 --quick --threads 2)
if "${run[@]}" --out "$out" >"$work/first.txt" 2>&1; then ok; else
  fail "first run"
  cat "$work/first.txt"
fi
page=$out/index.html
[ -s "$page" ] && ok || fail "no $page"
expect '^\[1/[0-9]*\] map-fr079 ' "$work/first.txt" "progress lines"
# What the first run did, to compare the rerun with (the plan's size is not fixed here).
ran=$(grep -c '^    done in ' "$work/first.txt")
skipped=$(grep -c ': skipped, needs ' "$work/first.txt")
[ "$ran" -ge 10 ] && ok || fail "expected at least 10 steps to run, $ran ran"
expect 'report written to' "$work/first.txt" "summary line"

# Every table and figure section.
for anchor in maps stability table2 fig8 table6 table5 fig9 table3 table4 table7 table8 \
              relocalize table9 loops fig10 table10 commands; do
  expect "id=\"$anchor\"" "$page" "section $anchor"
done
for caption in "Figure 3 (ours)" "Figure 6 (ours)" "Figure 7 (ours)" "Figure 8 (ours), FR079" \
               "Figure 9 (ours), FR079, <code>--preset default" \
               "Figure 9 (ours), FR079, <code>--preset paper" \
               "Kidnapped robot (ours), FR079: corrected log"; do
  expect "$caption" "$page" "figure caption '$caption'"
done
images=$(grep -o '<img src="data:image/png;base64,' "$page" | wc -l)
[ "$images" -eq 7 ] && ok || fail "expected 7 embedded figures, found $images"
# No file references: the page is self-contained.
if grep -q '<img src="[^d]' "$page"; then fail "an image is not embedded"; else ok; fi
# Ours beside the paper's: the paper's Table II and III rows for FR079, and our values with a
# difference under them.
expect '<td>paper</td><td>0.120</td><td>5.20</td><td>17.80</td>' "$page" "Table II paper row"
expect '<td>paper</td><td>1.000</td><td>0.710</td><td>6.05</td>' "$page" "Table III paper row"
expect 'keyplace, overlap criterion only' "$page" "Table II our row"
expect 'class="diff"' "$page" "differences"
expect 'class="\(better\|worse\|differs\)"' "$page" "highlighted differences"
# Table V: the paper's parameters beside our defaults.
expect '<td>l_g (m)</td><td class="text">Table V</td><td>0.1</td><td>0.1</td>' "$page" "Table V l_g"
# Sections without data say how to make them.
expect 'not computed: run <code>keyplace slam ' "$page" "slam marked not computed"
expect 'not computed: run <code>keyplace localize --map .* --poses icp' "$page" \
  "raw localization marked not computed"
# The kidnapped robot: the corrected log's row (6 starts) and the raw log's "not computed".
expect '<tr><th>FR079</th><td class="text">the map.s own log, shared-scan exclusion</td><td>6 (' \
  "$page" "kidnapped-robot row"
expect '<tr><th>FR079_r</th><td colspan="9" class="missing">not computed: run <code>keyplace relocalize --map .* --poses icp' \
  "$page" "raw kidnapped robot marked not computed"
expect 'Quick mode' "$page" "quick-mode warning"
if grep -q '<h2>Warnings' "$page"; then fail "the page has warnings"; else ok; fi

# A rerun reuses everything.
if "${run[@]}" --out "$out" --json "$work/second.json" >"$work/second.txt" 2>&1; then ok; else
  fail "second run"
fi
# --json: where the page is and what became of each step (here: all reused or skipped).
if /usr/bin/python3 - "$work/second.json" "$out" "$ran" "$skipped" <<'EOF'; then ok; else fail "report --json"; fi
import json, os, sys
j = json.load(open(sys.argv[1]))
out, ran, skipped = sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
assert j["index"] == os.path.join(out, "index.html") and j["page_bytes"] == os.path.getsize(j["index"]), j
assert j["work"] == os.path.join(out, "work") and j["datasets"] == "fr079" and j["quick"], j
assert (j["steps_ran"], j["steps_done_before"], j["steps_skipped"], j["steps_failed"]) == (0, ran, skipped, 0), j
assert j["steps_total"] == len(j["steps"]) == ran + skipped, j
states = {s["state"] for s in j["steps"]}
assert states <= {"done", "skipped"}, states
assert all(s["command"].startswith("keyplace ") for s in j["steps"]), j["steps"][0]
assert all(s["message"] for s in j["steps"] if s["state"] == "skipped"), j["steps"]
EOF
expect "Steps: 0 ran, $ran reused, $skipped skipped, 0 failed" "$page" "rerun reuses the $ran artefacts"
if grep -q '^    keyplace ' "$work/second.txt"; then fail "the rerun ran a command"; else ok; fi

# --no-run renders from an existing work directory into another page.
if "$keyplace" report --out "$work/norun" --work "$out/work" --data "$work/data" --datasets fr079 \
    --quick --no-run >"$work/norun.txt" 2>&1; then ok; else fail "--no-run"; fi
expect "Steps: 0 ran, $ran reused" "$work/norun/index.html" "--no-run page"
# (without --threads: the thread count is no part of a step's identity)

# Errors name the culprit.
if "$keyplace" report --out "$work/bad" --datasets fr079,mars >"$work/bad.txt" 2>&1; then
  fail "unknown data set accepted"
else
  expect "unknown data set 'mars'" "$work/bad.txt" "unknown data set message"
fi
cp -r "$out/work" "$work/broken-work"
echo '{ not json' >"$work/broken-work/maps/fr079.json"
if "$keyplace" report --out "$work/broken" --work "$work/broken-work" --data "$work/data" \
    --datasets fr079 --quick --no-run >"$work/broken.txt" 2>&1; then
  fail "a corrupt artefact was accepted"
else
  expect 'maps/fr079.json: not valid JSON' "$work/broken.txt" "corrupt artefact message"
fi

finish report_test
