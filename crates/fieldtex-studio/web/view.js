// fieldtex studio, mesh modes: the three.js view (renderer, camera, orbit controls,
// lights, one group per layer: mesh, crest, drawn, field, glb, cut, ref), camera fitting
// and polylines. The page reads the exported bindings; only setupView assigns them.

let THREE = null;
export let renderer = null;
export let scene = null;
export let camera = null;
export let controls = null;
export const groups = {};

/** Builds the view inside `box` with three.js `three` and its `OrbitControls`; the
 *  canvas's pointer events go to `handlers` (onPointerDown, onPointerMove, onPointerUp). */
export function setupView(three, OrbitControls, box, handlers) {
  THREE = three;
  renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(720, 560);
  renderer.setClearColor(0xffffff, 1);
  box.appendChild(renderer.domElement);
  scene = new THREE.Scene();
  camera = new THREE.PerspectiveCamera(40, 720 / 560, 0.001, 1000);
  camera.position.set(0, 0, 3);
  controls = new OrbitControls(camera, renderer.domElement);
  controls.addEventListener('change', render);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x666677, 2.2));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  sun.position.set(1, 2, 3);
  camera.add(sun);
  scene.add(camera);
  for (const g of ['mesh', 'crest', 'drawn', 'field', 'glb', 'cut', 'ref']) {
    groups[g] = new THREE.Group();
    scene.add(groups[g]);
  }
  renderer.domElement.addEventListener('pointerdown', handlers.onPointerDown);
  renderer.domElement.addEventListener('pointermove', handlers.onPointerMove);
  renderer.domElement.addEventListener('pointerup', handlers.onPointerUp);
  render();
}

export function render() {
  if (renderer) renderer.render(scene, camera);
}

export function clearGroup(g) {
  for (const c of [...groups[g].children]) {
    groups[g].remove(c);
    c.traverse((o) => { if (o.geometry) o.geometry.dispose(); });
  }
}

export function fitCamera(lo, hi) {
  const c = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  const r = Math.max(1e-6, Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2);
  controls.target.copy(c);
  camera.position.set(c.x + r * 0.9, c.y + r * 0.7, c.z + r * 2.4);
  camera.near = r / 100; camera.far = r * 100;
  camera.updateProjectionMatrix();
  controls.update();
}

export function polyline(points, color, width = 1) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(points.flat(), 3));
  const m = new THREE.LineBasicMaterial({ color, linewidth: width, depthTest: true });
  return new THREE.Line(g, m);
}
