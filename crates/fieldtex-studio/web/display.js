// fieldtex studio, viewer displays that do not depend on the page's state: the UV
// checker texture and the per-patch colouring of a GLB's geometry. three.js is passed
// in (the page loads it on demand from /vendor/).

let checker = null;

/** A 16 × 16 checker (every fourth line red) for judging UV stretch and seams; made once. */
export function checkerTexture(THREE) {
  if (checker) return checker;
  const c = document.createElement('canvas');
  c.width = c.height = 512;
  const x = c.getContext('2d');
  for (let j = 0; j < 16; j++) for (let i = 0; i < 16; i++) {
    x.fillStyle = (i + j) % 2 ? '#f2f2f2' : (i % 4 === 0 || j % 4 === 0 ? '#d04030' : '#303848');
    x.fillRect(i * 32, j * 32, 32, 32);
  }
  checker = new THREE.CanvasTexture(c);
  checker.colorSpace = THREE.SRGBColorSpace;
  checker.flipY = false;
  return checker;
}

/** Per-triangle colours of the connected components of the index graph: the GLB
 *  writer splits vertices at UV seams, so these are the atlas charts / conformal
 *  patches. Returns a non-indexed geometry with a colour attribute. */
export function patchGeometry(THREE, geom) {
  const n = geom.attributes.position.count;
  const index = geom.index ? geom.index.array : Array.from({ length: n }, (_, i) => i);
  const parent = new Int32Array(n).map((_, i) => i);
  const find = (a) => { while (parent[a] !== a) { parent[a] = parent[parent[a]]; a = parent[a]; } return a; };
  for (let t = 0; t < index.length; t += 3) {
    const a = find(index[t]), b = find(index[t + 1]), c = find(index[t + 2]);
    parent[b] = a; parent[find(c)] = a;
  }
  const g = geom.index ? geom.toNonIndexed() : geom.clone();
  const colors = new Float32Array(g.attributes.position.count * 3);
  const ids = new Map();
  for (let t = 0; t < index.length; t += 3) {
    const root = find(index[t]);
    if (!ids.has(root)) ids.set(root, ids.size);
    const h = (ids.get(root) * 0.61803398875) % 1;
    const col = new THREE.Color().setHSL(h, 0.65, 0.55);
    for (let k = 0; k < 3; k++) colors.set([col.r, col.g, col.b], (t + k) * 3);
  }
  g.setAttribute('color', new THREE.BufferAttribute(colors, 3));
  g.userData.patches = ids.size;
  return g;
}
