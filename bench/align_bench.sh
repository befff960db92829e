#!/usr/bin/env bash
# Speed of `fieldtex align` on the horse refined to ~388K triangles (issue: feature-aligned
# shape texturing, target < 2 min on 2 cores), with the per-stage timings of report.json.
# Usage: bench/align_bench.sh [--size 1024] [--exemplar NAME]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
size=1024
exemplar=stripes_Fabric071
while [ $# -gt 0 ]; do
  case "$1" in
    --size) size="$2"; shift 2 ;;
    --exemplar) exemplar="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
cargo build --release -p fieldtex-cli -p fieldtex --example refine_mesh
mkdir -p out/align-bench
horse=out/align-bench/horse-388k.obj
[ -f "$horse" ] || target/release/examples/refine_mesh ../shared/data/meshes/horse.ply "$horse" 1
t0=$(date +%s.%N)
target/release/fieldtex align --mesh "$horse" --exemplar "../shared/data/exemplars/$exemplar.png" \
  --size "$size" --out out/align-bench/horse --quiet
t1=$(date +%s.%N)
python3 - "$t0" "$t1" out/align-bench/horse/report.json <<'PY'
import json, sys
t0, t1, path = float(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
r = json.load(open(path))
print(f"BENCH align_horse_388k wall_s={t1 - t0:.1f}")
for stage, ms in r["timings_ms"]:
    print(f"  {stage:<20} {ms / 1e3:8.2f} s")
m = r["metrics"]
print("  carriers", m["texopt"]["carriers"], "field singularities", m["field"]["singularities"])
print("  orientation error (surface, mean deg)", round(m["orientation_error"]["surface"]["mean_deg"], 2))
print("  feature coverage", round(m["feature_coverage"]["fraction"], 3))
PY
