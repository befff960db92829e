#!/usr/bin/env bash
# Texture transfer (paper B, issue 14): fidelity on a known answer and speed.
#
# 1. Fidelity: a source whose colour is a known function of geometry (accessibility,
#    height, solid-angle curvature + noise) on one mesh, transferred to other meshes;
#    Pearson r of luma against the same function on the target, for the default
#    (CCA + multiscale matching), the three --match settings and the PCA ablation.
# 2. Speed: `fieldtex transfer` end to end on a real textured source onto a target with
#    512K samples, 3 runs, median wall time and per-stage medians from report.json.
#
# Usage: bench/transfer_bench.sh [--samples N] [--runs 3] [--skip-fidelity] [--skip-speed]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
samples=200000
speed_samples=512000
runs=3
fidelity=1
speed=1
while [ $# -gt 0 ]; do
  case "$1" in
    --samples) samples="$2"; shift 2 ;;
    --speed-samples) speed_samples="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --skip-fidelity) fidelity=0; shift ;;
    --skip-speed) speed=0; shift ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
cargo build --release -p fieldtex-cli -p fieldtex --example transfer_fidelity
data=../shared/data
out=out/transfer-bench
mkdir -p "$out"
if [ "$fidelity" = 1 ]; then
  echo "== fidelity (samples=$samples)"
  target/release/examples/transfer_fidelity "$out/fidelity" "$data/meshes/stanford-bunny.obj" \
    "$data/meshes/armadillo.obj" "$data/meshes/fertility.obj" --samples "$samples" | tee "$out/fidelity.txt"
fi
if [ "$speed" = 1 ]; then
  echo "== speed: blub -> armadillo, $speed_samples samples, $runs runs"
  for i in $(seq 1 "$runs"); do
    target/release/fieldtex transfer --source "$data/textured/blub/blub.obj" \
      --target "$data/meshes/armadillo.obj" --samples "$speed_samples" \
      --out "$out/speed-$i" --quiet
  done
  python3 - "$out" "$runs" <<'PY'
import json, sys, statistics
out, runs = sys.argv[1], int(sys.argv[2])
reps = [json.load(open(f"{out}/speed-{i}/report.json")) for i in range(1, runs + 1)]
stages = {}
for r in reps:
    for s, ms in r["timings_ms"]:
        stages.setdefault(s, []).append(ms / 1e3)
total = [sum(ms for _, ms in r["timings_ms"]) / 1e3 for r in reps]
print(f"BENCH transfer_blub_armadillo samples={reps[0]['metrics']['samples']['target']} median_total_s={statistics.median(total):.1f} runs={total}")
for s, v in stages.items():
    print(f"  {s:<20} {statistics.median(v):8.2f} s")
desc = [sum(ms for s, ms in r["timings_ms"] if s == "target_descriptors") / 1e3 for r in reps]
print(f"  target descriptors median {statistics.median(desc):.2f} s (target < 20 s)")
PY
fi
