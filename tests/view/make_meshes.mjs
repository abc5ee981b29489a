// Writes the viewer test's meshes into a folder: an icosphere at three subdivision levels (an LOD
// chain, finest first), a manifest listing them, and an ASCII PLY with a per-vertex `distance`
// property (for the heat map). Usage: node make_meshes.mjs OUT_DIR
import { mkdirSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';

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
console.log(`wrote ${levels.length + 2} files to ${out}`);
