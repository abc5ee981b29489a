// The qem viewer page: loads data/scene.json (written by `qem view`, see docs/viewer.md) and what
// it lists, and shows the levels with three.js. A scene is a list of levels, each a model with
// {faces, vertices, error}: an LOD chain walks them with the slider, compare mode draws two side
// by side with one shared camera and one animation clock (so the views are linked). A level is
// either buffers written by qem (positions and faces, with the file's normals, texture
// coordinates, colours, materials and textures when it has them, and a per-vertex `distance` for
// the error heat map) or a glTF document shown as itself by three's GLTFLoader (materials,
// textures, node hierarchy, skins, animations). Seam edges and a UV checker texture can be
// overlaid to judge how simplification treated the seams.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { SeamOverlay } from './seams.js';
import { checkerTexture } from './checker.js';

// Viridis at 0, .25, .5, .75, 1 (sRGB): the same stops as `qem render` (src/view/render.cpp).
const VIRIDIS = [
  [0.267, 0.005, 0.329], [0.229, 0.322, 0.546], [0.128, 0.567, 0.551], [0.369, 0.789, 0.383], [0.993, 0.906, 0.144],
];
const BASE_COLOR = new THREE.Color().setRGB(0.72, 0.76, 0.82, THREE.SRGBColorSpace);
const SEAM_COLOR = 0xff1f8f;

// What the tests (and a curious user in the console) can read: the page's state.
const viewer = { ready: false, error: null, scene: null, level: 0, renders: 0, warnings: [] };
window.qemViewer = viewer;

const $ = (id) => document.getElementById(id);
// Data paths are file names: escape each segment (a texture may be called "a b#1.png").
const urlOf = (path) => path.split('/').map(encodeURIComponent).join('/');

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
  const r = await fetch(urlOf(path));
  if (!r.ok) throw new Error(`${path}: HTTP ${r.status}`);
  return new Type(await r.arrayBuffer());
}

// A texture that fails to load leaves its material plain, with a note, rather than no page.
async function loadTexture(path) {
  try {
    const t = await new THREE.TextureLoader().loadAsync(urlOf(path));
    t.colorSpace = THREE.SRGBColorSpace;  // MTL diffuse maps are colour images
    t.wrapS = t.wrapT = THREE.RepeatWrapping;
    t.anisotropy = 4;
    return t;
  } catch (e) {
    viewer.warnings.push(`${path}: the texture could not be loaded`);
    return null;
  }
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
  // Everything up front: the slider then switches levels instantly.
  await Promise.all(scene.levels.map(async (level) => {
    if (level.gltf) {
      try {
        level.gltfData = await new GLTFLoader().loadAsync(urlOf(level.gltf));
      } catch (e) {
        throw new Error(`${level.name}: the glTF document could not be loaded (${e.message || e})`);
      }
      return;
    }
    level.positionArray = await fetchBuffer(level.positions, Float32Array);
    level.indexArray = await fetchBuffer(level.indices, Uint32Array);
    if (level.distance) level.distanceArray = await fetchBuffer(level.distance, Float32Array);
    if (level.normals) level.normalArray = await fetchBuffer(level.normals, Float32Array);
    if (level.uvs) level.uvArray = await fetchBuffer(level.uvs, Float32Array);
    if (level.colors) level.colorArray = await fetchBuffer(level.colors, Float32Array);
    if (level.face_materials) level.materialArray = await fetchBuffer(level.face_materials, Uint32Array);
    if (level.materials) level.textures = await Promise.all(level.materials.map((m) => (m.texture ? loadTexture(m.texture) : null)));
  }));
  return scene;
}

// Faces sorted by material (stable), for three's geometry groups: one draw per material.
function groupByMaterial(indices, materials, count) {
  const faces = indices.length / 3;
  const order = Array.from({ length: faces }, (_, f) => f).sort((a, b) => materials[a] - materials[b] || a - b);
  const sorted = new Uint32Array(indices.length), sortedMaterials = new Uint32Array(faces), groups = [];
  order.forEach((f, k) => {
    sorted.set(indices.subarray(3 * f, 3 * f + 3), 3 * k);
    sortedMaterials[k] = materials[f];
    const m = Math.min(materials[f], count - 1);
    if (groups.length && groups[groups.length - 1].material === m) groups[groups.length - 1].count += 3;
    else groups.push({ start: 3 * k, count: 3, material: m });
  });
  return { sorted, sortedMaterials, groups };
}

// A level written as buffers: one Mesh with the file's normals, UVs, colours and materials.
function buildBufferLevel(level, range, materialOptions) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(level.positionArray, 3));
  let faceMaterials = null;
  const mats = level.materials || [];
  if (mats.length && level.materialArray) {
    const { sorted, sortedMaterials, groups } = groupByMaterial(level.indexArray, level.materialArray, mats.length);
    g.setIndex(new THREE.BufferAttribute(sorted, 1));
    for (const gr of groups) g.addGroup(gr.start, gr.count, gr.material);
    faceMaterials = sortedMaterials;
  } else {
    g.setIndex(new THREE.BufferAttribute(level.indexArray, 1));
  }
  if (level.normalArray) g.setAttribute('normal', new THREE.BufferAttribute(level.normalArray, 3));
  else g.computeVertexNormals();
  if (level.uvArray) g.setAttribute('uv', new THREE.BufferAttribute(level.uvArray, 2));
  const colorSets = {};
  if (level.colorArray) {
    // File colours are sRGB (PLY, OBJ, OFF); three works in linear light.
    const k = level.color_components || 3, src = level.colorArray, n = src.length / k, out = new Float32Array(n * 3), c = new THREE.Color();
    for (let i = 0; i < n; ++i) {
      c.setRGB(src[k * i], src[k * i + 1], src[k * i + 2], THREE.SRGBColorSpace);
      out[3 * i] = c.r; out[3 * i + 1] = c.g; out[3 * i + 2] = c.b;
    }
    colorSets.file = new THREE.BufferAttribute(out, 3);
  }
  if (level.distanceArray && range) {
    const [lo, hi] = range, d = level.distanceArray, colors = new Float32Array(d.length * 3), c = new THREE.Color();
    for (let i = 0; i < d.length; ++i) {
      const [r, gr, b] = heatColor(hi > lo ? (d[i] - lo) / (hi - lo) : 0);
      c.setRGB(r, gr, b, THREE.SRGBColorSpace);
      colors[3 * i] = c.r; colors[3 * i + 1] = c.g; colors[3 * i + 2] = c.b;
    }
    colorSets.heat = new THREE.BufferAttribute(colors, 3);
  }
  g.computeBoundingSphere();
  const materials = mats.length
    ? mats.map((m, i) => {
      const mat = new THREE.MeshLambertMaterial({ ...materialOptions, map: level.textures[i] || null,
        color: new THREE.Color().setRGB(m.color[0], m.color[1], m.color[2], THREE.SRGBColorSpace) });
      if (m.opacity < 1) Object.assign(mat, { transparent: true, opacity: m.opacity });
      return mat;
    })
    : [new THREE.MeshLambertMaterial({ ...materialOptions, color: BASE_COLOR })];
  const mesh = new THREE.Mesh(g, mats.length ? materials : materials[0]);
  const root = new THREE.Group();
  root.add(mesh);
  return { root, meshes: [{ mesh, faceMaterials, colorSets }], clips: [], textured: materials.some((m) => m.map) };
}

// A glTF level: the document's own scene, with an animation mixer when it has animations.
function buildGltfLevel(level) {
  const gltf = level.gltfData, root = new THREE.Group();
  root.add(gltf.scene);
  const meshes = [];
  gltf.scene.traverse((o) => {
    if (!o.isMesh) return;
    meshes.push({ mesh: o, faceMaterials: null, colorSets: {} });
    // Skinned meshes move away from their bind-pose bounds: never cull them.
    if (o.isSkinnedMesh) o.frustumCulled = false;
    for (const m of Array.isArray(o.material) ? o.material : [o.material])
      Object.assign(m, { polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 });
  });
  const clips = gltf.animations || [];
  const mixer = clips.length ? new THREE.AnimationMixer(gltf.scene) : null;
  const actions = clips.map((c) => mixer.clipAction(c));
  return { gltf: true, root, meshes, clips, mixer, actions, textured: meshes.some((m) => [].concat(m.mesh.material).some((x) => x.map)) };
}

const clipName = (clip, i) => clip.name || `clip ${i + 1}`;

// One side of the window: its own three.js scene holding the current level.
class View {
  constructor(shared) {
    this.shared = shared;
    this.scene = new THREE.Scene();
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 0.9));
    this.light = new THREE.DirectionalLight(0xffffff, 2.0);
    this.scene.add(this.light, this.light.target);
    this.content = new THREE.Group();
    this.scene.add(this.content);
    this.current = null;
  }
  show(obj) {
    if (this.current === obj) return;
    if (this.current) this.content.remove(this.current.root);
    this.current = obj;
    this.content.add(obj.root);
  }
}

// Everything a level object needs for the toggles, made once per level on first use.
function decorate(obj, shared) {
  if (obj.decorated) return;
  obj.decorated = true;
  obj.wires = [];
  obj.seams = [];
  for (const entry of obj.meshes) {
    const m = entry.mesh;
    // The wireframe draws the same (possibly skinned) geometry over the faces.
    const w = m.isSkinnedMesh ? new THREE.SkinnedMesh(m.geometry, shared.wireMaterial) : new THREE.Mesh(m.geometry, shared.wireMaterial);
    if (m.isSkinnedMesh) { w.bind(m.skeleton, m.bindMatrix); w.frustumCulled = false; }
    w.visible = false;
    m.add(w);
    obj.wires.push(w);
    const s = new SeamOverlay(m, entry.faceMaterials, shared.seamMaterial);
    s.line.visible = false;
    obj.seams.push(s);
  }
}

function styleLevel(obj, state, shared) {
  decorate(obj, shared);
  const heat = state.heatmap;
  obj.hasHeat = false;
  for (const { mesh, colorSets } of obj.meshes) {
    const useHeat = heat && !!colorSets.heat, colors = useHeat ? colorSets.heat : colorSets.file;
    obj.hasHeat ||= !!colorSets.heat;
    if (colors && mesh.geometry.getAttribute('color') !== colors) mesh.geometry.setAttribute('color', colors);
    for (const mat of [].concat(mesh.material)) {
      if (!mat.userData.qem) mat.userData.qem = { map: mat.map, color: mat.color.clone(), vertexColors: mat.vertexColors };
      const orig = mat.userData.qem;
      const checker = state.uvChecker && !!mesh.geometry.getAttribute('uv');
      // Buffers: colours are the heat map or the file's; a glTF material keeps its own choice.
      const vertexColors = obj.gltf ? orig.vertexColors : !!colors;
      const map = checker ? shared.checker : useHeat ? null : orig.map;
      const color = checker || useHeat ? new THREE.Color(0xffffff) : orig.color;
      if (mat.flatShading !== state.flat || mat.map !== map || mat.vertexColors !== vertexColors) {
        mat.flatShading = state.flat;
        mat.map = map;
        mat.vertexColors = vertexColors;
        mat.needsUpdate = true;
      }
      mat.color.copy(color);
    }
  }
  obj.wires.forEach((w) => { w.visible = state.wireframe; });
  obj.seams.forEach((s) => { s.line.visible = state.seams; });
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

  const levels = scene.levels;
  const shared = {
    wireMaterial: new THREE.MeshBasicMaterial({ color: 0x1a1a20, wireframe: true, transparent: true, opacity: 0.45 }),
    seamMaterial: new THREE.LineBasicMaterial({ color: SEAM_COLOR, depthTest: true }),
    checker: checkerTexture(),
  };
  // Push faces back a little so the wireframe and seam lines drawn over them do not z-fight.
  const materialOptions = { side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 };
  const objects = levels.map((l) => (l.gltf ? buildGltfLevel(l) : buildBufferLevel(l, scene.distance_range, materialOptions)));
  // glTF documents keep their own coordinates: shift them into qem's frame (buffers are stored
  // relative to scene.center), then frame everything by the union of what is drawn (a skinned
  // model's pose need not match its bind-pose bounds, which qem measured).
  const c0 = new THREE.Vector3().fromArray(scene.center || [0, 0, 0]);
  objects.forEach((o, i) => { if (levels[i].gltf) o.root.position.copy(c0).negate(); });
  const frame = new THREE.Box3();
  for (const o of objects) { o.root.updateMatrixWorld(true); frame.union(new THREE.Box3().setFromObject(o.root, true)); }
  const frameCenter = frame.isEmpty() ? new THREE.Vector3() : frame.getCenter(new THREE.Vector3());
  const radius = frame.isEmpty() ? scene.radius || 1 : Math.max(frame.getSize(new THREE.Vector3()).length() / 2, 1e-9);

  const compare = scene.mode === 'compare';
  const views = compare ? [new View(shared), new View(shared)] : [new View(shared)];
  views.forEach((v) => v.content.position.copy(frameCenter).negate());
  const camera = new THREE.PerspectiveCamera(35, 1, radius / 100, radius * 100);
  // The same default view as `qem render`: yaw 30 degrees, pitch 20 degrees.
  const yaw = (30 * Math.PI) / 180, pitch = (20 * Math.PI) / 180;
  const dist = (radius / Math.sin((17.5 * Math.PI) / 180)) * 1.05;
  camera.position.set(Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch), Math.cos(pitch) * Math.cos(yaw)).multiplyScalar(dist);
  const controls = new OrbitControls(camera, canvas);
  controls.target.set(0, 0, 0);
  controls.update();

  // Files with their own normals (or glTF) look as their author meant with smooth shading.
  const fileNormals = levels.some((l) => l.gltf || l.normals);
  const state = { level: 0, flat: !fileNormals, wireframe: false, heatmap: true, seams: false, uvChecker: false };
  viewer.state = state;
  $(fileNormals ? 'shading-smooth' : 'shading-flat').checked = true;
  const hasHeat = !!scene.distance_range && levels.some((l) => l.distance);
  const hasUv = levels.some((l) => l.gltf || l.uvs);
  $('title').textContent = scene.title || 'qem view';
  document.title = `${scene.title || 'qem'} — qem view`;

  // One animation clock for every view: original and simplified move in step.
  const anim = { playing: true, time: 0, clip: 'all', last: null, duration: 0 };
  viewer.anim = anim;
  const clipNames = [];
  for (const o of objects) o.clips.forEach((c, i) => { if (!clipNames.includes(clipName(c, i))) clipNames.push(clipName(c, i)); });
  anim.duration = Math.max(0, ...objects.flatMap((o) => o.clips.map((c) => c.duration)));
  if (clipNames.length) {
    $('animation').hidden = false;
    const select = $('clip');
    select.innerHTML = '';
    for (const [value, label] of [['all', 'All clips'], ...clipNames.map((n) => [n, n])]) {
      const opt = document.createElement('option');
      opt.value = value; opt.textContent = label;
      select.appendChild(opt);
    }
    select.hidden = clipNames.length < 2;
    $('anim-time').max = String(anim.duration);
  }
  function chooseClips() {
    for (const o of objects)
      o.actions?.forEach((a, i) => { if (anim.clip === 'all' || clipName(o.clips[i], i) === anim.clip) a.play(); else a.stop(); });
  }
  chooseClips();

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
  if (hasUv) $('uv-checker-toggle').hidden = false;
  if (compare) {
    $('labels').innerHTML = '<div class="label" id="label-0"></div><div class="label" id="label-1"></div>';
    $('label-0').style.left = '50%';
  }
  const shown = () => (compare ? [0, 1] : [state.level]);

  function update() {
    shown().forEach((li, vi) => {
      views[vi].show(objects[li]);
      styleLevel(objects[li], state, shared);
    });
    // The panel describes the level being judged: the current one, or the simplified side.
    const cur = levels[compare ? 1 : state.level];
    $('face-count').textContent = formatNumber(cur.faces);
    $('vertex-count').textContent = formatNumber(cur.vertices);
    $('error-value').textContent = formatError(cur.error);
    $('level-index').textContent = `${state.level + 1} / ${levels.length}`;
    const seamCount = shown().reduce((s, li) => s + objects[li].seams.reduce((t, x) => t + x.seams + x.borders, 0), 0);
    $('seam-count').textContent = state.seams ? `(${formatNumber(seamCount)} edges)` : '';
    if (compare)
      [0, 1].forEach((i) => {
        const l = levels[i];
        $(`label-${i}`).textContent = `${i ? 'Simplified' : 'Original'}: ${l.name} · ${formatNumber(l.faces)} faces · ` +
          `${formatNumber(l.vertices)} vertices${i ? ` · error ${formatError(l.error)}` : ''}`;
      });
    $('legend').hidden = !(hasHeat && state.heatmap && shown().some((li) => objects[li].hasHeat));
    viewer.level = state.level;
    applyTime();
    render();
  }

  // Poses every shown level at the clock's time; skinned seam lines follow the skin.
  function applyTime() {
    for (const li of shown()) {
      const o = objects[li];
      if (!o.mixer) continue;
      o.mixer.setTime(anim.time);
      o.root.updateMatrixWorld(true);
      if (state.seams) o.seams.forEach((s) => { if (s.skinned) s.update(); });
    }
    $('anim-time').value = String(anim.duration ? anim.time % anim.duration : 0);
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

  // Animation frames only while something plays; otherwise the page renders on demand.
  function tick(now) {
    if (!anim.playing || !clipNames.length) { anim.last = null; return; }
    if (anim.last !== null) anim.time += Math.min(0.1, (now - anim.last) / 1000);
    anim.last = now;
    applyTime();
    render();
    requestAnimationFrame(tick);
  }
  function setPlaying(p) {
    anim.playing = p;
    $('play').textContent = p ? 'Pause' : 'Play';
    if (p) requestAnimationFrame(tick);
  }

  slider.addEventListener('input', () => { state.level = Number(slider.value); update(); });
  for (const el of document.querySelectorAll('input[name=shading]'))
    el.addEventListener('change', () => { state.flat = $('shading-flat').checked; update(); });
  $('wireframe').addEventListener('change', (e) => { state.wireframe = e.target.checked; update(); });
  $('heatmap').addEventListener('change', (e) => { state.heatmap = e.target.checked; update(); });
  $('seams').addEventListener('change', (e) => { state.seams = e.target.checked; update(); });
  $('uv-checker').addEventListener('change', (e) => { state.uvChecker = e.target.checked; update(); });
  $('play').addEventListener('click', () => setPlaying(!anim.playing));
  // The panel folds to its title, so that it does not hide the left model in compare mode.
  $('panel-toggle').addEventListener('click', () => {
    const folded = $('panel').classList.toggle('collapsed');
    $('panel-toggle').textContent = folded ? '+' : '–';
    $('panel-toggle').title = folded ? 'Show the panel' : 'Hide the panel';
    $('panel-toggle').setAttribute('aria-expanded', String(!folded));
  });
  $('clip').addEventListener('change', (e) => { anim.clip = e.target.value; chooseClips(); update(); });
  $('anim-time').addEventListener('input', (e) => { setPlaying(false); anim.time = Number(e.target.value); update(); });
  controls.addEventListener('change', render);
  window.addEventListener('resize', render);

  // For the tests: what each view shows, read from three's own objects (bone matrices as the
  // renderer uploads them, the bounds of the skinned positions, seam counts, textures).
  viewer.inspect = () => views.map((v) => {
    const o = v.current, skinned = o.meshes.map((e) => e.mesh).filter((m) => m.isSkinnedMesh);
    const box = new THREE.Box3();
    for (const m of skinned) { m.computeBoundingBox(); box.union(m.boundingBox.clone().applyMatrix4(m.matrixWorld)); }
    const bones = skinned.map((m) => Array.from(m.skeleton.boneMatrices));
    return {
      meshes: o.meshes.length, skinned: skinned.length, joints: skinned.reduce((s, m) => s + m.skeleton.bones.length, 0),
      boneMatrices: bones.flat(), skinnedBox: skinned.length ? [box.min.toArray(), box.max.toArray()] : null,
      clips: o.clips.map((c, i) => clipName(c, i)), time: anim.time, textured: o.textured,
      seams: o.seams ? o.seams.reduce((s, x) => s + x.seams, 0) : 0, borders: o.seams ? o.seams.reduce((s, x) => s + x.borders, 0) : 0,
    };
  });
  viewer.setPlaying = setPlaying;
  // What could not be shown (a texture the browser cannot decode) is said, not hidden.
  if (viewer.warnings.length) {
    $('notes').hidden = false;
    for (const w of viewer.warnings) $('notes').appendChild(Object.assign(document.createElement('li'), { textContent: w }));
  }
  update();
  setPlaying(clipNames.length > 0);
  viewer.ready = true;
  document.body.dataset.ready = 'true';
}

loadScene().then(main).catch((e) => {
  console.error(e);
  showMessage(`qem view: ${e.message}`);
  document.body.dataset.ready = 'error';
});
