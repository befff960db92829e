#!/usr/bin/env bash
# Quality and speed probe of `fieldtex align` on photo-size exemplars (issue 16/17):
# per run the wall time, the per-stage timings, the contrast ratio (std of baked-texel
# luminance / the exemplar's), the gradient ratio (mean luminance-gradient magnitude,
# per exemplar pixel), the surface orientation error and the feature coverage.
# 512² exemplars: the two real 512² photos of the data set, and 124² thumbnails enlarged
# 4× (their structures then span as many pixels as in a 512² photo).
# Contrast and gradient ratios are measured on the model's texture by
# `examples/texture_contrast` (texels of the empty-texel grey left out), so builds that do
# not report them (--bin an older binary) are measured the same way.
# Usage: bench/align_quality.sh [--size 1024] [--threads 2] [--meshes "fandisk bunny"]
#        [--exemplars "bricks512 gravel512 stonewall512 bricksgray512 stripes"]
#        [--bin PATH] [--tag NAME]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
size=1024
threads=2
bin=target/release/fieldtex
tag=new
meshes="fandisk stanford-bunny koala-lowres"
exemplars="bricks512 gravel512 stonewall512 bricksgray512 stripes"
while [ $# -gt 0 ]; do
  case "$1" in
    --size) size="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --meshes) meshes="$2"; shift 2 ;;
    --exemplars) exemplars="$2"; shift 2 ;;
    --bin) bin="$2"; shift 2 ;;
    --tag) tag="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
data=../shared/data
cargo build --release -q -p fieldtex-cli
cargo build --release -q -p fieldtex-texopt --example resize_exemplar
cargo build --release -q -p fieldtex --example texture_contrast
out=out/align-quality
mkdir -p "$out/exemplars"
exemplar_path() {
  case "$1" in
    bricks512) src=bricks_Bricks012 ;;
    gravel512) src=gravel_Gravel005 ;;
    stonewall512) src=stone-wall_Rocks001 ;;
    bricksgray512) echo "$data/exemplars/bricks-gray-large_MaterialX-brick_base_gray.png"; return ;;
    wood512) echo "$data/exemplars/woodgrain-large_MaterialX-wood_color.png"; return ;;
    stripes) echo "$data/exemplars/stripes_Fabric071.png"; return ;;
    *) echo "$data/exemplars/$1.png"; return ;;
  esac
  local p="$out/exemplars/$1.png"
  [ -f "$p" ] || target/release/examples/resize_exemplar "$data/exemplars/$src.png" 512 "$p"
  echo "$p"
}
echo "binary: $bin ($tag), atlas $size, $threads threads"
printf "%-14s %-14s %7s %7s %8s %8s %8s %8s %9s\n" mesh exemplar wall_s cpu_s contrast gradient orient_deg coverage metrics_s
for m in $meshes; do
  mesh="$data/meshes/$m.obj"
  for e in $exemplars; do
    ex="$(exemplar_path "$e")"
    dir="$out/$tag-$m-$e"
    mkdir -p "$dir"
    /usr/bin/time -f '%e %U %S' -o "$dir.time" "$bin" align --mesh "$mesh" --exemplar "$ex" \
      --size "$size" --threads "$threads" --out "$dir" --quiet
    ratios="$(target/release/examples/texture_contrast "$dir/model.glb" "$ex" 1)"
    python3 - "$dir.time" "$dir/report.json" "$m" "$e" "$ratios" "$(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || true)" <<'PY'
import json, sys
times, path, m, e = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
wall, user, sys_s = (float(v) for v in open(times).read().split()[-3:])
cr, gr = (float(v) for v in sys.argv[5].split())
r = json.load(open(path))
mt = r["metrics"]
c = {"contrast_ratio": cr, "gradient_ratio": gr}
t = dict((k, v) for k, v in r["timings_ms"])
metrics = sum(v for k, v in r["timings_ms"] if k.startswith("metrics")) / 1e3
print(f"{m:<14} {e:<14} {wall:7.1f} {user + sys_s:7.1f} {c.get('contrast_ratio', float('nan')):8.3f} "
      f"{c.get('gradient_ratio', float('nan')):8.3f} "
      f"{mt['orientation_error']['surface']['mean_deg']:8.2f} "
      f"{mt['feature_coverage']['fraction']:8.3f} {metrics:9.2f}")
print(f"    load average (1, 5, 15 min) after the run: {sys.argv[6]}")
print("    stages: " + " ".join(f"{k}={v / 1e3:.2f}" for k, v in r["timings_ms"] if v >= 100))
PY
  done
done
