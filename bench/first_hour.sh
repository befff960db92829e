#!/usr/bin/env bash
# First-hour timings (issue 17): the demo, orient 512² with approximate / exact / no
# metrics, eval on a 1024² image. Prints the median wall time of N runs (default 3) and
# the CPU time of the last run. Usage: bench/first_hour.sh [N]
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-3}
cargo build --release -q -p fieldtex-cli
F=target/release/fieldtex
E=../shared/data/exemplars/stripes_Fabric071.png
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
bench() {
  local name=$1; shift
  local walls=() cpu=""
  for _ in $(seq "$N"); do
    local out
    /usr/bin/time -f "%e %U %S" -o "$T/time" "$@" >/dev/null 2>&1
    out=$(tail -1 "$T/time")
    walls+=("$(echo "$out" | cut -d' ' -f1)")
    cpu=$(echo "$out" | awk '{print $2 + $3}')
  done
  printf '%-34s median %6.2f s wall   %6.2f CPU-s (last run)\n' "$name" \
    "$(printf '%s\n' "${walls[@]}" | median)" "$cpu"
}
bench "demo (defaults)" $F demo --out "$T/demo" --quiet
bench "orient 512² --no-metrics" $F orient --preset whorl --exemplar $E --out "$T/o" --quiet --no-metrics
bench "orient 512² (approximate metrics)" $F orient --preset whorl --exemplar $E --out "$T/o" --quiet
bench "orient 512² --exact-metrics" $F orient --preset whorl --exemplar $E --out "$T/o" --quiet --exact-metrics
$F orient --preset whorl --exemplar $E --size 1024 --out "$T/o1024" --quiet --no-metrics
bench "eval 1024² (approximate)" $F eval "$T/o1024/texture.png" --exemplar $E --field "$T/o1024/field.npy" --quiet
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
