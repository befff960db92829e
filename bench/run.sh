#!/usr/bin/env bash
# One command for all benchmarks: builds the Rust bench binaries, installs and runs the
# peers (libigl, CHOLMOD, xatlas) in a venv, and prints ours vs peers with ratios.
# Results: bench/results/latest.json (commit it as a baseline when it matters).
# The atlas size sweep (issue 17) builds atlases of meshes from 0.7K to 388K triangles
# (shared meshes, and bunny/horse refined by midpoint subdivision) with bench_atlas and
# with xatlas on the same OBJ files, and prints time ratios, chart counts and packing.
# Usage: bench/run.sh [--quick] [--no-peers] [--atlas-sweep-only]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
mkdir -p bench/results
log="$(mktemp)"
quick=""; peers=1; sweep_only=0
for a in "$@"; do
  case "$a" in
    --quick) quick="--quick" ;;
    --no-peers) peers=0 ;;
    --atlas-sweep-only) sweep_only=1 ;;
  esac
done
cargo build --release --examples -p fieldtex -p fieldtex-linalg -p fieldtex-io -p fieldtex-mesh \
  -p fieldtex-param -p fieldtex-synth -p fieldtex-fields -p fieldtex-eval
ex=target/release/examples
run() { echo "## $*" >&2; "$@" | tee -a "$log"; }
if [ "$sweep_only" = 0 ]; then
  # Geometry first: its procedural-torus cotan line is superseded by the horse one below.
  run "$ex/bench_geometry"
  run "$ex/bench_foundation" $quick
  for b in bench_linalg bench_io bench_synth bench_fields bench_eval; do
    [ -x "$ex/$b" ] && run "$ex/$b"
  done
  if [ "$peers" = 1 ]; then
    bench/setup_peers.sh
    run bench/.venv/bin/python bench/peers.py $quick
  fi
fi
# Atlas size sweep: the same OBJ files for us and for xatlas.
data=../shared/data
sweep="$(mktemp -d)"
trap 'rm -rf "$sweep"' EXIT
specs=()
for entry in avocado:textured/avocado/avocado.obj:0 spot:textured/spot/spot_triangulated.obj:0 \
    fandisk:meshes/fandisk.obj:0 armadillo:meshes/armadillo.obj:0 bunny:meshes/stanford-bunny.obj:0 \
    horse:meshes/horse.ply:0 bunny_x4:meshes/stanford-bunny.obj:1 horse_x4:meshes/horse.ply:1; do
  IFS=: read -r name file levels <<<"$entry"
  "$ex/refine_mesh" "$data/$file" "$sweep/$name.obj" "$levels" >/dev/null
  specs+=("$name=$sweep/$name.obj")
done
for spec in "${specs[@]}"; do
  name=${spec%%=*}; file=${spec#*=}
  runs=3; [ "$(grep -c '^f ' "$file")" -gt 50000 ] && runs=1
  [ -n "$quick" ] && runs=1
  run "$ex/bench_atlas" "$file" 1024 4 "$runs" --atlas-only --name "sw_$name"
done
if [ "$peers" = 1 ]; then
  [ "$sweep_only" = 1 ] && bench/setup_peers.sh
  run bench/.venv/bin/python bench/peers.py $quick --atlas-sweep "${specs[@]/#/sw_}"
fi
python3 bench/compare.py bench/results/latest.json < "$log"
rm -f "$log"
