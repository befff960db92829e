#!/usr/bin/env bash
# A/B of the parallel engine's wall time after the lattice generalisation: runs
# `orient --size N` alternately with two binaries (base, new, base, new, …) and prints
# the median of the synthesis time each report.json records, and the ratio new/base.
# Usage: bench/core_synth_ab.sh BASE_BIN NEW_BIN [RUNS=5] [SIZE=512]
set -euo pipefail
base=${1:?base binary}; new=${2:?new binary}; runs=${3:-5}; size=${4:-512}
e=$(cd "$(dirname "$0")/.." && pwd)/../shared/data/exemplars/stripes_Fabric071.png
tmp=$(mktemp -d)
for i in $(seq "$runs"); do
  for which in base new; do
    bin=$base; [ "$which" = new ] && bin=$new
    "$bin" orient --preset whorl --exemplar "$e" --size "$size" --seed "$i" --out "$tmp/$which-$i" --quiet
  done
done
python3 - "$tmp" "$runs" <<'PY'
import json, statistics, sys, glob
tmp, runs = sys.argv[1], int(sys.argv[2])
def synth_ms(path):
    r = json.load(open(path))
    t = dict(r["timings_ms"])
    return t["synthesis"], ["synthesis"]
med = {}
for which in ("base", "new"):
    vals = [synth_ms(f"{tmp}/{which}-{i}/report.json") for i in range(1, runs + 1)]
    med[which] = statistics.median(v for v, _ in vals)
    print(f"{which}: synthesis median {med[which]:.1f} ms over {runs} runs (keys {vals[0][1]})")
print(f"ratio new/base {med['new'] / med['base']:.3f}")
PY
rm -rf "$tmp"
