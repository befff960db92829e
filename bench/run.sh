#!/usr/bin/env bash
# One command for all benchmarks: builds the Rust bench binaries, installs and runs the
# peers (libigl, CHOLMOD, xatlas) in a venv, and prints ours vs peers with ratios.
# Results: bench/results/latest.json (commit it as a baseline when it matters).
# Usage: bench/run.sh [--quick] [--no-peers]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
mkdir -p bench/results
log="$(mktemp)"
quick=""; peers=1
for a in "$@"; do
  case "$a" in
    --quick) quick="--quick" ;;
    --no-peers) peers=0 ;;
  esac
done
cargo build --release --examples -p fieldtex -p fieldtex-linalg -p fieldtex-io -p fieldtex-mesh \
  -p fieldtex-param -p fieldtex-synth -p fieldtex-fields -p fieldtex-eval
ex=target/release/examples
run() { echo "## $*" >&2; "$@" | tee -a "$log"; }
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
python3 bench/compare.py bench/results/latest.json < "$log"
rm -f "$log"
