#!/usr/bin/env bash
# Robustness sweep of the CLI as an outside tester would run it: odd meshes, odd
# images, malformed sketch files and odd option values through the newer commands
# (conformal, solid, transfer, eval --mesh, atlas, render, inspect, repair).
#
# Usage: tools/robustness_sweep.sh [BINARY] [WORK_DIR]
#   BINARY defaults to target/release/fieldtex, WORK_DIR to a fresh temporary folder.
#   ONLY=REGEX (environment) runs only the cases whose name matches, e.g. ONLY=^solid_.
# Every case runs under `timeout 60` on small inputs. A case is flagged when it
#   - panics (exit 101 or "panicked" in its output),
#   - hangs (exit 124 from timeout),
#   - exits 1 ("internal") where the case is an input error (expected exit 2),
#   - exits 0 where the input is invalid, or 2 where it is valid,
#   - prints Rust debug text (`Some(`, `Os {`, `kind:`, `Err(`, `{:?}`-style structs),
#   - leaves an input changed or a partial output folder (no report.json beside other files).
# The last line says how many cases were flagged; the exit status is 1 when any was.
set -u
BIN=${1:-target/release/fieldtex}
BIN=$(realpath "$BIN")
W=${2:-$(mktemp -d)}
mkdir -p "$W"
cd "$W" || exit 2
DATA=$(realpath "$(dirname "$0")/../../shared/data" 2>/dev/null || echo /work/shared/data)
TORUS=$DATA/meshes/torus.obj
DEF=$DATA/meshes/defects
SPOT=$DATA/textured/spot/spot_triangulated.obj
SPOT_TEX=$DATA/textured/spot/spot_texture.png
BLUB=$DATA/textured/blub/blub.obj

# ---- inputs ---------------------------------------------------------------------
python3 - <<'EOF'
import struct, zlib, json, math
def png(path, w, h, bitdepth=8, colour=2, fn=None):
    ch = {0: 1, 2: 3, 4: 2, 6: 4}[colour]
    bpc = bitdepth // 8
    raw = b""
    for y in range(h):
        raw += b"\0"
        for x in range(w):
            for c in range(ch):
                v = fn(x, y, c) if fn else ((x * 37 + y * 91 + c * 53) * 2654435761 >> 7) & 0xFFFF
                raw += (v & 0xFFFF).to_bytes(2, "big") if bpc == 2 else bytes([v & 0xFF])
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    ihdr = struct.pack(">IIBBBBB", w, h, bitdepth, colour, 0, 0, 0)
    open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
png("ex1x1.png", 1, 1)
png("ex2x2.png", 2, 2)
png("ex64.png", 64, 64)
png("ex64x8.png", 64, 8)
png("ex8x64.png", 8, 64)
png("ex16bit.png", 48, 48, 16, 2)
png("exgrey.png", 48, 48, 8, 0)
png("mask64.png", 64, 64, 8, 0, lambda x, y, c: 255 if x % 16 == 0 or y % 16 == 0 else 0)
png("exgreyalpha.png", 48, 48, 8, 4)
png("exalpha.png", 48, 48, 8, 6)
png("exflat.png", 48, 48, 8, 2, lambda x, y, c: 128)
open("empty.png", "wb").close()
open("garbage.png", "wb").write(b"\x89PNG\r\n\x1a\nthis is not a png at all")
# meshes
open("empty.obj", "w").close()
open("verts_only.obj", "w").write("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
open("one_tri.obj", "w").write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
open("degenerate.obj", "w").write("v 0 0 0\nv 0 0 0\nv 0 0 0\nv 1 1 1\nf 1 2 3\nf 1 2 4\n")
open("collinear.obj", "w").write("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 2 3 4\n")
open("nan.obj", "w").write("v 0 0 0\nv nan 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n")
open("inf.obj", "w").write("v 0 0 0\nv inf 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n")
open("huge.obj", "w").write("v 0 0 0\nv 1e38 0 0\nv 0 1e38 0\nv 0 0 1e38\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
open("tiny.obj", "w").write("v 0 0 0\nv 1e-30 0 0\nv 0 1e-30 0\nv 0 0 1e-30\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
open("badindex.obj", "w").write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n")
open("tet.obj", "w").write("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
# a tetrahedron with UVs but without a texture (transfer's texture-less source)
open("tet_uv.obj", "w").write("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\n"
    "f 1/1 3/3 2/2\nf 1/1 2/2 4/3\nf 1/1 4/3 3/2\nf 2/1 3/2 4/3\n")
# sketches (torus spans x,y in [-1.25,1.25], z in [-0.25,0.25])
on = [[1.25, 0, 0], [0, 1.25, 0]]
sk = {
 "sk_ok": {"curves": [{"points": on}]},
 "sk_empty_curves": {"curves": []},
 "sk_no_curves": {},
 "sk_one_point": {"curves": [{"points": [[1.25, 0, 0]]}]},
 "sk_zero_points": {"curves": [{"points": []}]},
 "sk_same_points": {"curves": [{"points": [[1.25, 0, 0], [1.25, 0, 0]]}]},
 "sk_huge_weight": {"curves": [{"points": on, "weight": 1e300}]},
 "sk_zero_weight": {"curves": [{"points": on, "weight": 0}]},
 "sk_neg_weight": {"curves": [{"points": on, "weight": -1}]},
 "sk_unknown_axis": {"curves": [{"points": on, "axis": "w"}]},
 "sk_zero_normal": {"curves": [{"points": on, "plane": {"point": [0, 0, 0], "normal": [0, 0, 0]}}]},
 "sk_far": {"curves": [{"points": [[1e6, 0, 0], [1e6, 1, 0]]}]},
 "sk_huge": {"curves": [{"points": [[1e300, 0, 0], [0, 1e300, 0]]}]},
 "sk_unknown_key": {"curves": [{"points": on, "colour": "red"}]},
}
for k, v in sk.items():
    json.dump(v, open(k + ".json", "w"))
open("sk_nan.json", "w").write('{"curves": [{"points": [[NaN, 0, 0], [0, 1.25, 0]]}]}')
open("sk_nan_weight.json", "w").write('{"curves": [{"points": [[1.25, 0, 0], [0, 1.25, 0]], "weight": NaN}]}')
open("sk_not_json.json", "w").write("curves: nope")
open("sk_empty.json", "w").close()
EOF
cp "$TORUS" torus.obj
# A copy of blub (OBJ + MTL + texture), so that runs writing beside it stay in WORK_DIR.
mkdir -p blub && cp "$DATA"/textured/blub/* blub/
BLUB=$W/blub/blub.obj
# A folder nobody can write into: a read-only one, or (as root, who may write anywhere)
# a path under /proc, where no file can be created.
ro=$W/readonly
mkdir -p "$ro" && chmod a-w "$ro"
[ "$(id -u)" = 0 ] && ro=/proc/self/fieldtex-sweep
: > outfile

FLAGGED=0
# Checksums of the inputs made above (outputs are named o_*).
inputs_sum() {
  local f
  for f in "$W"/*; do
    case $(basename "$f") in o_*) ;; *) [ -f "$f" ] && md5sum "$f" ;; esac
  done
}
THREADS=(--threads 2)
# case NAME EXPECT ARGS… — EXPECT is 0 (valid input), 2 (input error) or "02" (either,
# as long as it is a clean exit).
case_() {
  local name=$1 want=$2
  shift 2
  [[ $name =~ ${ONLY:-.} ]] || return 0
  local out=$W/log/$name
  mkdir -p "$W/log"
  local before
  before=$(inputs_sum)
  timeout 60 "$BIN" "${THREADS[@]}" --quiet "$@" >"$out.stdout" 2>"$out.stderr"
  local rc=$?
  local why=""
  grep -q "panicked" "$out.stderr" && why="$why panic;"
  [ $rc = 101 ] && why="$why exit101;"
  [ $rc = 124 ] && why="$why hang;"
  grep -Eq 'Some\(|None\b|Os \{|kind: |Err\(|Ok\(|\w+ \{ \w+: ' "$out.stderr" && why="$why debug-text;"
  case "$want" in
    0) [ $rc = 0 ] || why="$why exit$rc (wanted 0);" ;;
    2) [ $rc = 2 ] || why="$why exit$rc (wanted 2);" ;;
    02) [ $rc = 0 ] || [ $rc = 2 ] || why="$why exit$rc (wanted 0 or 2);" ;;
  esac
  local after
  after=$(inputs_sum)
  [ "$before" = "$after" ] || why="$why input-changed;"
  for d in "$W"/o_*; do
    [ -d "$d" ] || continue
    if [ -n "$(ls -A "$d" 2>/dev/null | grep -v '^\.')" ] && [ ! -e "$d/report.json" ]; then
      why="$why partial-output($d);"
    fi
  done
  if [ -n "$why" ]; then
    FLAGGED=$((FLAGGED + 1))
    echo "FLAG $name: rc=$rc$why"
    head -c 600 "$out.stderr" | sed 's/^/    /'
  else
    echo "ok   $name: rc=$rc $(head -c 160 "$out.stderr" | tr '\n' ' ')"
  fi
  rm -rf "$W"/o_*
}

E=ex64.png
# ---- inspect / repair / render / atlas on odd meshes -----------------------------
for m in empty verts_only one_tri degenerate collinear nan inf huge tiny badindex tet; do
  case_ inspect_$m 02 inspect $m.obj
  case_ repair_$m 02 repair $m.obj --out o_r_$m.obj
  case_ render_$m 02 render $m.obj --out o_r_$m.png --size 64
  case_ atlas_$m 02 atlas $m.obj --out o_a_$m --size 64
done
for m in "$DEF"/*; do
  b=$(basename "$m")
  case_ inspect_$b 0 inspect "$m"
  case_ repair_$b 0 repair "$m" --out o_r.obj
  case_ render_$b 0 render "$m" --out o_r.png --size 64
  case_ atlas_$b 02 atlas "$m" --out o_a --size 64
done
case_ repair_weld_nan 2 repair torus.obj --out o_r.obj --weld-epsilon NaN
case_ repair_weld_neg 2 repair torus.obj --out o_r.obj --weld-epsilon -1
case_ repair_weld_inf 2 repair torus.obj --out o_r.obj --weld-epsilon inf
case_ repair_out_input 2 repair torus.obj --out torus.obj
case_ repair_out_readonly 2 repair torus.obj --out "$ro/x.obj"
case_ repair_out_dir 2 repair torus.obj --out "$W"
case_ repair_out_ext 2 repair torus.obj --out o_r.txt
for s in 0 1 3 65536; do case_ render_size_$s 02 render torus.obj --out o_r.png --size $s; done
case_ render_view_nan 2 render torus.obj --out o_r.png --size 64 --view NaN,0
case_ render_view_inf 2 render torus.obj --out o_r.png --size 64 --view 0,inf
case_ render_view_bad 2 render torus.obj --out o_r.png --size 64 --view 1
case_ render_out_input 2 render torus.obj --out torus.obj
case_ render_out_readonly 2 render torus.obj --out "$ro/x.png" --size 64
case_ render_out_dir 2 render torus.obj --out "$W" --size 64
for s in 0 1 3 65536; do case_ atlas_size_$s 02 atlas torus.obj --out o_a --size $s; done
case_ atlas_gutter_huge 02 atlas torus.obj --out o_a --size 64 --gutter 100000
case_ atlas_out_file 2 atlas torus.obj --out outfile --size 64
case_ atlas_out_readonly 2 atlas torus.obj --out "$ro/x" --size 64
THREADS=(--threads 0)
case_ threads_0 2 inspect torus.obj
THREADS=(--threads 2)

# ---- conformal ------------------------------------------------------------------
C=(conformal --mesh torus.obj --size 64 --levels 2 --patch-size 8)
case_ conformal_ok 0 "${C[@]}" --out o_c --exemplar $E
for e in ex1x1 ex2x2 ex64x8 ex8x64 ex16bit exgrey exgreyalpha exalpha exflat empty garbage; do
  case_ conformal_$e 02 "${C[@]}" --out o_c --exemplar $e.png
done
for s in 0 1 3 65536; do case_ conformal_size_$s 02 conformal --mesh torus.obj --out o_c --size $s --levels 2 --patch-size 8 --exemplar $E; done
for l in 0 99; do case_ conformal_levels_$l 02 conformal --mesh torus.obj --out o_c --size 64 --levels $l --patch-size 8 --exemplar $E; done
for v in NaN inf -1 0 1e-30 1e30; do case_ conformal_scale_$v 02 "${C[@]}" --out o_c --exemplar $E --scale $v; done
for p in 0 1 2 100000; do case_ conformal_patch_$p 02 conformal --mesh torus.obj --out o_c --size 64 --levels 2 --patch-size $p --exemplar $E; done
for m in empty one_tri degenerate nan huge tiny tet; do
  case_ conformal_mesh_$m 02 conformal --mesh $m.obj --out o_c --size 64 --levels 2 --patch-size 8 --exemplar $E
done
for m in "$DEF"/*; do
  b=$(basename "$m")
  case_ conformal_mesh_$b 02 conformal --mesh "$m" --out o_c --size 64 --levels 2 --patch-size 8 --exemplar $E
done
case_ conformal_out_file 2 "${C[@]}" --exemplar $E --out outfile
case_ conformal_out_readonly 2 "${C[@]}" --exemplar $E --out "$ro/x"

# ---- solid ----------------------------------------------------------------------
S=(solid --mesh torus.obj --resolution 32 --atlas-size 64 --levels 2)
case_ solid_ok 0 "${S[@]}" --out o_s --exemplar $E
for e in ex1x1 ex2x2 ex64x8 ex8x64 ex16bit exgrey exgreyalpha exalpha exflat empty garbage; do
  case_ solid_$e 02 "${S[@]}" --out o_s --exemplar $e.png
done
for k in sk_ok sk_empty_curves sk_no_curves sk_one_point sk_zero_points sk_same_points sk_huge_weight \
  sk_zero_weight sk_neg_weight sk_unknown_axis sk_zero_normal sk_far sk_huge sk_unknown_key sk_nan \
  sk_nan_weight sk_not_json sk_empty; do
  case_ solid_$k 02 "${S[@]}" --out o_s --exemplar $E --sketch $k.json
done
for r in 0 1 2 100000; do case_ solid_resolution_$r 02 solid --mesh torus.obj --out o_s --resolution $r --atlas-size 64 --levels 2 --exemplar $E; done
for l in 0 99; do case_ solid_levels_$l 02 solid --mesh torus.obj --out o_s --resolution 32 --atlas-size 64 --levels $l --exemplar $E; done
for s in 0 1 3 65536; do case_ solid_atlas_size_$s 02 solid --mesh torus.obj --out o_s --resolution 32 --atlas-size $s --levels 2 --exemplar $E; done
for c in 0,0,0,0,0,0 100,100,100,0,0,1 0,0,0,1,0,0 NaN,0,0,1,0,0 0,0,0,inf,0,0 1,2,3; do
  case_ "solid_cut_$c" 02 "${S[@]}" --out o_s --exemplar $E --cut=$c
done
for v in NaN inf -1 0 1e30; do
  case_ solid_feature_weight_$v 02 "${S[@]}" --out o_s --exemplar $E --feature-weight $v --feature-mask mask64.png
  case_ solid_interior_depth_$v 02 "${S[@]}" --out o_s --exemplar $E --interior ex64.png --interior-depth $v
done
case_ solid_feature_mask_wrong_size 2 "${S[@]}" --out o_s --exemplar $E --feature-mask ex2x2.png
case_ solid_sketch_field_cells_0 02 "${S[@]}" --out o_s --exemplar $E --sketch sk_ok.json --field-cells 0
# The integrated start (session 18): odd exemplars, sketches, interior and level passes.
case_ solid_integrated_ok 0 "${S[@]}" --out o_s --exemplar $E --sketch sk_ok.json --integrated-init
for e in ex2x2 ex64x8 exflat exgreyalpha; do
  case_ solid_integrated_$e 02 "${S[@]}" --out o_s --exemplar $e.png --sketch sk_ok.json --integrated-init
done
for k in sk_same_points sk_far sk_huge; do
  case_ solid_integrated_$k 02 "${S[@]}" --out o_s --exemplar $E --sketch $k.json --integrated-init
done
case_ solid_integrated_interior 0 "${S[@]}" --out o_s --exemplar $E --integrated-init --interior ex64.png
case_ solid_integrated_level_passes 0 "${S[@]}" --out o_s --exemplar $E --integrated-init --level-passes 0,0
# orient --integrated-init on odd exemplars and sizes.
for e in ex2x2 ex64x8 exflat exgreyalpha; do
  case_ orient_integrated_$e 02 orient --preset whorl --integrated-init --size 32 --out o_o --exemplar $e.png
done
case_ orient_integrated_ok 0 orient --preset arch --integrated-init --size 32 --out o_o --exemplar $E
case_ solid_sketch_field_cells_100000 02 "${S[@]}" --out o_s --exemplar $E --sketch sk_ok.json --field-cells 100000
for o in "--field-cells 0" "--field-cells 100000" "--passes 0" "--passes 100000" "--block 0" "--block 1" \
  "--neighbourhood 0" "--neighbourhood 4" "--neighbourhood 99" "--trilinear-levels 99" "--integrate-levels 99" \
  "--level-passes 1,2,3,4,5,6,7,8" "--level-passes x" "--level-passes ,"; do
  # shellcheck disable=SC2086
  case_ "solid_${o// /_}" 02 "${S[@]}" --out o_s --exemplar $E $o
done
for m in empty one_tri degenerate nan huge tiny tet; do
  case_ solid_mesh_$m 02 solid --mesh $m.obj --out o_s --resolution 32 --atlas-size 64 --levels 2 --exemplar $E
done
for m in "$DEF"/*; do
  b=$(basename "$m")
  case_ solid_mesh_$b 02 solid --mesh "$m" --out o_s --resolution 32 --atlas-size 64 --levels 2 --exemplar $E
done
case_ solid_out_file 2 "${S[@]}" --exemplar $E --out outfile
case_ solid_out_readonly 2 "${S[@]}" --exemplar $E --out "$ro/x"

# ---- transfer -------------------------------------------------------------------
# tr_args KEY=VALUE…: the small transfer run from blub (OBJ+MTL+texture) onto the torus,
# with the given options replacing the defaults below.
tr_args() {
  local -A o=([--source]=$BLUB [--target]=torus.obj [--out]=o_t [--size]=64 [--samples]=4000
    [--descriptor-samples]=1000 [--clusters]=4)
  local kv
  for kv in "$@"; do o[${kv%%=*}]=${kv#*=}; done
  local k
  for k in "${!o[@]}"; do [ -n "${o[$k]}" ] && printf '%s\n%s\n' "$k" "${o[$k]}"; done
}
tcase() {
  local name=$1 want=$2
  shift 2
  local args
  mapfile -t args < <(tr_args "$@")
  case_ "$name" "$want" transfer "${args[@]}"
}
tcase transfer_ok 0
tcase transfer_spot_source_texture 0 --source="$SPOT" --source-texture="$SPOT_TEX"
tcase transfer_textureless 2 --source=tet.obj
tcase transfer_uv_no_texture 2 --source=tet_uv.obj
tcase transfer_uv_source_texture_1x1 02 --source=tet_uv.obj --source-texture=ex1x1.png
tcase transfer_source_texture_1x1 02 --source-texture=ex1x1.png
tcase transfer_source_texture_16bit 0 --source-texture=ex16bit.png
tcase transfer_source_texture_empty 2 --source-texture=empty.png
tcase transfer_mask_mismatch 2 --mask=ex2x2.png
tcase transfer_up_w 2 --up=w
for o in --samples=0 --samples=1 --samples=100000000 --descriptor-samples=0 --descriptor-samples=1 --clusters=0 \
  --clusters=1 --clusters=100000 --size=0 --size=1 --size=3 --size=65536 --coherence=NaN --coherence=inf \
  --coherence=1e30 --neighbourhood=0 --neighbourhood=4 --neighbourhood=99 --engine=nonparametric --engine=x \
  --reduce=x --match=x --match=none --reduce=pca; do
  tcase "transfer_$o" 02 "$o"
done
tcase transfer_nonparametric_neighbourhood_1 02 --engine=nonparametric --neighbourhood=1
for m in empty one_tri degenerate collinear nan inf huge tiny tet; do
  tcase transfer_target_$m 02 --target=$m.obj
done
for m in "$DEF"/*; do tcase "transfer_target_$(basename "$m")" 02 --target="$m"; done
tcase transfer_source_nonmanifold 02 --source="$DEF/nonmanifold_edge.obj" --source-texture=ex64.png
tcase transfer_same_mesh 0 --target="$BLUB"
tcase transfer_out_file 2 --out=outfile
tcase transfer_out_readonly 2 --out="$ro/x"
# Writing into the source's folder is allowed (no output is an input); the sources
# must stay as they were.
blub_sum=$(md5sum "$W"/blub/*)
tcase transfer_out_source_dir 0 --out="$W/blub"
[ "$blub_sum" = "$(md5sum "$W"/blub/blub*)" ] || { FLAGGED=$((FLAGGED + 1)); echo "FLAG transfer_out_source_dir: a source file changed"; }

# ---- eval --mesh ----------------------------------------------------------------
case_ eval_mesh_ok 0 eval --mesh "$BLUB" --reference "$BLUB" --samples 2000
case_ eval_mesh_no_reference 2 eval --mesh "$BLUB" --samples 2000
case_ eval_mesh_different_meshes 02 eval --mesh "$BLUB" --reference torus.obj --samples 2000
case_ eval_mesh_textureless 2 eval --mesh tet.obj --reference "$BLUB" --samples 2000
case_ eval_mesh_textureless_ref 2 eval --mesh "$BLUB" --reference tet_uv.obj --samples 2000
case_ eval_mesh_untextured_spot 2 eval --mesh "$SPOT" --reference "$BLUB" --samples 2000
for s in 0 1 2 100000000; do case_ eval_mesh_samples_$s 02 eval --mesh "$BLUB" --reference "$BLUB" --samples $s; done
for m in empty one_tri degenerate nan huge; do case_ eval_mesh_$m 02 eval --mesh $m.obj --reference "$BLUB" --samples 2000; done
case_ eval_mesh_out_input 2 eval --mesh "$BLUB" --reference "$BLUB" --samples 2000 --out "$(dirname "$BLUB")/blub_diffuse.png"
case_ eval_mesh_out_readonly 2 eval --mesh "$BLUB" --reference "$BLUB" --samples 2000 --out "$ro/x.json"
case_ eval_mesh_with_exemplar 02 eval --mesh "$BLUB" --reference "$BLUB" --samples 2000 --exemplar ex64.png
for e in ex1x1 ex2x2 ex16bit exgrey exalpha ex64x8; do case_ eval_image_$e 02 eval $e.png --exemplar $e.png; done
case_ eval_image_garbage 2 eval ex64.png --exemplar garbage.png

chmod u+w "$W/readonly"
echo "flagged: $FLAGGED"
[ "$FLAGGED" = 0 ]
