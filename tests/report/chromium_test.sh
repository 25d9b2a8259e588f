#!/usr/bin/env bash
# scripts/check-report.sh in headless Chromium: the fixture report (made by the cli.report test)
# passes with a screenshot; a page with a broken image, one with a missing image file and one
# with a console error must fail.
# Usage: chromium_test.sh SOURCE_DIR REPORT_DIR
set -uo pipefail
source_dir=$1
report=$2
check="$source_dir/scripts/check-report.sh"
# shellcheck source=../support/script_checks.sh
source "$source_dir/tests/support/script_checks.sh"

if [ ! -s "$report/index.html" ]; then
  echo "chromium_test: $report/index.html missing (the cli.report test makes it)"
  exit 1
fi

# The real report.
if bash "$check" "$report" "$work/shot.png" >"$work/good.txt" 2>&1; then ok; else
  fail "the fixture report did not pass"
  cat "$work/good.txt"
fi
[ -s "$work/shot.png" ] && ok || fail "no screenshot"
if python3 -c "import sys; d=open(sys.argv[1],'rb').read(24); sys.exit(0 if d[:8]==b'\x89PNG\r\n\x1a\n' and int.from_bytes(d[16:20],'big')==1280 else 1)" "$work/shot.png"; then
  ok
else
  fail "the screenshot is not a 1280 px wide PNG"
fi
grep -q '7 images loaded' "$work/good.txt" && ok || fail "expected 7 images: $(cat "$work/good.txt")"

# The same page with its first image's data replaced by bytes that are no PNG.
python3 - "$report/index.html" "$work/broken.html" <<'PY'
import re, sys
html = open(sys.argv[1], encoding="utf-8").read()
html = re.sub(r'data:image/png;base64,[A-Za-z0-9+/=]+', 'data:image/png;base64,bm90IGEgcG5n', html,
              count=1)
open(sys.argv[2], "w", encoding="utf-8").write(html)
PY
fails_with "a broken image" "image 1 did not load" bash "$check" "$work/broken.html" \
  "$work/broken.png"

# A missing image file.
cat >"$work/missing.html" <<'HTML'
<!DOCTYPE html><html><head><meta charset="utf-8"><title>t</title></head>
<body><p>text</p><img src="no-such-figure.png" alt="fig"></body></html>
HTML
fails_with "a missing image" "did not load" bash "$check" "$work/missing.html" "$work/missing.png"

# A console error and a script error.
cat >"$work/console.html" <<'HTML'
<!DOCTYPE html><html><head><meta charset="utf-8"><title>t</title></head>
<body><p>text</p><script>console.error("figure data missing"); undefinedFunction();</script>
</body></html>
HTML
fails_with "a console error" "console.error: figure data missing" bash "$check" \
  "$work/console.html" "$work/console.png"
# fails_with leaves the error output in $work/err: the script error is reported too.
grep -q 'undefinedFunction' "$work/err" && ok || fail "script error not reported: $(cat "$work/err")"

# Usage errors.
fails_with "a missing page" "no such file" bash "$check" "$work/nothing-here"

finish chromium_test
