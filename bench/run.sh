#!/usr/bin/env bash
# One command for all benchmarks: builds the Rust bench binaries, installs and runs the
# peers (libigl, CHOLMOD, xatlas) in a venv, and prints ours vs peers with ratios.
# Results: bench/results/latest.json (commit it as a baseline when it matters).
# Usage: bench/run.sh [--quick] [--no-peers] [--atlas-sweep-only] [--only BENCH_BINARY]
#                     [--base REV | --base-examples DIR]
#
# Same-run regression check: with `--base REV` the tree at REV is checked out as a git
# worktree in bench/.base and built there with its own target dir (bench/.base/target,
# a full release build: minutes, several GB); with `--base-examples DIR` prebuilt base
# bench binaries are used instead. Each bench binary then runs base and new in turn
# (base, new, base, new: the same machine state for both), and bench/regression.py
# prints every line's new/base ratio, flagging lines more than 10 % worse.
#
# The atlas size sweep (issue 17) builds atlases of meshes from 0.7K to 388K triangles
# (shared meshes, and bunny/horse refined by midpoint subdivision) with bench_atlas and
# with xatlas on the same OBJ files, and prints time ratios, chart counts and packing.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
mkdir -p bench/results
log="$(mktemp)"
quick=""; peers=1; sweep_only=0; only=""; base_rev=""; base_ex=""
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick="--quick" ;;
    --no-peers) peers=0 ;;
    --atlas-sweep-only) sweep_only=1 ;;
    --only) only="$2"; shift ;;
    --base) base_rev="$2"; shift ;;
    --base-examples) base_ex="$2"; shift ;;
    *) echo "unknown argument $1" >&2; exit 2 ;;
  esac
  shift
done
benches="bench_geometry bench_foundation bench_linalg bench_io bench_synth bench_fields bench_eval"
crates="-p fieldtex -p fieldtex-linalg -p fieldtex-io -p fieldtex-mesh -p fieldtex-param -p fieldtex-synth -p fieldtex-fields -p fieldtex-eval"
if [ -n "$only" ]; then
  benches="$only"
  src=$(ls crates/*/examples/"$only".rs 2>/dev/null | head -1)
  [ -n "$src" ] || { echo "no example $only.rs under crates/*/examples" >&2; exit 2; }
  crates="-p $(basename "$(dirname "$(dirname "$src")")") --example $only"
  peers=0
fi
# shellcheck disable=SC2086
cargo build --release $([ -z "$only" ] && echo --examples) $crates
ex=target/release/examples
base_dir=.
if [ -n "$base_rev" ]; then
  base_dir=bench/.base
  if [ ! -d bench/.base ]; then
    git worktree add --detach bench/.base "$base_rev"
  else
    git -C bench/.base checkout --detach "$base_rev"
  fi
  # Data sits in shared/ beside the repository: give the base tree the same neighbour.
  [ -e bench/shared ] || ln -s "$(cd "$root/.." && pwd)/shared" bench/shared
  # shellcheck disable=SC2086
  (cd bench/.base && CARGO_TARGET_DIR="$root/bench/.base/target" \
    cargo build --release $([ -z "$only" ] && echo --examples) $crates)
  base_ex="$root/bench/.base/target/release/examples"
fi
args_of() { [ "$1" = bench_foundation ] && echo "$quick"; true; }
if [ -n "$base_ex" ]; then
  base_log="$(mktemp)"
  for b in $benches; do
    [ -x "$ex/$b" ] && [ -x "$base_ex/$b" ] || continue
    for _ in 1 2; do
      echo "## base $b" >&2; (cd "$base_dir" && "$base_ex/$b" $(args_of "$b")) | tee -a "$base_log"
      echo "## new $b" >&2; "$ex/$b" $(args_of "$b") | tee -a "$log"
    done
  done
  python3 bench/regression.py "$base_log" "$log"
  rm -f "$base_log" "$log"
  exit 0
fi
run() { echo "## $*" >&2; "$@" | tee -a "$log"; }
if [ "$sweep_only" = 0 ]; then
  # Geometry first: its procedural-torus cotan line is superseded by the horse one below.
  for b in $benches; do
    # shellcheck disable=SC2046
    [ -x "$ex/$b" ] && run "$ex/$b" $(args_of "$b")
  done
  if [ "$peers" = 1 ]; then
    bench/setup_peers.sh
    run bench/.venv/bin/python bench/peers.py $quick
  fi
fi
if [ -n "$only" ]; then
  python3 bench/compare.py bench/results/latest.json < "$log"
  rm -f "$log"
  exit 0
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
  echo "# load before sw_$name: $(cut -d' ' -f1-3 /proc/loadavg)"
  run "$ex/bench_atlas" "$file" 1024 4 "$runs" --atlas-only --name "sw_$name"
done
if [ "$peers" = 1 ]; then
  [ "$sweep_only" = 1 ] && bench/setup_peers.sh
  echo "# load before the xatlas sweep: $(cut -d' ' -f1-3 /proc/loadavg)"
  run bench/.venv/bin/python bench/peers.py $quick --atlas-sweep "${specs[@]/#/sw_}"
fi
python3 bench/compare.py bench/results/latest.json < "$log"
rm -f "$log"
