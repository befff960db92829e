#!/usr/bin/env bash
# Quality and speed of `fieldtex orient` (issue: orientation-field guided synthesis)
# against Embark's texture-synthesis (installed into bench/.tools by this script),
# on the same exemplar and output size, measured in the same run.
# err_deg: coherence-weighted orientation error of the texture against the field turned by
# the exemplar's own dominant stripe direction; the exemplar's own error against that
# direction (its waviness, a floor for any synthesis) is printed at the end of each line.
# Usage: bench/orient_bench.sh [--size N] [--presets "whorl left-loop"] [--exemplars "stripes_Fabric071 ..."]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
size=512
presets="arch tented-arch left-loop right-loop whorl"
exemplars="stripes_Fabric071 bands-fingerprint-like_Onyx013 woodgrain_Wood022 weave-diagonal_Fabric015"
while [ $# -gt 0 ]; do
  case "$1" in
    --size) size="$2"; shift 2 ;;
    --presets) presets="$2"; shift 2 ;;
    --exemplars) exemplars="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
cargo build --release -p fieldtex-cli
if [ ! -x bench/.tools/bin/texture-synthesis ]; then
  cargo install --root bench/.tools texture-synthesis-cli --locked
fi
bin=target/release/fieldtex
ex=../shared/data/exemplars
out=out/orient-bench
mkdir -p "$out"
# A constant 0° field (the exemplar's x axis along +x) of the output size: Embark's
# unguided output is scored by the guided coherence in this frame, so that both outputs
# are compared by the same measure (plain coherence penalises every rotated patch, even
# an exact rotated copy of the exemplar; fieldtex-eval's guided_coherence docs).
python3 - "$out/zero-field-$size.npy" "$size" <<'PY'
import struct, sys
path, n = sys.argv[1], int(sys.argv[2])
header = "{'descr': '<f4', 'fortran_order': False, 'shape': (%d, %d, 2), }" % (n, n)
header += " " * (64 - (10 + len(header) + 1) % 64) + "\n"
with open(path, "wb") as f:
    f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode())
    f.write(struct.pack("<ff", 1.0, 0.0) * (n * n))
PY
printf "%-32s %-12s %8s %8s %8s %8s %9s %9s %9s %8s\n" exemplar preset err_deg coher g_coher pd_near pd_near_nofix synth_ms analysis_ms embark_s
for e in $exemplars; do
  # Embark, unguided, same exemplar and size (wall time; CPU time is about 2x on 2 cores).
  t0=$(date +%s.%N)
  bench/.tools/bin/texture-synthesis --no-progress --out-size "$size" --seed 1 --out "$out/embark-$e.png" generate "$ex/$e.png" >/dev/null
  t1=$(date +%s.%N)
  embark=$(python3 -c "print(f'{$t1-$t0:.1f}')")
  embark_coh=$("$bin" eval "$out/embark-$e.png" --exemplar "$ex/$e.png" --field "$out/zero-field-$size.npy" --quiet \
    | python3 -c "import json,sys; r=json.load(sys.stdin); print(round(r['coherence']['mean'],5), 'guided', round(r['guided_coherence']['mean'],5))")
  for p in $presets; do
    "$bin" orient --preset "$p" --exemplar "$ex/$e.png" --size "$size" --out "$out/$e-$p" --quiet
    "$bin" orient --preset "$p" --exemplar "$ex/$e.png" --size "$size" --out "$out/$e-$p-nofix" --no-rosy-fix --quiet
    python3 - "$out/$e-$p/report.json" "$out/$e-$p-nofix/report.json" "$e" "$p" "$embark" "$embark_coh" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); n = json.load(open(sys.argv[2]))
m = r["metrics"]; t = dict((k, v) for k, v in r["timings_ms"])
err = m["texture"]["orientation_error"]["mean_error_deg"]
coh = m["texture"]["coherence"]["mean"]
gcoh = m["texture"]["guided_coherence"]["mean"]
print(f"{sys.argv[3]:32} {sys.argv[4]:12} {err:8.2f} {coh:8.5f} {gcoh:8.5f} {m.get('phase_defects_near_singularities', -1):8} "
      f"{n['metrics'].get('phase_defects_near_singularities', -1):9} {t['synthesis']:9.0f} {t['analysis']:9.0f} {sys.argv[5]:>8}  (embark coherence {sys.argv[6]}; "
      f"exemplar's own error {m.get('exemplar_orientation', {}).get('self_error_deg', float('nan')):.1f} deg)")
PY
  done
done
