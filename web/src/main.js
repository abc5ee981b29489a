// The qem viewer page: loads data/scene.json (written by `qem view`, see docs/viewer.md) and its
// binary buffers, and shows the levels with three.js. A scene is a list of levels, each a mesh
// with {faces, vertices, error}: an LOD chain walks them with the slider, compare mode draws two
// side by side with one shared camera (so the views are linked), and a level carrying a
// per-vertex `distance` buffer can be coloured as an error heat map.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

// Viridis at 0, .25, .5, .75, 1 (sRGB): the same stops as `qem render` (src/view/render.cpp).
const VIRIDIS = [
  [0.267, 0.005, 0.329], [0.229, 0.322, 0.546], [0.128, 0.567, 0.551], [0.369, 0.789, 0.383], [0.993, 0.906, 0.144],
];
const BASE_COLOR = new THREE.Color().setRGB(0.72, 0.76, 0.82, THREE.SRGBColorSpace);

// What the tests (and a curious user in the console) can read: the page's state.
const viewer = { ready: false, error: null, scene: null, level: 0, renders: 0 };
window.qemViewer = viewer;

const $ = (id) => document.getElementById(id);

function heatColor(t) {
  t = Math.min(1, Math.max(0, Number.isFinite(t) ? t : 0));
  const x = t * 4, i = Math.min(3, Math.floor(x)), f = x - i;
  return VIRIDIS[i].map((a, k) => a + f * (VIRIDIS[i + 1][k] - a));
}

function formatNumber(n) { return n.toLocaleString('en-US'); }
function formatError(e) {
  if (e === null || e === undefined || !Number.isFinite(e)) return 'n/a';
  return e === 0 ? '0' : e.toPrecision(3);
}

function showMessage(text) {
  const m = $('message');
  m.textContent = text;
  m.hidden = false;
  viewer.error = text;
}

async function fetchBuffer(path, Type) {
  const r = await fetch(path);
  if (!r.ok) throw new Error(`${path}: HTTP ${r.status}`);
  return new Type(await r.arrayBuffer());
}

async function loadScene() {
  if (location.protocol === 'file:')
    throw new Error('This page loads its data with fetch(), which browsers block for file:// pages. ' +
      'Serve the folder over HTTP (for example `python3 -m http.server`) or use `qem view`.');
  const r = await fetch('data/scene.json');
  if (!r.ok) throw new Error(`data/scene.json: HTTP ${r.status}`);
  const scene = await r.json();
  if (scene.format !== 'qem-view' || !Array.isArray(scene.levels) || scene.levels.length === 0)
    throw new Error('data/scene.json is not a qem-view scene');
  // All buffers up front: the slider then switches levels instantly.
  await Promise.all(scene.levels.map(async (level) => {
    level.positionArray = await fetchBuffer(level.positions, Float32Array);
    level.indexArray = await fetchBuffer(level.indices, Uint32Array);
    if (level.distance) level.distanceArray = await fetchBuffer(level.distance, Float32Array);
  }));
  return scene;
}

function makeGeometry(level, range) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(level.positionArray, 3));
  g.setIndex(new THREE.BufferAttribute(level.indexArray, 1));
  g.computeVertexNormals();
  if (level.distanceArray && range) {
    const [lo, hi] = range, d = level.distanceArray, colors = new Float32Array(d.length * 3), c = new THREE.Color();
    for (let i = 0; i < d.length; ++i) {
      const [r, gr, b] = heatColor(hi > lo ? (d[i] - lo) / (hi - lo) : 0);
      c.setRGB(r, gr, b, THREE.SRGBColorSpace);
      colors[3 * i] = c.r; colors[3 * i + 1] = c.g; colors[3 * i + 2] = c.b;
    }
    g.setAttribute('color', new THREE.BufferAttribute(colors, 3));
  }
  g.computeBoundingSphere();
  return g;
}

// One side of the window: its own three.js scene with the current level's mesh and wireframe.
class View {
  constructor() {
    this.scene = new THREE.Scene();
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 0.9));
    this.light = new THREE.DirectionalLight(0xffffff, 2.0);
    this.scene.add(this.light, this.light.target);
    this.material = new THREE.MeshLambertMaterial({
      color: BASE_COLOR, flatShading: true, side: THREE.DoubleSide,
      // Push the faces back a little so the wireframe drawn over them is not z-fighting.
      polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    });
    this.wireMaterial = new THREE.MeshBasicMaterial({ color: 0x1a1a20, wireframe: true, transparent: true, opacity: 0.45 });
    this.mesh = new THREE.Mesh(undefined, this.material);
    this.wire = new THREE.Mesh(undefined, this.wireMaterial);
    this.scene.add(this.mesh, this.wire);
    this.geometries = new Map();
  }
  show(level, index, range) {
    if (!this.geometries.has(index)) this.geometries.set(index, makeGeometry(level, range));
    const g = this.geometries.get(index);
    this.mesh.geometry = g;
    this.wire.geometry = g;
    this.hasHeat = !!g.getAttribute('color');
  }
  style({ flat, wireframe, heatmap }) {
    const heat = heatmap && this.hasHeat;
    if (this.material.flatShading !== flat || this.material.vertexColors !== heat) {
      this.material.flatShading = flat;
      this.material.vertexColors = heat;
      this.material.needsUpdate = true;
    }
    this.material.color.copy(heat ? new THREE.Color(0xffffff) : BASE_COLOR);
    this.wire.visible = wireframe;
  }
}

function main(scene) {
  viewer.scene = scene;
  const canvas = $('view');
  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  } catch (e) {
    throw new Error(`WebGL is not available in this browser (${e.message})`);
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setClearColor(0xf5f5f5);

  const compare = scene.mode === 'compare';
  const views = compare ? [new View(), new View()] : [new View()];
  const radius = scene.radius || 1;
  const camera = new THREE.PerspectiveCamera(35, 1, radius / 100, radius * 100);
  // The same default view as `qem render`: yaw 30 degrees, pitch 20 degrees.
  const yaw = (30 * Math.PI) / 180, pitch = (20 * Math.PI) / 180;
  const dist = (radius / Math.sin((17.5 * Math.PI) / 180)) * 1.05;
  camera.position.set(Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch), Math.cos(pitch) * Math.cos(yaw)).multiplyScalar(dist);
  const controls = new OrbitControls(camera, canvas);
  controls.target.set(0, 0, 0);
  controls.update();

  const state = { level: 0, flat: true, wireframe: false, heatmap: true };
  viewer.state = state;
  const levels = scene.levels;
  const hasHeat = !!scene.distance_range && levels.some((l) => l.distance);
  $('title').textContent = scene.title || 'qem view';
  document.title = `${scene.title || 'qem'} — qem view`;

  const slider = $('level-slider');
  if (!compare && levels.length > 1) {
    $('levels').hidden = false;
    slider.max = String(levels.length - 1);
  }
  if (hasHeat) {
    $('heatmap-toggle').hidden = false;
    $('legend-min').textContent = formatError(scene.distance_range[0]);
    $('legend-max').textContent = formatError(scene.distance_range[1]);
  }
  if (compare) {
    $('labels').innerHTML = '<div class="label" id="label-0"></div><div class="label" id="label-1"></div>';
    $('label-0').style.left = '50%';
  }

  function update() {
    const shown = compare ? [0, 1] : [state.level];
    shown.forEach((li, vi) => {
      views[vi].show(levels[li], li, scene.distance_range);
      views[vi].style(state);
    });
    // The panel describes the level being judged: the current one, or the simplified side.
    const cur = levels[compare ? 1 : state.level];
    $('face-count').textContent = formatNumber(cur.faces);
    $('vertex-count').textContent = formatNumber(cur.vertices);
    $('error-value').textContent = formatError(cur.error);
    $('level-index').textContent = `${state.level + 1} / ${levels.length}`;
    if (compare)
      [0, 1].forEach((i) => {
        const l = levels[i];
        $(`label-${i}`).textContent = `${i ? 'Simplified' : 'Original'}: ${l.name} · ${formatNumber(l.faces)} faces · ` +
          `${formatNumber(l.vertices)} vertices${i ? ` · error ${formatError(l.error)}` : ''}`;
      });
    $('legend').hidden = !(hasHeat && state.heatmap && views.some((v) => v.hasHeat));
    viewer.level = state.level;
    render();
  }

  function render() {
    const w = canvas.clientWidth, h = canvas.clientHeight;
    const size = renderer.getSize(new THREE.Vector2());
    if (size.x !== w || size.y !== h) renderer.setSize(w, h, false);
    const vw = compare ? w / 2 : w;
    camera.aspect = vw / h;
    camera.updateProjectionMatrix();
    renderer.setScissorTest(compare);
    views.forEach((v, i) => {
      // The light follows the camera, so the side facing the viewer is always lit.
      v.light.position.copy(camera.position).add(camera.up.clone().multiplyScalar(radius * 2));
      v.light.target.position.copy(controls.target);
      renderer.setViewport(i * vw, 0, vw, h);
      renderer.setScissor(i * vw, 0, vw, h);
      renderer.render(v.scene, camera);
    });
    if (compare) $('label-1').style.left = `${w * 0.75}px`, $('label-0').style.left = `${w * 0.25}px`;
    viewer.renders++;
  }

  slider.addEventListener('input', () => { state.level = Number(slider.value); update(); });
  for (const el of document.querySelectorAll('input[name=shading]'))
    el.addEventListener('change', () => { state.flat = $('shading-flat').checked; update(); });
  $('wireframe').addEventListener('change', (e) => { state.wireframe = e.target.checked; update(); });
  $('heatmap').addEventListener('change', (e) => { state.heatmap = e.target.checked; update(); });
  controls.addEventListener('change', render);
  window.addEventListener('resize', render);
  update();
  viewer.ready = true;
  document.body.dataset.ready = 'true';
}

loadScene().then(main).catch((e) => {
  console.error(e);
  showMessage(`qem view: ${e.message}`);
  document.body.dataset.ready = 'error';
});
