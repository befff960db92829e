#!/usr/bin/env bash
# Quality of `fieldtex solid` slices (issue 15): a unit box with a bent sketch (quarter
# arcs in the xy plane, on the top face and on an interior plane) against the same run
# with a constant field. For each exemplar: coherence and colour sliced-Wasserstein of
# the middle z slice (cut-1.png, fully inside the box) against the exemplar, and the
# orientation error of the slice against the sketched field (cut-1-field.npy: the local
# x axis per pixel) from `fieldtex eval`.
# Usage: bench/solid_quality.sh [--resolution 96] [exemplar names…]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
res=96
names=()
while [ $# -gt 0 ]; do
  case "$1" in
    --resolution) res="$2"; shift 2 ;;
    *) names+=("$1"); shift ;;
  esac
done
[ ${#names[@]} -gt 0 ] || names=(stripes_Fabric071 woodgrain_Wood022)
cargo build --release -p fieldtex-cli
dir=out/solid-quality
mkdir -p "$dir"
python3 - "$dir" <<'PY'
import sys, math, json
d = sys.argv[1]
v = [(x, y, z) for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
f = [(1,3,4,2),(5,6,8,7),(1,2,6,5),(3,7,8,4),(1,5,7,3),(2,4,8,6)]
with open(f"{d}/box.obj", "w") as o:
    for p in v: o.write("v %g %g %g\n" % p)
    for q in f: o.write("f %d %d %d\nf %d %d %d\n" % (q[0], q[1], q[2], q[0], q[2], q[3]))
def arc(r, z, n=12):
    return [[-0.5 + r * math.cos(t), -0.5 + r * math.sin(t), z] for t in [i / n * math.pi / 2 for i in range(n + 1)]]
s = {"curves": [
    {"points": arc(0.7, 0.5), "axis": "x"},
    {"points": arc(0.45, 0.0), "plane": {"point": [0, 0, 0], "normal": [0, 0, 1]}, "axis": "x"},
    {"points": arc(0.95, 0.0), "plane": {"point": [0, 0, 0], "normal": [0, 0, 1]}, "axis": "x"},
]}
json.dump(s, open(f"{d}/bent-sketch.json", "w"))
PY
# Middle z plane of voxel centres: extent 1, N voxels, spacing 1/N, origin −0.5 + 0.5/N.
k=$((res / 2))
z=$(python3 -c "print(-0.5 + 0.5 / $res + $k / $res)")
for name in "${names[@]}"; do
  ex="../shared/data/exemplars/$name.png"
  for tag in bent constant; do
    sk=(); [ "$tag" = bent ] && sk=(--sketch "$dir/bent-sketch.json")
    out="$dir/$name-$tag"
    target/release/fieldtex solid --mesh "$dir/box.obj" "${sk[@]}" --exemplar "$ex" \
      --resolution "$res" --atlas-size 256 --cut="0,0,$z,0,0,1" --keep --out "$out" --quiet
    # Both runs are measured in their own field's frame (cut-1-field.npy: the sketched
    # field, or the constant x axis): guided coherence compares the exemplar with the
    # slice's neighbourhoods taken along the field's planes (issue 15's "slices along
    # the field's planes"); plain coherence compares axis-aligned patches.
    field="$out/cut-1-field.npy"
    target/release/fieldtex eval "$out/cut-1.png" --exemplar "$ex" --field "$field" --out "$out/eval.json" > /dev/null
  done
  python3 - "$dir/$name-bent/eval.json" "$dir/$name-constant/eval.json" "$name" <<'PY'
import json, sys
b, c = (json.load(open(p)) for p in sys.argv[1:3])
def g(m, *keys):
    for k in keys:
        if m is None: return None
        m = m.get(k) if isinstance(m, dict) else None
    return m
cb, cc = g(b, "coherence", "mean"), g(c, "coherence", "mean")
sb, sc = g(b, "color_sliced_wasserstein", "distance"), g(c, "color_sliced_wasserstein", "distance")
ob, oc = g(b, "orientation_error", "mean_error_deg"), g(c, "orientation_error", "mean_error_deg")
gb, gc = g(b, "guided_coherence", "mean"), g(c, "guided_coherence", "mean")
print(f"QUALITY {sys.argv[3]}: guided coherence (along the field) bent {gb} constant {gc} ratio {gb / gc if gb and gc else None}")
print(f"  plain coherence (axis-aligned patches) bent {cb} constant {cc} ratio {cb / cc if cb and cc else None}")
print(f"  colour SW bent {sb} constant {sc} ratio {sb / sc if sb and sc else None}")
print(f"  orientation error vs the field: bent {ob}°, constant {oc}°")
PY
done
