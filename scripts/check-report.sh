#!/usr/bin/env bash
# Opens a keyplace report in headless Chromium, saves a screenshot, and fails when an image did
# not load (missing, or not decodable: naturalWidth 0) or the page logged a console error, a
# JavaScript error or a resource load failure.
#
# Usage: scripts/check-report.sh REPORT_DIR_OR_HTML [SCREENSHOT.png]
#   REPORT_DIR_OR_HTML  the report directory (its index.html is checked) or an HTML file
#   SCREENSHOT.png      where to save the screenshot (default: next to the page, screenshot.png)
# Environment: CHROMIUM (default: chromium, else chromium-browser), WINDOW (default 1280,2400).
# Exit status: 0 page fine, 1 broken images or console errors, 2 usage or set-up problem.
set -euo pipefail

if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
page=$1
[ -d "$page" ] && page=$page/index.html
if [ ! -f "$page" ]; then
  echo "check-report: $page: no such file" >&2
  exit 2
fi
page=$(realpath "$page")
screenshot=${2:-$(dirname "$page")/screenshot.png}
window=${WINDOW:-1280,2400}

browser=${CHROMIUM:-}
if [ -z "$browser" ]; then
  for candidate in chromium chromium-browser google-chrome; do
    if command -v "$candidate" >/dev/null 2>&1; then
      browser=$candidate
      break
    fi
  done
fi
if [ -z "$browser" ]; then
  echo "check-report: no chromium found (Debian: apt-get install chromium;" \
       "scripts/install-deps.sh installs it)" >&2
  exit 2
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

flags=(--headless --disable-gpu --no-sandbox --no-first-run --no-default-browser-check
       --disable-extensions --disable-background-networking --disable-sync --mute-audio
       --hide-scrollbars "--user-data-dir=$work/profile" "--window-size=$window")

# 1. The screenshot, of the page as it is.
if ! timeout 120 "$browser" "${flags[@]}" "--screenshot=$(realpath -m "$screenshot")" \
    "file://$page" >"$work/screenshot.log" 2>&1 || [ ! -s "$screenshot" ]; then
  echo "check-report: $browser could not take a screenshot of $page:" >&2
  tail -20 "$work/screenshot.log" >&2
  exit 2
fi

# 2. The checks, on a copy of the page with a probe script first in <head> (the report itself
# has no script). The probe records console errors, uncaught errors and failed loads, and after
# the load event writes what it found into an attribute of <html>, which --dump-dom prints.
probe='<script>
(function () {
  var problems = [];
  var describe = function (x) { try { return String(x && x.message || x); } catch (e) { return "?"; } };
  var original = console.error;
  console.error = function () {
    problems.push("console.error: " + Array.prototype.map.call(arguments, describe).join(" "));
    return original.apply(console, arguments);
  };
  window.addEventListener("error", function (event) {
    var target = event.target;
    if (target && target !== window && (target.src || target.href)) {
      problems.push("failed to load " + String(target.src || target.href).slice(0, 80));
    } else {
      problems.push("error: " + describe(event.message || event.error));
    }
  }, true);
  window.addEventListener("unhandledrejection", function (event) {
    problems.push("unhandled rejection: " + describe(event.reason));
  });
  window.addEventListener("load", function () {
    var images = document.images;
    for (var i = 0; i < images.length; ++i) {
      if (!images[i].complete || images[i].naturalWidth === 0) {
        problems.push("image " + (i + 1) + " did not load: " +
                      (images[i].getAttribute("alt") || String(images[i].src).slice(0, 80)));
      }
    }
    var root = document.documentElement;
    root.setAttribute("data-check-images", String(images.length));
    root.setAttribute("data-check-problems", JSON.stringify(problems));
    root.setAttribute("data-check-done", "1");
  });
})();
</script>'
probed=$(dirname "$page")/.check-report-$$.html
trap 'rm -rf "$work" "$probed"' EXIT
python3 - "$page" "$probed" "$probe" <<'EOF'
import re, sys
page, probed, probe = sys.argv[1], sys.argv[2], sys.argv[3]
html = open(page, encoding="utf-8", errors="replace").read()
match = re.search(r"<head[^>]*>", html, re.I)
html = html[:match.end()] + probe + html[match.end():] if match else probe + html
open(probed, "w", encoding="utf-8").write(html)
EOF
timeout 120 "$browser" "${flags[@]}" --virtual-time-budget=15000 --enable-logging=stderr --v=0 \
  --dump-dom "file://$probed" >"$work/dom.html" 2>"$work/browser.log" || true

result=$(python3 - "$work/dom.html" "$work/browser.log" <<'EOF'
import html, json, re, sys
dom = open(sys.argv[1], encoding="utf-8", errors="replace").read()
log = open(sys.argv[2], encoding="utf-8", errors="replace").read()
head = dom[:4000]
if 'data-check-done="1"' not in head:
    print("FAIL")
    print("  the page did not finish loading (no load event within the time budget)")
    sys.exit()
images = re.search(r'data-check-images="(\d+)"', head).group(1)
problems = json.loads(html.unescape(re.search(r'data-check-problems="([^"]*)"', head).group(1)))
# Console errors Chromium reports itself (e.g. resources blocked before the probe could see them).
for line in log.splitlines():
    if ":CONSOLE(" in line and ("ERROR" in line.split(":CONSOLE(")[0] or "Uncaught" in line):
        problems.append("browser log: " + line.strip()[:200])
print("FAIL" if problems else "OK " + images)
for p in problems:
    print("  " + p)
EOF
)
status=${result%%$'\n'*}
if [ "${status%% *}" != "OK" ]; then
  echo "check-report: $page: problems found (screenshot $screenshot):" >&2
  echo "$result" | sed 1d >&2
  exit 1
fi
echo "check-report: $page: ${status#OK } images loaded, no console errors; screenshot $screenshot"
