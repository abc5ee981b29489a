// The UV checker texture: square cells whose colour changes across the atlas, so stretching,
// flipped charts and where a UV seam cuts the surface show at a glance.
import * as THREE from 'three';

export function checkerTexture(cells = 16, size = 512) {
  const canvas = document.createElement('canvas');
  canvas.width = canvas.height = size;
  const g = canvas.getContext('2d');
  const s = size / cells;
  for (let y = 0; y < cells; ++y)
    for (let x = 0; x < cells; ++x) {
      // Hue across u, lightness across v: a cell's colour tells where in the atlas it is.
      const hue = Math.round((360 * x) / cells), light = (x + y) % 2 ? 30 + (40 * y) / cells : 85;
      g.fillStyle = `hsl(${hue}, 75%, ${light}%)`;
      g.fillRect(x * s, y * s, s, s);
    }
  const t = new THREE.CanvasTexture(canvas);
  t.colorSpace = THREE.SRGBColorSpace;
  t.wrapS = t.wrapT = THREE.RepeatWrapping;
  t.anisotropy = 4;
  return t;
}
