#!/usr/bin/env bash
# Regenerates the README gallery (docs/gallery/*.png) from built-in presets and the
# shared exemplars. Writes full outputs to out/gallery/, copies the previews.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
cargo build --release -p fieldtex-cli
bin=target/release/fieldtex
ex=../shared/data/exemplars
mkdir -p docs/gallery out/gallery
for p in arch tented-arch left-loop right-loop whorl; do
  "$bin" orient --preset "$p" --exemplar "$ex/stripes_Fabric071.png" --size 384 --out "out/gallery/orient-$p" --quiet
  cp "out/gallery/orient-$p/preview.png" "docs/gallery/orient-$p.png"
done
"$bin" demo --out out/gallery/demo --quiet
cp out/gallery/demo/preview.png docs/gallery/demo.png
"$bin" atlas ../shared/data/meshes/stanford-bunny.obj --out out/gallery/atlas-bunny --quiet
cp out/gallery/atlas-bunny/preview.png docs/gallery/atlas-bunny.png
echo "gallery written to docs/gallery/"
