#!/usr/bin/env bash
# Texture transfer (paper B, issue 14): fidelity on a known answer and speed.
#
# 1. Fidelity: a source whose colour is a known function of geometry (accessibility,
#    height, solid-angle curvature + noise) on one mesh, transferred to other meshes;
#    Pearson r of luma against the same function on the target, for the default
#    (CCA + multiscale matching), the three --match settings and the PCA ablation.
# 2. Speed: `fieldtex transfer` end to end on a real textured source onto a target with
#    512K samples, both engines, 3 runs each, median wall time and per-stage medians
#    from report.json, and the ratio non-parametric / parametric.
# 3. With --mask-below H: the fidelity run again with the source's texels below
#    normalised height H masked (an incomplete source, paper B Fig. 8).
#
# Usage: bench/transfer_bench.sh [--samples N] [--speed-samples N] [--runs 3]
#        [--skip-fidelity] [--skip-speed] [--mask-below H]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
samples=200000
speed_samples=512000
runs=3
fidelity=1
speed=1
mask_below=
while [ $# -gt 0 ]; do
  case "$1" in
    --samples) samples="$2"; shift 2 ;;
    --speed-samples) speed_samples="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --skip-fidelity) fidelity=0; shift ;;
    --skip-speed) speed=0; shift ;;
    --mask-below) mask_below="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
# Two commands: `--example` would restrict a combined build to examples only.
cargo build --release -p fieldtex-cli
cargo build --release -p fieldtex --example transfer_fidelity --example bench_descriptors
data=../shared/data
out=out/transfer-bench
mkdir -p "$out"
if [ "$fidelity" = 1 ]; then
  echo "== fidelity (samples=$samples)"
  target/release/examples/transfer_fidelity "$out/fidelity" "$data/meshes/stanford-bunny.obj" \
    "$data/meshes/armadillo.obj" "$data/meshes/fertility.obj" --samples "$samples" --with-weighted \
    | tee "$out/fidelity.txt"
  if [ -n "$mask_below" ]; then
    echo "== fidelity, source masked below height $mask_below (parametric)"
    target/release/examples/transfer_fidelity "$out/fidelity-masked" "$data/meshes/stanford-bunny.obj" \
      "$data/meshes/armadillo.obj" "$data/meshes/fertility.obj" --samples "$samples" \
      --engines parametric --mask-below "$mask_below" | tee "$out/fidelity-masked.txt"
  fi
fi
if [ "$speed" = 1 ]; then
  echo "== descriptors alone (armadillo, $speed_samples samples, $runs runs), solid-angle accuracy, sample spacing"
  /usr/bin/time -f "  %e s wall %U s user %S s sys" target/release/examples/bench_descriptors \
    "$data/meshes/armadillo.obj" --samples "$speed_samples" --runs "$runs"
  for engine in parametric nonparametric; do
    echo "== speed ($engine): blub -> armadillo, $speed_samples samples, $runs runs"
    for i in $(seq 1 "$runs"); do
      /usr/bin/time -f "  run $i: %e s wall %U s user %S s sys" \
        target/release/fieldtex transfer --source "$data/textured/blub/blub.obj" \
        --target "$data/meshes/armadillo.obj" --samples "$speed_samples" --engine "$engine" \
        --out "$out/speed-$engine-$i" --quiet
      uptime
    done
  done
  python3 - "$out" "$runs" <<'PY'
import json, sys, statistics
out, runs = sys.argv[1], int(sys.argv[2])
med = {}
for engine in ["parametric", "nonparametric"]:
    reps = [json.load(open(f"{out}/speed-{engine}-{i}/report.json")) for i in range(1, runs + 1)]
    stages = {}
    for r in reps:
        for s, ms in r["timings_ms"]:
            stages.setdefault(s, []).append(ms / 1e3)
    total = [sum(ms for _, ms in r["timings_ms"]) / 1e3 for r in reps]
    med[engine] = statistics.median(total)
    print(f"BENCH transfer_blub_armadillo engine={engine} samples={reps[0]['metrics']['samples']['target']} median_total_s={med[engine]:.1f} runs={[round(t, 1) for t in total]}")
    for s, v in stages.items():
        print(f"  {s:<20} {statistics.median(v):8.2f} s")
    desc = [sum(ms for s, ms in r["timings_ms"] if s == "target_descriptors") / 1e3 for r in reps]
    print(f"  target descriptors median {statistics.median(desc):.2f} s (target < 20 s)")
print(f"ratio nonparametric / parametric (median end to end): {med['nonparametric'] / med['parametric']:.2f}"
      " (targets: parametric < 30 s, non-parametric < 180 s)")
PY
fi
