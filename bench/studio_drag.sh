#!/usr/bin/env bash
# Latency of the studio's interactive loop over loopback HTTP (singularity drag, stroke
# drag, coarse and full texture). Prints medians. Usage: bench/studio_drag.sh [EXEMPLAR_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q -p fieldtex-studio --example bench_studio_drag
exec target/release/examples/bench_studio_drag "${1:-../shared/data/exemplars}"
