#!/usr/bin/env bash
# The studio in a real browser, RUNS times (default 3): prints each run's drag →
# redraw latency line and the median of the per-run medians. Needs scripts/setup-studio,
# tools/studio-browser-test/node_modules (npm ci) and /usr/bin/chromium.
# Usage: bench/studio_browser.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
runs="${1:-3}"
cargo build --release -q -p fieldtex-cli
medians=()
for i in $(seq "$runs"); do
  line="$(node tools/studio-browser-test/run.js | grep 'LATENCY')"
  echo "run $i: ${line#*] }"
  medians+=("$(echo "$line" | sed -E 's/.*median ([0-9.]+) ms.*/\1/')")
done
printf '%s\n' "${medians[@]}" | sort -n | awk '{a[NR]=$1} END {print "median of the run medians: " a[int((NR+1)/2)] " ms (target 50 ms)"}'
uptime
