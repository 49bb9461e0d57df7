#!/usr/bin/env bash
# Opens a report in headless Chromium (Debian's package, installed when missing) and saves a
# screenshot of the whole page, to check that every table and picture renders in a browser.
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
