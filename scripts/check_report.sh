#!/usr/bin/env bash
# Opens a report in headless Chromium (Debian's package, installed when missing) and saves a
# screenshot of the whole page, to check that every table and picture renders in a browser; then
# checks that every published table of results/reference/papers.json (each top-level key but
# "comment" and "claims") and the scorecard appear in the report, that no verdict other than holds is
# without a cause or with a cause its evidence contradicts, then runs check_report_html.py
# (size, rendering, raw markdown, absolute paths, scorecard first). Exit 1 when one fails.
# Usage: scripts/check_report.sh [results/report/report.html] [screenshot.png]
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^set -/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;; esac  # the header above; nothing runs
cd "$(dirname "$0")/.."
html="${1:-results/report/report.html}"
png="${2:-$(dirname "$html")/screenshot.png}"
[ -f "$html" ] || { echo "check_report: no $html (run scripts/run.sh or omniloc report first)" >&2; exit 2; }
command -v chromium >/dev/null || scripts/install-deps.sh --report-check
abs="$(cd "$(dirname "$html")" && pwd)/$(basename "$html")"
# A tall window: the report is one long page.
chromium --headless=new --no-sandbox --disable-gpu --hide-scrollbars --window-size=1200,6000 \
  --screenshot="$png" "file://$abs" 2>/dev/null
# The page must have loaded its embedded pictures: count them in the HTML.
imgs=$(grep -oE '<img src="data:image/(png|jpeg);base64' "$html" | wc -l)
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
# Every verdict other than holds carries a cause whose evidence these results support.
for status in ("no cause recorded", "evidence contradicts the cause"):
    if f">{status}<" in doc:
        missing.append(f"a cause (the scorecard's 'Why a claim does not hold' table has '{status}')")
if missing:
    print("check_report: missing from the report: " + ", ".join(missing), file=sys.stderr)
    sys.exit(1)
print(f"check_report: all {len(keys)} published tables of papers.json and the scorecard are in the report")
PY
# What a reader sees: rendered pictures, size, no raw markdown, no absolute paths,
# the scorecard first.
/usr/bin/python3 scripts/check_report_html.py "$html"
