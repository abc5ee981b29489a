// Seam edges of a mesh, for the viewer's seam overlay. A seam is where the surface continues but
// its attributes jump: the mesh stores one vertex per side (a "wedge", as glTF and OBJ's
// face-varying indices do), at the same position with different UVs, normals or colours. Welding
// the vertices by position shows them: an edge between two welded positions is a seam when the
// two faces that share it use different attribute values at an end (or different materials), and
// a border when only one face has it (several faces: non-manifold, shown too).
import * as THREE from 'three';

// Attributes whose jumps make a seam (glTF/three names).
const SEAM_ATTRIBUTES = ['normal', 'uv', 'color'];
// Attribute values closer than this are one value (float noise from the writers).
const SAME = 1e-5;

/**
 * @param {THREE.BufferGeometry} geometry
 * @param {ArrayLike<number>|null} faceMaterials material of each triangle, or null
 * @returns {{pairs: Uint32Array, seams: number, borders: number}} vertex index pairs, two per edge
 */
export function seamEdges(geometry, faceMaterials = null) {
  const pos = geometry.getAttribute('position');
  const n = pos.count;
  const weld = new Uint32Array(n);
  const first = new Map();
  for (let i = 0; i < n; ++i) {
    const k = `${pos.getX(i)},${pos.getY(i)},${pos.getZ(i)}`;
    const w = first.get(k);
    if (w === undefined) { first.set(k, i); weld[i] = i; } else weld[i] = w;
  }
  const attrs = SEAM_ATTRIBUTES.map((a) => geometry.getAttribute(a)).filter(Boolean);
  const same = (a, b) => {
    if (a === b) return true;
    for (const at of attrs)
      for (let c = 0; c < at.itemSize; ++c)
        if (Math.abs(at.getComponent(a, c) - at.getComponent(b, c)) > SAME) return false;
    return true;
  };
  const index = geometry.getIndex();
  const corners = index ? index.count : n;
  const corner = index ? (i) => index.getX(i) : (i) => i;
  // Edge key: the two welded ends, smaller first (n^2 < 2^53 for any mesh a browser can hold).
  const edges = new Map();
  for (let f = 0; f < corners / 3; ++f)
    for (let e = 0; e < 3; ++e) {
      const a = corner(3 * f + e), b = corner(3 * f + ((e + 1) % 3));
      const wa = weld[a], wb = weld[b];
      if (wa === wb) continue;
      const key = wa < wb ? wa * n + wb : wb * n + wa;
      const list = edges.get(key);
      if (list) list.push(a, b, f); else edges.set(key, [a, b, f]);
    }
  const out = [];
  let seams = 0, borders = 0;
  for (const l of edges.values()) {
    if (l.length !== 6) { out.push(l[0], l[1]); ++borders; continue; }
    const [a1, b1, f1, a2, b2, f2] = l;
    // The second face's corner at a1's position, and at b1's.
    const [p, q] = weld[a2] === weld[a1] ? [a2, b2] : [b2, a2];
    if (!same(a1, p) || !same(b1, q) || (faceMaterials && faceMaterials[f1] !== faceMaterials[f2])) {
      out.push(a1, b1);
      ++seams;
    }
  }
  return { pairs: Uint32Array.from(out), seams, borders };
}

/**
 * A line overlay of a mesh's seams and borders, as a child of the mesh (so it shares its
 * transform). For a skinned mesh the line follows the skin: update() moves its ends with the
 * bones (three's getVertexPosition applies them), once per animation frame.
 */
export class SeamOverlay {
  constructor(mesh, faceMaterials, material) {
    this.mesh = mesh;
    const { pairs, seams, borders } = seamEdges(mesh.geometry, faceMaterials);
    this.pairs = pairs;
    this.seams = seams;
    this.borders = borders;
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pairs.length * 3), 3));
    this.line = new THREE.LineSegments(g, material);
    this.line.frustumCulled = false;
    this.line.renderOrder = 2;
    mesh.add(this.line);
    this.update();
  }
  get skinned() { return !!this.mesh.isSkinnedMesh; }
  update() {
    const attr = this.line.geometry.getAttribute('position');
    const v = new THREE.Vector3();
    for (let i = 0; i < this.pairs.length; ++i) {
      this.mesh.getVertexPosition(this.pairs[i], v);
      attr.setXYZ(i, v.x, v.y, v.z);
    }
    attr.needsUpdate = true;
  }
}
