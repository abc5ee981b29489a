#!/usr/bin/env python3
# A mesh with a smooth vertex colour field, for the far-place repair's cost with colours
# (docs/benchmarks.md, "Far places"): the positions and faces of any mesh ../shared/bench can read,
# red = 0.5 + 0.5 sin(6x + 2y), green = y, blue = 0.5 + 0.5 cos(9z) over its box (x, y, z in [0, 1]).
# Binary PLY: float x y z, uchar red green blue.   bench/coloured_mesh.py IN OUT.ply
import math, os, struct, sys
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'shared', 'bench'))
from make_meshes import read_mesh  # noqa: E402

verts, tris = read_mesh(sys.argv[1])[:2]
lo = [min(v[k] for v in verts) for k in range(3)]
hi = [max(v[k] for v in verts) for k in range(3)]
with open(sys.argv[2], 'wb') as f:
    f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\nproperty float x\n"
             "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
             f"property uchar blue\nelement face {len(tris)}\nproperty list uchar int vertex_indices\n"
             "end_header\n").encode())
    for v in verts:
        t = [(v[k] - lo[k]) / ((hi[k] - lo[k]) or 1) for k in range(3)]
        c = (0.5 + 0.5 * math.sin(6 * t[0] + 2 * t[1]), t[1], 0.5 + 0.5 * math.cos(9 * t[2]))
        f.write(struct.pack('<3f3B', *v[:3], *(int(255 * x) for x in c)))
    for t in tris:
        f.write(struct.pack('<B3i', 3, *t))
