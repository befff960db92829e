#!/usr/bin/env bash
# Byte-identity probe for refactors: runs align, orient (plane and curved patch),
# field and crest with one binary on fixed inputs and seeds, and prints the md5 of every
# output that must not change (report.json differs by timings and is left out).
# Usage: tools/identity_check.sh BINARY OUTDIR   (compare two OUTDIR/md5.txt with diff)
set -euo pipefail
bin=${1:?binary}; out=${2:?out dir}
data=${DATA:-$(cd "$(dirname "$0")/.." && pwd)/../shared/data}
m=$data/meshes; e=$data/exemplars
rm -rf "$out"; mkdir -p "$out"
"$bin" crest "$m/fandisk.obj" --out "$out/crest.obj" --quiet
"$bin" field "$m/fandisk.obj" --out "$out/field.ply" --quiet
"$bin" orient --preset whorl --exemplar "$e/stripes_Fabric071.png" --size 256 --out "$out/orient" --quiet
"$bin" orient --preset whorl --exemplar "$e/stripes_Fabric071.png" --size 256 \
  --mesh "$m/demosthenes-bust-open.obj" --patch 0.18,1.6,0.9,0.8 --out "$out/orient-patch" --quiet
"$bin" align --mesh "$m/fandisk.obj" --exemplar "$e/stripes_Fabric071.png" --size 256 --out "$out/align" --quiet
(cd "$out" && find . -type f ! -name report.json ! -name md5.txt | sort | xargs md5sum) > "$out/md5.txt"
cat "$out/md5.txt"
