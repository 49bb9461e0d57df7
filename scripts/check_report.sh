#!/usr/bin/env bash
# Opens a report in headless Chromium (Debian's package, installed when missing) and saves a
# screenshot of the whole page, to check that every table and picture renders in a browser; then
# checks that every published table of results/reference/papers.json (each top-level key but
# "comment" and "claims") and the scorecard appear in the report. Exit 1 when one is missing.
# Usage: scripts/check_report.sh [results/report/report.html] [screenshot.png]
set -euo pipefail
cd "$(dirname "$0")/.."
html="${1:-results/report/report.html}"
png="${2:-$(dirname "$html")/screenshot.png}"
[ -f "$html" ] || { echo "check_report: no $html (run scripts/run.sh or scripts/report.py first)" >&2; exit 2; }
if ! command -v chromium >/dev/null; then
  SUDO=; [ "$(id -u)" -eq 0 ] || SUDO=sudo
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium >/dev/null
fi
abs="$(cd "$(dirname "$html")" && pwd)/$(basename "$html")"
# A tall window: the report is one long page.
chromium --headless=new --no-sandbox --disable-gpu --hide-scrollbars --window-size=1200,6000 \
  --screenshot="$png" "file://$abs" 2>/dev/null
# The page must have loaded its embedded pictures: count them in the HTML.
imgs=$(grep -o '<img src="data:image/png;base64' "$html" | wc -l)
echo "check_report: $html has $imgs embedded pictures; screenshot $png ($(stat -c %s "$png") bytes)"
# Every published table and record of papers.json must appear (as a section id or in the text),
# and the scorecard must be there.
/usr/bin/python3 - "$html" <<'PY'
import json, pathlib, sys
doc = pathlib.Path(sys.argv[1]).read_text()
papers = json.loads(pathlib.Path("results/reference/papers.json").read_text())
keys = [k for k in papers if k not in ("comment", "claims")]
missing = [k for k in keys if k not in doc]
if 'id="scorecard"' not in doc:
    missing.append("the reproduction scorecard")
if missing:
    print("check_report: missing from the report: " + ", ".join(missing), file=sys.stderr)
    sys.exit(1)
print(f"check_report: all {len(keys)} published tables of papers.json and the scorecard are in the report")
PY
