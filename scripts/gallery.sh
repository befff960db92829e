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
only="${1:-all}"
# align (paper A): with and without feature-to-feature alignment (like paper A Fig. 7).
if [ "$only" = all ] || [ "$only" = align ]; then
  for m in ../shared/data/textured/blub/blub.obj ../shared/data/meshes/fandisk.obj ../shared/data/meshes/rocker-arm.obj; do
    n="$(basename "$m" .obj)"
    "$bin" align --mesh "$m" --exemplar "$ex/stripes_Fabric071.png" --size 512 --out "out/gallery/align-$n" --quiet
    "$bin" align --mesh "$m" --exemplar "$ex/stripes_Fabric071.png" --size 512 --no-feature-align --out "out/gallery/align-$n-nofa" --quiet
    cp "out/gallery/align-$n/preview.png" "docs/gallery/align-$n.png"
    cp "out/gallery/align-$n-nofa/preview.png" "docs/gallery/align-$n-nofa.png"
  done
  [ "$only" = align ] && { echo "gallery (align) written to docs/gallery/"; exit 0; }
fi
# align on photo exemplars (issue 16): bricks and wood are 512² photos, stone wall and
# gravel 124² photo thumbnails enlarged 4× (as bench/align_quality.sh does, so their
# structures span as many pixels as in a 512² photo); fandisk and koala, 1024² atlas
# (`gallery.sh photos` for these only).
if [ "$only" = all ] || [ "$only" = photos ]; then
  cargo build --release -q -p fieldtex-texopt --example resize_exemplar
  mkdir -p out/gallery/photos
  for src in stone-wall_Rocks001 gravel_Gravel005; do
    [ -f "out/gallery/photos/$src-512.png" ] ||
      target/release/examples/resize_exemplar "$ex/$src.png" 512 "out/gallery/photos/$src-512.png"
  done
  for m in fandisk koala-lowres; do
    for e in bricks stone-wall gravel wood; do
      case "$e" in
        bricks) p="$ex/bricks-gray-large_MaterialX-brick_base_gray.png" ;;
        stone-wall) p=out/gallery/photos/stone-wall_Rocks001-512.png ;;
        gravel) p=out/gallery/photos/gravel_Gravel005-512.png ;;
        wood) p="$ex/woodgrain-large_MaterialX-wood_color.png" ;;
      esac
      "$bin" align --mesh "../shared/data/meshes/$m.obj" --exemplar "$p" --size 1024 \
        --out "out/gallery/photo-$m-$e" --quiet
      cp "out/gallery/photo-$m-$e/preview.png" "docs/gallery/photo-$m-$e.png"
    done
  done
  [ "$only" = photos ] && { echo "gallery (photos) written to docs/gallery/"; exit 0; }
fi
# orient (paper D): the five fingerprint presets and a curved patch (`gallery.sh orient`
# for these only).
"$bin" orient --preset whorl --exemplar "$ex/stripes_Fabric071.png" --mesh ../shared/data/meshes/demosthenes-bust-open.obj \
  --patch 0.18,1.6,0.9,0.8 --size 512 --out out/gallery/orient-patch --quiet --no-metrics
cp out/gallery/orient-patch/preview.png docs/gallery/orient-patch.png
for p in arch tented-arch left-loop right-loop whorl; do
  "$bin" orient --preset "$p" --exemplar "$ex/stripes_Fabric071.png" --size 384 --out "out/gallery/orient-$p" --quiet --no-metrics
  cp "out/gallery/orient-$p/preview.png" "docs/gallery/orient-$p.png"
done
# The arch preset started from the exemplar carried along the field (--integrated-init).
"$bin" orient --preset arch --integrated-init --exemplar "$ex/stripes_Fabric071.png" --size 384 \
  --out out/gallery/orient-arch-integrated --quiet --no-metrics
cp out/gallery/orient-arch-integrated/preview.png docs/gallery/orient-arch-integrated.png
[ "$only" = orient ] && { echo "gallery (orient) written to docs/gallery/"; exit 0; }
"$bin" demo --out out/gallery/demo --quiet
cp out/gallery/demo/preview.png docs/gallery/demo-cube.png
cp out/gallery/demo/orient.png docs/gallery/demo-orient-whorl.png
mesh=../shared/data/meshes
for m in torus fertility stanford-bunny; do
  "$bin" conformal --mesh "$mesh/$m.obj" --exemplar "$ex/pebbles_Rocks002.png" --out "out/gallery/conformal-$m" --quiet
done
cp out/gallery/conformal-torus/preview.png docs/gallery/conformal-torus.png
cp out/gallery/conformal-fertility/preview.png docs/gallery/conformal-fertility.png
cp out/gallery/conformal-stanford-bunny/preview.png docs/gallery/conformal-bunny.png
"$bin" conformal --mesh "$mesh/stanford-bunny.obj" --exemplar "$ex/pebbles_Rocks002.png" --no-multiscale --out out/gallery/conformal-bunny-nms --quiet
cp out/gallery/conformal-bunny-nms/preview.png docs/gallery/conformal-bunny-no-multiscale.png
"$bin" conformal --mesh "$mesh/stanford-bunny.obj" --exemplar "$ex/pebbles_Rocks002.png" --quasi-isometric --out out/gallery/conformal-bunny-qi --quiet
cp out/gallery/conformal-bunny-qi/preview.png docs/gallery/conformal-bunny-quasi-isometric.png
"$bin" atlas ../shared/data/meshes/stanford-bunny.obj --out out/gallery/atlas-bunny --quiet
cp out/gallery/atlas-bunny/preview.png docs/gallery/atlas-bunny.png
echo "gallery written to docs/gallery/"
