#!/usr/bin/env bash
# `fieldtex conformal` (issue 13, paper C) on the shared meshes: wall time, topology,
# zero points, flips, angle/area distortion, feature-size CV with and without
# multi-scale, seam length against `fieldtex atlas`, colour jump ratio, mass-spring.
# Every timed run also records CPU time (user + sys, GNU time) and the load average, so
# numbers taken on a busy machine can be judged.
# Usage: bench/conformal_bench.sh [--runs N] [--exemplar NAME] [--meshes "bunny torus ..."]
#   (a mesh is a name in ../shared/data/meshes or a path under ../shared/data without
#   its extension, e.g. textured/painted_wooden_stool/painted_wooden_stool_1k)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
runs=1
exemplar=pebbles_Rocks002
meshes="stanford-bunny torus rocker-arm fertility demosthenes-bust-open"
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs="$2"; shift 2 ;;
    --exemplar) exemplar="$2"; shift 2 ;;
    --meshes) meshes="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
cargo build --release -p fieldtex-cli
bin=target/release/fieldtex
ex="../shared/data/exemplars/$exemplar.png"
out=out/conformal-bench
mkdir -p "$out"
for name in $meshes; do
  # A shared mesh by name, or a path under ../shared/data without its extension
  # (e.g. textured/spot/spot_triangulated).
  f=""
  for base in "../shared/data/meshes/$name" "../shared/data/$name"; do
    for ext in obj ply stl gltf glb; do
      if [ -z "$f" ] && [ -f "$base.$ext" ]; then f="$base.$ext"; fi
    done
  done
  [ -n "$f" ] || { echo "conformal_bench: no mesh $name" >&2; exit 2; }
  m=$(basename "$name")
  walls=()
  for r in $(seq 1 "$runs"); do
    /usr/bin/time -f '%e %U %S' -o "$out/$m.time" \
      $bin conformal --mesh "$f" --exemplar "$ex" --out "$out/$m" --quiet
    read -r wall user sys < "$out/$m.time"
    walls+=("$wall")
    echo "   run $r: $wall s wall, $(python3 -c "print(round($user + $sys, 2))") s CPU, load $(cut -d' ' -f1-3 /proc/loadavg)"
  done
  $bin conformal --mesh "$f" --exemplar "$ex" --out "$out/$m-nomulti" --no-multiscale --quiet
  $bin atlas "$f" --out "$out/$m-atlas" --quiet
  if [ "$m" = stanford-bunny ]; then
    $bin conformal --mesh "$f" --exemplar "$ex" --out "$out/$m-qi" --quasi-isometric --quiet
  fi
  python3 bench/conformal_summary.py "$m" "$out" "${walls[@]}"
done
