#!/usr/bin/env bash
# Speed of `fieldtex solid` (issue 15): the bunny's surface shell at virtual N³
# (default 256; target < 60 s on 2 cores), then a new axis-aligned cut through the
# middle (target < 1 s after the shell), with voxels computed and voxels per second
# from report.json, and user+system CPU time (the machine may be shared).
# Usage: bench/solid_bench.sh [--resolution 256] [--exemplar NAME] [--no-sketch]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
res=256
exemplar=woodgrain_Wood022
sketch=(--sketch docs/examples/bunny-sketch.json)
tag=sketch
while [ $# -gt 0 ]; do
  case "$1" in
    --resolution) res="$2"; shift 2 ;;
    --exemplar) exemplar="$2"; shift 2 ;;
    --no-sketch) sketch=(); tag=constant; shift ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
cargo build --release -p fieldtex-cli
out="out/solid-bench/bunny-$res-$exemplar-$tag"
# A z cut through the middle voxel plane: z = origin_z + k·spacing, computed from the
# grid the run reports; a first run without the cut gives the grid.
mesh=../shared/data/meshes/stanford-bunny.obj
ex="../shared/data/exemplars/$exemplar.png"
python3 - "$mesh" "$res" > /tmp/solid-bench-cut.txt <<'PY'
import sys, math
vs = [list(map(float, l.split()[1:4])) for l in open(sys.argv[1]) if l.startswith('v ')]
res = int(sys.argv[2])
lo = [min(v[a] for v in vs) for a in range(3)]; hi = [max(v[a] for v in vs) for a in range(3)]
ext = [hi[a] - lo[a] for a in range(3)]; s = max(ext) / res
n = [max(1, math.ceil(ext[a] / s)) for a in range(3)]
o = [0.5 * (lo[a] + hi[a]) - 0.5 * (n[a] - 1) * s for a in range(3)]
k = n[2] // 2
print(f"{0.5*(lo[0]+hi[0])},{0.5*(lo[1]+hi[1])},{o[2] + k * s!r},0,0,1")
PY
cut=$(cat /tmp/solid-bench-cut.txt)
/usr/bin/time -f "cpu_user_s=%U cpu_sys_s=%S wall_s=%e max_rss_kb=%M" \
  target/release/fieldtex solid --mesh "$mesh" "${sketch[@]}" --exemplar "$ex" \
  --resolution "$res" --cut="$cut" --out "$out" --quiet 2> /tmp/solid-bench-time.txt
python3 - "$out/report.json" "$(cat /tmp/solid-bench-time.txt | tail -1)" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); m = r["metrics"]
t = dict(r["timings_ms"])
sh = m["shell"]; cut = m["cuts"][0]
print(f"BENCH solid_bunny_{m['grid']['sizes']} {sys.argv[2]}")
for stage, ms in r["timings_ms"]:
    print(f"  {stage:<22} {ms / 1e3:8.2f} s")
print(f"  shell: requested {sh['requested']} voxels, computed {sh['computed_finest']} finest "
      f"({100*m['shell_share_of_full_volume']:.1f} % of the full volume), {sh['computed_all_levels']} all levels, "
      f"{sh['corrections']} corrections, {sh['seconds']:.1f} s synthesis, {m['shell_voxels_per_second']:.0f} voxels/s")
print(f"  cut {cut['image_size']}: {cut['image_seconds']:.2f} s for the image, {cut['image_voxels_requested']} voxels requested, "
      f"{cut['image_voxels_computed_finest']} finest computed, {cut['image_voxels_per_second']:.0f} voxels/s")
if "frame_field" in m:
    ff = m["frame_field"]
    print(f"  frame field: grid {ff['grid']['dims']}, alignment error max {ff['alignment_error_max_deg']:.3f}° "
          f"mean {ff['alignment_error_mean_deg']:.4f}°, edits {m['frame_field_edit_ms']}")
PY
