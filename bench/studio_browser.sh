#!/usr/bin/env bash
# The studio in a real browser, RUNS times (default 3): prints each run's latency lines
# (drag → field redrawn; edit → first 128² texture and full texture shown; cut plane
# moved → cut image shown, first and later cuts) and the median over runs of each.
# Needs scripts/setup-studio, tools/studio-browser-test/node_modules (npm ci) and
# /usr/bin/chromium.
# Usage: bench/studio_browser.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
runs="${1:-3}"
cargo build --release -q -p fieldtex-cli
metrics=()
for i in $(seq "$runs"); do
  out="$(node tools/studio-browser-test/run.js)"
  echo "run $i:"
  echo "$out" | grep 'LATENCY' | sed 's/^.*\] /  /'
  metrics+=("$(echo "$out" | grep '^METRICS ' | sed 's/^METRICS //')")
done
printf '%s\n' "${metrics[@]}" | node -e '
const rows = require("fs").readFileSync(0, "utf8").trim().split("\n").map((l) => JSON.parse(l));
const med = (xs) => { const s = xs.filter((x) => x !== null).sort((a, b) => a - b); return s.length ? s[Math.floor((s.length - 1) / 2)] : NaN; };
const targets = { drag_median_ms: 50, texture_first_ms: 300, texture_full_ms: 1500 };
for (const k of Object.keys(rows[0])) {
  const t = targets[k] ? ` (target ${targets[k]})` : "";
  console.log(`median over ${rows.length} runs: ${k} ${med(rows.map((r) => r[k])).toFixed(1)}${t}`);
}'
uptime
