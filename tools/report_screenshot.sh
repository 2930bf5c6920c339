#!/usr/bin/env bash
# docs/report.png: `abcube report` on cornell, as headless Chromium draws the page.
# Usage: bash tools/report_screenshot.sh [ABCUBE]   (default build/abcube; needs chromium)
set -euo pipefail
cd "$(dirname "$0")/.."
ABCUBE=${1:-build/abcube}
WORK=$(mktemp -d /tmp/abcube_screenshot.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
"$ABCUBE" report scenes/cornell.json -o "$WORK/report" --width 320 --height 240 --cube-res 128 --sweep 64,128,256
chromium --headless=new --no-sandbox --disable-gpu --no-first-run --user-data-dir="$WORK/profile" \
  --hide-scrollbars --window-size=1280,1500 --virtual-time-budget=15000 \
  --screenshot="$WORK/page.png" "file://$WORK/report/index.html" 2> /dev/null
python3 - "$WORK/page.png" docs/report.png <<'PY'
import shutil, sys
shutil.copyfile(sys.argv[1], sys.argv[2])
PY
echo "docs/report.png written"
