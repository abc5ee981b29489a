// End-to-end test of `qem view` in headless Chromium (Debian's /usr/bin/chromium driven by
// playwright-core; no browser download). Starts `qem view` servers on free ports of 127.0.0.1,
// loads the page, moves the LOD slider, toggles shading / wireframe / heat map, orbits and zooms
// with the mouse, checks compare mode and a static export served by a plain HTTP server, and
// checks that every screenshot shows a mesh (decoded with node:zlib, see png.mjs). Also checks
// that Chromium decodes a `qem render` PNG to the pixels the file holds. Appearance: a textured OBJ
// (.mtl, map_Kd) shows its texture and colours and serves no file outside its folder, a
// vertex-coloured PLY its colours, seams and the UV checker overlay; CesiumMan.glb (from
// ../shared/data) loads with its skin and its animation plays, also after `qem simplify`, side by
// side with the original on one clock.
// Env: QEM (the qem binary), MESH_DIR (from make_meshes.mjs), OUT_DIR (screenshots), SHARED_DATA
// (default ../shared/data beside the repository; the CesiumMan tests are skipped without it).
// Prints one line per check and a final `N passed, M failed`; exits non-zero on any failure.
import { spawn, spawnSync } from 'node:child_process';
import { mkdirSync, readFileSync, existsSync, mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { createServer } from 'node:http';
import { tmpdir } from 'node:os';
import { dirname, join, normalize, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { createRequire } from 'node:module';
import { request } from 'node:http';
import { countHue, decodePng, regionStats } from './png.mjs';

// playwright-core is installed in web/node_modules (scripts/install-web-deps.sh), not beside this file.
const here = dirname(fileURLToPath(import.meta.url));
const { chromium } = createRequire(join(here, '..', '..', 'web', 'package.json'))('playwright-core');

const QEM = resolve(process.env.QEM || 'build/qem');
const MESH_DIR = resolve(process.env.MESH_DIR || 'build/web-test/meshes');
const OUT_DIR = resolve(process.env.OUT_DIR || 'build/web-test');
const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
const SHARED_DATA = resolve(process.env.SHARED_DATA || join(here, '..', '..', '..', 'shared', 'data'));
const CESIUM_MAN = join(SHARED_DATA, 'CesiumMan.glb');
const W = 900, H = 600;
// Left panel area, excluded when judging what the canvas shows.
const PANEL_RIGHT = 280;

mkdirSync(OUT_DIR, { recursive: true });
const children = new Set();
let passed = 0, failed = 0, skipped = 0;
class Skip extends Error {}

function killChildren() { for (const c of children) c.kill('SIGTERM'); children.clear(); }
for (const sig of ['SIGINT', 'SIGTERM']) process.on(sig, () => { killChildren(); process.exit(1); });
process.on('exit', killChildren);
// The whole run must stay within a couple of minutes whatever hangs.
setTimeout(() => { console.log('not ok - the test run timed out'); console.log(`${passed} passed, ${failed + 1} failed`); killChildren(); process.exit(1); }, 280000).unref();

function check(cond, what) { if (!cond) throw new Error(what); }

/// Starts `qem view ARGS --port 0` and resolves with its URL (read from its first output line).
function startQem(args) {
  return new Promise((res, rej) => {
    const proc = spawn(QEM, ['view', ...args, '--port', '0'], { cwd: MESH_DIR, stdio: ['ignore', 'pipe', 'pipe'] });
    children.add(proc);
    let out = '', err = '';
    const timer = setTimeout(() => rej(new Error(`qem view did not start: ${out}${err}`)), 30000);
    proc.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/http:\/\/127\.0\.0\.1:(\d+)\//);
      if (m) { clearTimeout(timer); res({ url: m[0], proc, stderr: () => err }); }
    });
    proc.stderr.on('data', (d) => { err += d; });
    proc.on('exit', (code) => { children.delete(proc); clearTimeout(timer); rej(new Error(`qem view exited with ${code}: ${err.trim()}`)); });
  });
}
function stopQem(s) { if (s) { s.proc.kill('SIGTERM'); children.delete(s.proc); } }

/// A plain static file server (not qem), to show an export can be hosted anywhere.
function serveDir(dir) {
  return new Promise((res) => {
    const server = createServer((req, resp) => {
      let p = decodeURIComponent(new URL(req.url, 'http://x').pathname);
      if (p.endsWith('/')) p += 'index.html';
      const file = normalize(join(dir, p));
      if (!file.startsWith(dir) || !existsSync(file)) { resp.writeHead(404); resp.end(); return; }
      const type = file.endsWith('.html') ? 'text/html' : file.endsWith('.js') ? 'text/javascript'
        : file.endsWith('.css') ? 'text/css' : file.endsWith('.json') ? 'application/json'
        : file.endsWith('.png') ? 'image/png' : 'application/octet-stream';
      resp.writeHead(200, { 'Content-Type': type });
      resp.end(readFileSync(file));
    });
    server.listen(0, '127.0.0.1', () => res({ server, url: `http://127.0.0.1:${server.address().port}/` }));
  });
}

async function openViewer(browser, url) {
  const page = await browser.newPage({ viewport: { width: W, height: H } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(url);
  await page.waitForFunction(() => window.qemViewer && (window.qemViewer.ready || window.qemViewer.error), null, { timeout: 30000 });
  const error = await page.evaluate(() => window.qemViewer.error);
  check(!error, `the page reports an error: ${error}`);
  check(errors.length === 0, `page errors: ${errors.join('; ')}`);
  return page;
}

async function shot(page, name) {
  const path = join(OUT_DIR, `${name}.png`);
  await page.screenshot({ path });
  return decodePng(readFileSync(path));
}
const text = (page, id) => page.locator(`#${id}`).innerText();
const canvasStats = (img) => regionStats(img, PANEL_RIGHT, 0, img.width, img.height);
function differs(a, b) {
  let n = 0;
  for (let i = 0; i < a.data.length; i += 4) if (a.data[i] !== b.data[i] || a.data[i + 1] !== b.data[i + 1] || a.data[i + 2] !== b.data[i + 2]) ++n;
  return n;
}

const tests = [];
const test = (name, fn) => tests.push({ name, fn });

test('LOD chain: slider walks the levels, face count and error follow, screenshot not blank', async (ctx) => {
  const page = await openViewer(ctx.browser, ctx.chain.url);
  check(await page.locator('#levels').isVisible(), 'the level slider is hidden');
  check((await text(page, 'face-count')) === '1,280', `faces at level 1: ${await text(page, 'face-count')}`);
  check((await text(page, 'vertex-count')) === '642', `vertices at level 1: ${await text(page, 'vertex-count')}`);
  const a = await shot(page, 'chain-level1');
  const sa = canvasStats(a);
  check(sa.distinct >= 30, `only ${sa.distinct} distinct colours: blank canvas?`);
  check(sa.foreground > 0.1 * sa.pixels, `the mesh covers only ${sa.foreground} of ${sa.pixels} pixels`);
  await page.locator('#level-slider').fill('2');
  check((await text(page, 'face-count')) === '80', `faces at level 3: ${await text(page, 'face-count')}`);
  check((await text(page, 'vertex-count')) === '42', `vertices at level 3: ${await text(page, 'vertex-count')}`);
  check((await text(page, 'error-value')) === '0.0800', `error at level 3: ${await text(page, 'error-value')}`);
  check((await text(page, 'level-index')) === '3 / 3', `level index: ${await text(page, 'level-index')}`);
  const b = await shot(page, 'chain-level3');
  check(canvasStats(b).foreground > 0.1 * sa.pixels, 'level 3 shows nothing');
  check(differs(a, b) > 1000, 'the picture did not change with the level');
  await page.locator('#level-slider').fill('1');
  check((await text(page, 'face-count')) === '320', `faces at level 2: ${await text(page, 'face-count')}`);
  check((await text(page, 'error-value')) === '0.0200', `error at level 2: ${await text(page, 'error-value')}`);
  await page.close();
});

test('shading and wireframe toggles change the picture', async (ctx) => {
  const page = await openViewer(ctx.browser, ctx.chain.url);
  await page.locator('#level-slider').fill('1');
  const flat = await shot(page, 'toggle-flat');
  await page.locator('#shading-smooth').check();
  const smooth = await shot(page, 'toggle-smooth');
  check(differs(flat, smooth) > 1000, 'smooth shading looks like flat shading');
  await page.locator('#wireframe').check();
  const wire = await shot(page, 'toggle-wireframe');
  check(differs(smooth, wire) > 1000, 'the wireframe did not appear');
  // Dark edge pixels: the wireframe is near-black, the shaded sphere is not.
  let dark = 0;
  for (let i = 0; i < wire.data.length; i += 4) if (wire.data[i] + wire.data[i + 1] + wire.data[i + 2] < 200) ++dark;
  check(dark > 500, `only ${dark} dark (edge) pixels`);
  await page.close();
});

test('drag orbits and scroll zooms', async (ctx) => {
  const page = await openViewer(ctx.browser, ctx.chain.url);
  await page.locator('#level-slider').fill('2');  // few big faces: a rotation is easy to see
  const before = await shot(page, 'orbit-before');
  await page.mouse.move(600, 300);
  await page.mouse.down();
  await page.mouse.move(700, 340, { steps: 8 });
  await page.mouse.up();
  const after = await shot(page, 'orbit-after');
  check(differs(before, after) > 1000, 'dragging did not rotate the view');
  const f0 = canvasStats(after).foreground;
  await page.mouse.move(600, 300);
  for (let i = 0; i < 5; ++i) await page.mouse.wheel(0, -200);
  await page.waitForTimeout(300);  // OrbitControls zooms on the next frames
  const zoomed = await shot(page, 'zoom-in');
  const f1 = canvasStats(zoomed).foreground;
  check(f1 > f0 * 1.2, `zooming in did not enlarge the mesh (${f0} -> ${f1} pixels)`);
  await page.close();
});

test('heat map: a mesh with a distance property is coloured, with a legend and a toggle', async (ctx) => {
  const page = await openViewer(ctx.browser, ctx.heat.url);
  check(await page.locator('#legend').isVisible(), 'no legend');
  check(await page.locator('#heatmap-toggle').isVisible(), 'no heat map toggle');
  check(!(await page.locator('#levels').isVisible()), 'a single mesh shows a level slider');
  const legendMax = await text(page, 'legend-max');
  check(legendMax === '1.00', `legend max ${legendMax}, expected 1.00`);
  const on = await shot(page, 'heatmap-on');
  const son = regionStats(on, PANEL_RIGHT, 0, W - 80, H);
  check(son.saturated > 0.05 * son.pixels, `only ${son.saturated} coloured pixels with the heat map on`);
  await page.locator('#heatmap').uncheck();
  check(!(await page.locator('#legend').isVisible()), 'the legend stays when the heat map is off');
  const off = await shot(page, 'heatmap-off');
  const soff = regionStats(off, PANEL_RIGHT, 0, W - 80, H);
  check(soff.saturated < son.saturated / 10, `still ${soff.saturated} coloured pixels with the heat map off`);
  await page.close();
});

test('compare: original and simplified side by side, both drawn, labelled with their counts', async (ctx) => {
  const page = await openViewer(ctx.browser, ctx.compare.url);
  const l0 = await text(page, 'label-0'), l1 = await text(page, 'label-1');
  check(l0.includes('1,280 faces') && l0.includes('Original'), `left label: ${l0}`);
  check(l1.includes('80 faces') && l1.includes('Simplified'), `right label: ${l1}`);
  check((await text(page, 'face-count')) === '80', 'the panel does not describe the simplified mesh');
  check(!(await page.locator('#levels').isVisible()), 'compare mode shows a level slider');
  const img = await shot(page, 'compare');
  const left = regionStats(img, PANEL_RIGHT, 60, W / 2, H), right = regionStats(img, W / 2, 60, W, H);
  check(left.foreground > 0.05 * left.pixels, `left half nearly empty (${left.foreground} pixels)`);
  check(right.foreground > 0.05 * right.pixels, `right half nearly empty (${right.foreground} pixels)`);
  // Linked cameras: one drag turns both meshes.
  await page.mouse.move(W * 0.75, H / 2);
  await page.mouse.down();
  await page.mouse.move(W * 0.75 + 120, H / 2 + 30, { steps: 8 });
  await page.mouse.up();
  const img2 = await shot(page, 'compare-orbit');
  const changedLeft = differs({ data: img.data.subarray(0, img.data.length) }, { data: img2.data });
  check(changedLeft > 1000, 'the drag did not change the view');
  let leftChanged = 0;
  for (let y = 60; y < H; ++y) for (let x = PANEL_RIGHT; x < W / 2; ++x) { const o = (y * W + x) * 4; if (img.data[o] !== img2.data[o]) ++leftChanged; }
  check(leftChanged > 500, 'dragging on the right did not turn the left view: cameras not linked');
  await page.close();
});

test('static export: qem view --export writes a page that any HTTP server can host', async (ctx) => {
  const dir = mkdtempSync(join(tmpdir(), 'qem-export-'));
  try {
    const r = spawnSync(QEM, ['view', 'chain.json', '--export', dir], { cwd: MESH_DIR, encoding: 'utf8' });
    check(r.status === 0, `qem view --export failed: ${r.stderr}`);
    for (const f of ['index.html', 'app.js', 'style.css', 'data/scene.json', 'data/level0.pos.f32', 'data/level2.idx.u32'])
      check(existsSync(join(dir, f)), `${f} missing from the export`);
    const scene = JSON.parse(readFileSync(join(dir, 'data/scene.json'), 'utf8'));
    check(scene.levels.map((l) => l.faces).join() === '1280,320,80', `levels ${scene.levels.map((l) => l.faces)}`);
    const { server, url } = await serveDir(dir);
    try {
      const page = await openViewer(ctx.browser, url);
      check((await text(page, 'face-count')) === '1,280', 'wrong face count from the export');
      const s = canvasStats(await shot(page, 'export'));
      check(s.distinct >= 30 && s.foreground > 0.1 * s.pixels, 'the exported page shows nothing');
      await page.close();
    } finally { server.close(); }
  } finally { rmSync(dir, { recursive: true, force: true }); }
});

test('several meshes on the command line form a chain; errors are measured when not given', async (ctx) => {
  const s = await startQem(['sphere_l3.obj', 'sphere_l2.obj', 'sphere_l1.obj', '--chain']);
  try {
    const page = await openViewer(ctx.browser, s.url);
    check((await text(page, 'error-value')) === '0', `level 1 error ${await text(page, 'error-value')}`);
    await page.locator('#level-slider').fill('2');
    const e = Number(await text(page, 'error-value'));
    // Icosphere level 1 vs level 3 (unit sphere): the Hausdorff distance is about 0.1.
    check(e > 0.03 && e < 0.3, `measured error ${e} out of the plausible range`);
    await page.close();
  } finally { stopQem(s); }
});

test('qem render: Chromium reads its PNG and sees the same pixels', async (ctx) => {
  const dir = mkdtempSync(join(tmpdir(), 'qem-render-'));
  try {
    const file = join(dir, 'render.png');
    const r = spawnSync(QEM, ['render', 'sphere_distance.ply', file, '--width', '160', '--height', '120'],
      { cwd: MESH_DIR, encoding: 'utf8' });
    check(r.status === 0, `qem render failed: ${r.stderr}`);
    const bytes = readFileSync(file), want = decodePng(bytes);
    const page = await ctx.browser.newPage();
    await page.setContent(`<img src="data:image/png;base64,${bytes.toString('base64')}">`);
    const got = await page.evaluate(async () => {
      const img = document.querySelector('img');
      await img.decode();
      const c = document.createElement('canvas');
      c.width = img.naturalWidth; c.height = img.naturalHeight;
      const g = c.getContext('2d');
      g.drawImage(img, 0, 0);
      return { width: c.width, height: c.height, data: Array.from(g.getImageData(0, 0, c.width, c.height).data) };
    });
    await page.close();
    check(got.width === 160 && got.height === 120, `Chromium sees a ${got.width}x${got.height} picture`);
    const wrong = differs(want, { data: got.data });
    check(wrong === 0, `${wrong} pixels differ between Chromium's decoding and the file's`);
    check(regionStats(want).saturated > 500, 'the heat map is missing from the picture');
  } finally { rmSync(dir, { recursive: true, force: true }); }
});


/// GET of a raw request path (not normalised, so `..` and `%2e%2e` reach the server as written).
function rawGet(url, path) {
  return new Promise((res, rej) => {
    const u = new URL(url);
    const req = request({ host: u.hostname, port: u.port, path, method: 'GET' }, (resp) => {
      const chunks = [];
      resp.on('data', (c) => chunks.push(c));
      resp.on('end', () => res({ status: resp.statusCode, type: resp.headers['content-type'], body: Buffer.concat(chunks) }));
    });
    req.on('error', rej);
    req.end();
  });
}
const inspect = (page) => page.evaluate(() => window.qemViewer.inspect());
// Largest absolute difference between two equally long number arrays.
const maxDiff = (a, b) => a.reduce((m, x, i) => Math.max(m, Math.abs(x - b[i])), 0);
function needCesiumMan() { if (!existsSync(CESIUM_MAN)) throw new Skip(`${CESIUM_MAN} not found`); }

test('textured OBJ: map_Kd texture and Kd colours are drawn, only files inside its folder are served', async (ctx) => {
  const s = await startQem(['textured.obj']);
  try {
    const page = await openViewer(ctx.browser, s.url);
    const warning = "texture '../outside.png' not shown: a path outside the model's folder";
    for (let i = 0; i < 20 && !s.stderr().includes(warning); ++i) await page.waitForTimeout(100);  // stderr may trail stdout
    check(s.stderr().includes(warning), `no warning for the outside texture: ${s.stderr()}`);
    const info = (await inspect(page))[0];
    check(info.textured, 'the page reports no texture');
    const img = await shot(page, 'textured-obj');
    // The texture is red on its left half and blue on its right; the southern faces are Kd green.
    const red = countHue(img, 0, PANEL_RIGHT), blue = countHue(img, 2, PANEL_RIGHT), green = countHue(img, 1, PANEL_RIGHT);
    check(red > 2000 && blue > 2000, `texture not drawn: ${red} red and ${blue} blue pixels`);
    check(green > 2000, `Kd colour not drawn: ${green} green pixels`);
    // The UV checker replaces the texture; seams (the u = 0/1 meridian, material borders) show.
    await page.locator('#uv-checker').check();
    const checker = await shot(page, 'textured-obj-uv-checker');
    check(differs(img, checker) > 5000, 'the UV checker did not change the picture');
    await page.locator('#uv-checker').uncheck();
    await page.locator('#seams').check();
    const seams = await shot(page, 'textured-obj-seams');
    const after = (await inspect(page))[0];
    check(after.seams >= 16 && after.borders === 0, `seams ${after.seams}, borders ${after.borders}`);
    check((await text(page, 'seam-count')).includes('edges'), 'the seam count is not shown');
    check(differs(img, seams) > 200, 'the seam overlay did not appear');
    await page.close();
    const tex = await rawGet(s.url, '/data/level0/tex/red%20blue.png');
    check(tex.status === 200 && tex.type === 'image/png' && tex.body.length > 50, `texture request: ${tex.status} ${tex.type}`);
    for (const path of ['/data/level0/../../outside.png', '/data/level0/%2e%2e/%2e%2e/outside.png', '/data/outside.png', '/data/level0/textured.mtl'])
      check((await rawGet(s.url, path)).status === 404, `${path} was served`);
  } finally { stopQem(s); }
});

test('a texture the browser cannot decode: the model is drawn plain and the panel says why', async (ctx) => {
  const s = await startQem(['broken.obj']);
  try {
    const page = await openViewer(ctx.browser, s.url);
    check(await page.locator('#notes').isVisible(), 'no note in the panel');
    const note = await text(page, 'notes');
    check(note.includes('broken.png') && note.includes('could not be loaded'), `note: ${note}`);
    const st = canvasStats(await shot(page, 'broken-texture'));
    check(st.foreground > 1000, 'the model is not drawn');
    await page.close();
  } finally { stopQem(s); }
});

test('file normals: used with smooth shading, the default when a file has them', async (ctx) => {
  const s = await startQem(['fixed_normals.obj']);
  try {
    const page = await openViewer(ctx.browser, s.url);
    check(await page.locator('#shading-smooth').isChecked(), 'smooth shading is not the default for a file with normals');
    // Every normal is +z: every pixel of the sphere gets one shade (up to antialiased edges).
    const img = await shot(page, 'file-normals');
    const shades = new Map();
    for (let y = 0; y < H; ++y)
      for (let x = PANEL_RIGHT; x < W; ++x) {
        const o = (y * W + x) * 4, k = (img.data[o] << 16) | (img.data[o + 1] << 8) | img.data[o + 2];
        if (Math.abs(img.data[o] - 245) + Math.abs(img.data[o + 1] - 245) + Math.abs(img.data[o + 2] - 245) > 24) shades.set(k, (shades.get(k) || 0) + 1);
      }
    const total = [...shades.values()].reduce((a, b) => a + b, 0), top = Math.max(...shades.values());
    check(total > 5000 && top > 0.8 * total, `the file normals are not used: the most common shade covers ${top} of ${total} pixels`);
    await page.locator('#shading-flat').check();  // flat: by the faces, many shades
    const flat = await shot(page, 'file-normals-flat');
    check(canvasStats(flat).distinct > 50, 'flat shading ignores the faces');
    await page.close();
  } finally { stopQem(s); }
});

test('vertex colours: a coloured PLY is drawn in its colours', async (ctx) => {
  const s = await startQem(['vcolor.ply']);
  try {
    const page = await openViewer(ctx.browser, s.url);
    const img = await shot(page, 'vertex-colours');
    // Red above the equator, blue below, from the default view (pitched 20 degrees down).
    const red = countHue(img, 0, PANEL_RIGHT), blue = countHue(img, 2, PANEL_RIGHT);
    check(red > 5000 && blue > 2000, `colours not drawn: ${red} red and ${blue} blue pixels`);
    await page.close();
  } finally { stopQem(s); }
});

test('export: textures go with the page and nothing outside the model folder does', async (ctx) => {
  const dir = mkdtempSync(join(tmpdir(), 'qem-export-tex-'));
  try {
    const r = spawnSync(QEM, ['view', 'textured.obj', '--export', dir], { cwd: MESH_DIR, encoding: 'utf8' });
    check(r.status === 0, `qem view --export failed: ${r.stderr}`);
    check(existsSync(join(dir, 'data/level0/tex/red blue.png')), 'the texture is missing from the export');
    check(!existsSync(join(dir, 'outside.png')) && !existsSync(join(dir, 'data/outside.png')), 'a file outside the model folder was exported');
    const { server, url } = await serveDir(dir);
    try {
      const page = await openViewer(ctx.browser, url);
      const img = await shot(page, 'export-textured');
      check(countHue(img, 0, PANEL_RIGHT) > 2000, 'the exported page does not draw the texture');
      await page.close();
    } finally { server.close(); }
  } finally { rmSync(dir, { recursive: true, force: true }); }
});

// Two inspections of a playing animation some frames apart: the skin must have moved.
async function checkPlays(page, what) {
  const a = await inspect(page);
  await page.waitForFunction((r) => window.qemViewer.renders > r + 10, await page.evaluate(() => window.qemViewer.renders), { timeout: 20000 });
  const b = await inspect(page);
  a.forEach((va, i) => {
    const vb = b[i];
    check(vb.time > va.time, `${what}: the animation clock did not advance (${va.time} -> ${vb.time})`);
    check(maxDiff(va.boneMatrices, vb.boneMatrices) > 1e-3, `${what}, view ${i}: the bone matrices did not change`);
    check(maxDiff(va.skinnedBox.flat(), vb.skinnedBox.flat()) > 1e-4, `${what}, view ${i}: the skinned bounds did not change`);
  });
  return b;
}

test('glTF: CesiumMan loads with its skin and texture, and its animation plays and pauses', async (ctx) => {
  needCesiumMan();
  const s = await startQem([CESIUM_MAN]);
  try {
    const page = await openViewer(ctx.browser, s.url);
    const [info] = await inspect(page);
    check(info.skinned >= 1 && info.joints >= 10, `skinned meshes ${info.skinned}, joints ${info.joints}`);
    check(info.textured, 'CesiumMan has no texture in the page');
    check(info.clips.length >= 1, 'no animation clip');
    check(await page.locator('#animation').isVisible(), 'no animation controls');
    await checkPlays(page, 'CesiumMan');
    const img = await shot(page, 'cesium-man');
    const st = canvasStats(img);
    check(st.distinct >= 100 && st.foreground > 0.03 * st.pixels, `CesiumMan not drawn (${st.distinct} colours, ${st.foreground} pixels)`);
    await page.locator('#play').click();  // pause: the pose holds
    const p0 = await inspect(page);
    await page.waitForTimeout(300);
    const p1 = await inspect(page);
    check(p0[0].time === p1[0].time && maxDiff(p0[0].boneMatrices, p1[0].boneMatrices) === 0, 'the animation runs while paused');
    await page.locator('#seams').check();
    const seams = (await inspect(page))[0];
    check(seams.seams + seams.borders > 50, `only ${seams.seams} seam and ${seams.borders} border edges on CesiumMan`);
    await page.close();
  } finally { stopQem(s); }
});

test('glTF: CesiumMan simplified by `qem simplify --ratio 0.5` keeps its skin and plays beside the original', async (ctx) => {
  needCesiumMan();
  const dir = mkdtempSync(join(tmpdir(), 'qem-cesium-'));
  let s;
  try {
    const out = join(dir, 'CesiumMan_half.glb');
    const r = spawnSync(QEM, ['simplify', CESIUM_MAN, out, '--ratio', '0.5'], { encoding: 'utf8' });
    check(r.status === 0, `qem simplify failed: ${r.stderr}`);
    s = await startQem([CESIUM_MAN, out]);  // two models: side by side
    const page = await openViewer(ctx.browser, s.url);
    const l0 = await text(page, 'label-0'), l1 = await text(page, 'label-1');
    const faces = (l) => Number(l.match(/([\d,]+) faces/)[1].replace(/,/g, ''));
    check(faces(l1) < 0.6 * faces(l0), `not simplified: ${l0} | ${l1}`);
    const [orig, simp] = await inspect(page);
    check(simp.skinned >= 1 && simp.joints === orig.joints, `the simplified model lost its skin (${simp.skinned} skinned, ${simp.joints} of ${orig.joints} joints)`);
    check(simp.textured, 'the simplified model lost its texture');
    check(simp.clips.join() === orig.clips.join(), `clips ${simp.clips} vs ${orig.clips}`);
    const b = await checkPlays(page, 'original and simplified CesiumMan');
    // One clock and one skeleton: both sides hold the same pose at every moment.
    check(maxDiff(b[0].boneMatrices, b[1].boneMatrices) < 1e-4, 'the two sides are not in step');
    const img = await shot(page, 'cesium-man-compare');
    const left = regionStats(img, PANEL_RIGHT, 60, W / 2, H), right = regionStats(img, W / 2, 60, W, H);
    check(left.foreground > 0.02 * left.pixels && right.foreground > 0.02 * right.pixels, 'a side is empty');
    await page.close();
  } finally { stopQem(s); rmSync(dir, { recursive: true, force: true }); }
});

test('mixed formats side by side: CesiumMan.glb beside an OBJ simplified from it, in one frame', async (ctx) => {
  needCesiumMan();
  const dir = mkdtempSync(join(tmpdir(), 'qem-mixed-'));
  let s;
  try {
    const obj = join(dir, 'half.obj');
    const r = spawnSync(QEM, ['simplify', CESIUM_MAN, obj, '--ratio', '0.5'], { encoding: 'utf8' });
    check(r.status === 0, `qem simplify failed: ${r.stderr}`);
    s = await startQem([CESIUM_MAN, obj]);
    const page = await openViewer(ctx.browser, s.url);
    await page.evaluate(() => window.qemViewer.setPlaying(false));
    // The panel folds away so that it does not cover the left model.
    await page.locator('#panel-toggle').click();
    check(!(await page.locator('#stats').isVisible()), 'the panel did not fold');
    const img = await shot(page, 'mixed-formats');
    // Both drawn, at the same height and size: the glTF is placed in qem's frame like the OBJ.
    const rows = (x0, x1) => {
      let top = H, bottom = -1;
      for (let y = 0; y < H - 50; ++y)
        for (let x = x0; x < x1; ++x) {
          const o = (y * W + x) * 4;
          if (Math.abs(img.data[o] - 245) + Math.abs(img.data[o + 1] - 245) + Math.abs(img.data[o + 2] - 245) > 24) { top = Math.min(top, y); bottom = y; break; }
        }
      return [top, bottom];
    };
    const [t0, b0] = rows(0, W / 2), [t1, b1] = rows(W / 2, W);
    check(b0 > t0 + 100 && b1 > t1 + 100, `a side is empty (rows ${t0}-${b0} and ${t1}-${b1})`);
    check(Math.abs((t0 + b0) - (t1 + b1)) / 2 < 0.15 * H, `the two sides are not in one frame (rows ${t0}-${b0} and ${t1}-${b1})`);
    const [glb, flat] = await inspect(page);
    check(glb.skinned >= 1 && flat.skinned === 0 && flat.meshes === 1, 'the sides are not the glTF and the OBJ');
    await page.close();
  } finally { stopQem(s); rmSync(dir, { recursive: true, force: true }); }
});

/// Splits a .glb into a .gltf with its buffer and images as files beside it (the images in a
/// subfolder, with a space in their names), as many exporters write them.
function splitGlb(glb, dir, stem) {
  const jsonLength = glb.readUInt32LE(12), doc = JSON.parse(glb.subarray(20, 20 + jsonLength).toString('utf8'));
  const binStart = 20 + jsonLength + 8, bin = glb.subarray(binStart, binStart + glb.readUInt32LE(20 + jsonLength));
  mkdirSync(join(dir, 'tex'), { recursive: true });
  (doc.images || []).forEach((img, i) => {
    const view = doc.bufferViews[img.bufferView], off = view.byteOffset || 0;
    const name = `skin ${i}.${img.mimeType === 'image/jpeg' ? 'jpg' : 'png'}`;
    writeFileSync(join(dir, 'tex', name), bin.subarray(off, off + view.byteLength));
    delete img.bufferView; delete img.mimeType;
    img.uri = `tex/${encodeURIComponent(name)}`;
  });
  writeFileSync(join(dir, `${stem}.bin`), bin);
  doc.buffers[0].uri = `${stem}.bin`;
  writeFileSync(join(dir, `${stem}.gltf`), JSON.stringify(doc));
  return join(dir, `${stem}.gltf`);
}

test('glTF with external files: a .gltf, its .bin and its images in a subfolder are served and drawn', async (ctx) => {
  needCesiumMan();
  const dir = mkdtempSync(join(tmpdir(), 'qem-gltf-'));
  let s;
  try {
    const gltf = splitGlb(readFileSync(CESIUM_MAN), dir, 'CesiumMan');
    s = await startQem([gltf]);
    const page = await openViewer(ctx.browser, s.url);
    const [info] = await inspect(page);
    check(info.skinned >= 1 && info.textured, `skinned ${info.skinned}, textured ${info.textured}`);
    const tex = await rawGet(s.url, '/data/level0/tex/skin%200.jpg');
    const png = await rawGet(s.url, '/data/level0/tex/skin%200.png');
    check(tex.status === 200 || png.status === 200, 'the image beside the .gltf is not served');
    check((await rawGet(s.url, '/data/level0/CesiumMan.bin')).status === 200, 'the .bin is not served');
    await checkPlays(page, 'CesiumMan.gltf');
    await page.close();
  } finally { stopQem(s); rmSync(dir, { recursive: true, force: true }); }
});

async function run() {
  for (const [bin, what] of [[QEM, 'the qem binary (build it first)'], [CHROMIUM, 'Chromium (scripts/install-web-deps.sh)']])
    if (!existsSync(bin)) { console.log(`not ok - ${what} not found at ${bin}`); console.log('0 passed, 1 failed'); process.exit(1); }
  const ctx = {};
  const userDataDir = mkdtempSync(join(tmpdir(), 'qem-chromium-'));
  let browser;
  try {
    [ctx.chain, ctx.heat, ctx.compare] = await Promise.all([
      startQem(['chain.json']), startQem(['sphere_distance.ply']), startQem(['--compare', 'sphere_l3.obj', 'sphere_l1.obj']),
    ]);
    const context = await chromium.launchPersistentContext(userDataDir, {
      executablePath: CHROMIUM,
      headless: true,
      viewport: { width: W, height: H },
      args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
        '--disable-component-update', '--disable-sync', '--enable-unsafe-swiftshader'],
    });
    browser = context;
    ctx.browser = context;
    for (const t of tests) {
      try {
        await t.fn(ctx);
        ++passed;
        console.log(`ok - ${t.name}`);
      } catch (e) {
        if (e instanceof Skip) { ++skipped; console.log(`skip - ${t.name}: ${e.message}`); continue; }
        ++failed;
        console.log(`not ok - ${t.name}: ${e.message.split('\n')[0]}`);
      }
    }
  } catch (e) {
    ++failed;
    console.log(`not ok - setup: ${e.message.split('\n')[0]}`);
  } finally {
    if (browser) await browser.close().catch(() => {});
    for (const s of [ctx.chain, ctx.heat, ctx.compare]) stopQem(s);
    rmSync(userDataDir, { recursive: true, force: true });
  }
  console.log(`screenshots in ${OUT_DIR}`);
  console.log(`${passed} passed, ${failed} failed${skipped ? `, ${skipped} skipped` : ''}`);
  process.exit(failed ? 1 : 0);
}

run();
