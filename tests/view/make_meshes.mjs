// Writes the viewer test's meshes into a folder: an icosphere at three subdivision levels (an LOD
// chain, finest first), a manifest listing them, an ASCII PLY with a per-vertex `distance`
// property (for the heat map), a textured OBJ (UV sphere, .mtl, a red|blue PNG texture in a
// subfolder, a plain green material, and a material whose texture lies outside the folder), a
// vertex-coloured PLY (red above the equator, blue below), an OBJ whose texture is not an
// image, and an OBJ with (deliberately constant) file normals. Usage: node make_meshes.mjs OUT_DIR
import { mkdirSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { encodePng } from './png.mjs';

function icosphere(level) {
  const t = (1 + Math.sqrt(5)) / 2;
  let v = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
           [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]].map(norm);
  let f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
           [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11],
           [6, 2, 10], [8, 6, 7], [9, 8, 1]];
  for (let l = 0; l < level; ++l) {
    const mid = new Map();
    const m = (a, b) => {
      const key = a < b ? `${a},${b}` : `${b},${a}`;
      if (!mid.has(key)) { v.push(norm(v[a].map((x, k) => (x + v[b][k]) / 2))); mid.set(key, v.length - 1); }
      return mid.get(key);
    };
    const g = [];
    for (const [a, b, c] of f) {
      const ab = m(a, b), bc = m(b, c), ca = m(c, a);
      g.push([a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]);
    }
    f = g;
  }
  return { v, f };
}
function norm(p) { const l = Math.hypot(...p); return p.map((x) => x / l); }

const toObj = ({ v, f }) =>
  v.map((p) => `v ${p.join(' ')}`).join('\n') + '\n' + f.map((t) => `f ${t.map((i) => i + 1).join(' ')}`).join('\n') + '\n';

const out = process.argv[2];
if (!out) { console.error('usage: node make_meshes.mjs OUT_DIR'); process.exit(2); }
mkdirSync(out, { recursive: true });
const levels = [3, 2, 1].map((l) => ({ name: `sphere_l${l}.obj`, mesh: icosphere(l) }));
for (const { name, mesh } of levels) writeFileSync(join(out, name), toObj(mesh));
writeFileSync(join(out, 'chain.json'), JSON.stringify({
  levels: levels.map(({ name, mesh }, i) => ({ path: name, faces: mesh.f.length, vertices: mesh.v.length, error: [0, 0.02, 0.08][i] })),
}, null, 2) + '\n');
// Heat map input: distance = height above the equator, so the colours vary smoothly over the sphere.
const { v, f } = icosphere(3);
const ply = ['ply', 'format ascii 1.0', `element vertex ${v.length}`, 'property float x', 'property float y',
  'property float z', 'property float distance', `element face ${f.length}`, 'property list uchar int vertex_indices',
  'end_header', ...v.map((p) => `${p.join(' ')} ${(p[1] + 1) / 2}`), ...f.map((t) => `3 ${t.join(' ')}`)].join('\n') + '\n';
writeFileSync(join(out, 'sphere_distance.ply'), ply);

// Textured: a UV sphere (u = longitude, v = latitude; the u = 0/1 meridian is a UV seam). The
// northern faces use `painted` (texture: left half of the image red, right half blue), the
// southern ones `green` (Kd only), the polar caps `stolen`, whose map_Kd points out of the
// folder and must not be served.
{
  const rings = 16, segs = 32, v = [], vt = [], f = [];
  for (let i = 0; i <= rings; ++i) {
    const lat = Math.PI * (i / rings - 0.5);
    const pole = i === 0 || i === rings;  // one vertex at each pole, so the sphere is closed
    for (let j = 0; j <= segs; ++j) {
      if (j < segs && (!pole || j === 0))
        v.push(pole ? [0, Math.sign(lat), 0] : [Math.cos(lat) * Math.cos((2 * Math.PI * j) / segs), Math.sin(lat), -Math.cos(lat) * Math.sin((2 * Math.PI * j) / segs)]);
      vt.push([j / segs, i / rings]);
    }
  }
  const vi = (i, j) => (i === 0 ? 1 : i === rings ? 2 + (rings - 1) * segs : 2 + (i - 1) * segs + (j % segs));
  const ti = (i, j) => i * (segs + 1) + j + 1;
  const groups = { painted: [], green: [], stolen: [] };
  for (let i = 0; i < rings; ++i)
    for (let j = 0; j < segs; ++j) {
      const q = [[i, j], [i, j + 1], [i + 1, j + 1], [i + 1, j]], c = q.map(([a, b]) => `${vi(a, b)}/${ti(a, b)}`);
      const g = i === 0 || i === rings - 1 ? 'stolen' : i >= rings / 2 ? 'painted' : 'green';
      // At a pole two corners of the quad are the pole itself: one triangle remains.
      for (const t of [[0, 1, 2], [0, 2, 3]])
        if (new Set(t.map((k) => vi(...q[k]))).size === 3) groups[g].push(`f ${t.map((k) => c[k]).join(' ')}`);
    }
  writeFileSync(join(out, 'textured.obj'), ['mtllib textured.mtl', ...v.map((p) => `v ${p.join(' ')}`),
    ...vt.map((t) => `vt ${t.join(' ')}`), ...Object.entries(groups).flatMap(([name, faces]) => [`usemtl ${name}`, ...faces])].join('\n') + '\n');
  writeFileSync(join(out, 'textured.mtl'), ['newmtl painted', 'Kd 1 1 1', 'map_Kd -s 1 1 1 tex/red blue.png',
    'newmtl green', 'Kd 0.1 0.8 0.1', 'newmtl stolen', 'Kd 1 1 1', 'map_Kd ../outside.png', ''].join('\n'));
  mkdirSync(join(out, 'tex'), { recursive: true });
  writeFileSync(join(out, 'tex', 'red blue.png'), encodePng(64, 64, (x) => (x < 32 ? [230, 20, 20] : [20, 40, 230])));
  writeFileSync(join(out, '..', 'outside.png'), encodePng(4, 4, () => [255, 255, 0]));
  // A texture the browser cannot decode: the page draws the material plain and says so.
  writeFileSync(join(out, 'broken.obj'), 'mtllib broken.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl b\nf 1/1 2/2 3/3\n');
  writeFileSync(join(out, 'broken.mtl'), 'newmtl b\nKd 1 1 1\nmap_Kd broken.png\n');
  writeFileSync(join(out, 'broken.png'), 'this is not an image');
}
// Vertex colours: red above the equator, blue below (PLY uchar red/green/blue).
{
  const { v, f } = icosphere(3);
  const col = (p) => (p[1] > 0 ? '220 30 30' : '30 40 220');
  writeFileSync(join(out, 'vcolor.ply'), ['ply', 'format ascii 1.0', `element vertex ${v.length}`, 'property float x',
    'property float y', 'property float z', 'property uchar red', 'property uchar green', 'property uchar blue',
    `element face ${f.length}`, 'property list uchar int vertex_indices', 'end_header',
    ...v.map((p) => `${p.join(' ')} ${col(p)}`), ...f.map((t) => `3 ${t.join(' ')}`)].join('\n') + '\n');
}
// File normals: an icosphere whose `vn` all point along +z (not its true normals), so that a
// page using them shades the whole sphere alike and one computing its own does not.
{
  const { v, f } = icosphere(3);
  writeFileSync(join(out, 'fixed_normals.obj'), [...v.map((p) => `v ${p.join(' ')}`), 'vn 0 0 1',
    ...f.map((t) => `f ${t.map((i) => `${i + 1}//1`).join(' ')}`)].join('\n') + '\n');
}
console.log(`wrote ${levels.length + 12} files to ${out}`);
