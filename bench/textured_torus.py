#!/usr/bin/env python3
# A textured, coloured torus for the partitioned run with attributes (docs/benchmarks.md,
# "Partitioned, with attributes"): 32 UV charts (8 around x 4 across), each with its own vertices
# (chart borders are UV seams), smooth vertex colours, relief at two scales. Binary PLY: float
# x y z u v, uchar red green blue.   bench/textured_torus.py CELLS_AROUND CELLS_ACROSS OUT.ply
import math, struct, sys
N, M = int(sys.argv[1]), int(sys.argv[2])  # cells around, across (faces = 2 N M)
CA, CB = 8, 4
out = sys.argv[3]
R, r0 = 1.0, 0.35
verts = bytearray(); faces = bytearray()
nv = 0
pack_v = struct.Struct('<5f3B').pack
pack_f = struct.Struct('<B3I').pack
ca, cb = N // CA, M // CB
for a in range(CA):
    for b in range(CB):
        base = nv
        for i in range(ca + 1):
            gi = a * ca + i
            th = 2 * math.pi * (gi % N) / N
            for j in range(cb + 1):
                gj = b * cb + j
                ph = 2 * math.pi * (gj % M) / M
                rr = r0 * (1 + 0.08 * math.sin(7 * th) * math.sin(5 * ph) + 0.03 * math.sin(23 * th + 11 * ph))
                x = (R + rr * math.cos(ph)) * math.cos(th)
                y = (R + rr * math.cos(ph)) * math.sin(th)
                z = rr * math.sin(ph)
                u = (a + 0.05 + 0.9 * i / ca) / CA
                v = (b + 0.05 + 0.9 * j / cb) / CB
                cr = int(127.5 + 120 * math.sin(3 * th))
                cg = int(127.5 + 120 * math.cos(2 * ph + th))
                cbv = int(127.5 + 120 * math.sin(5 * th + 3 * ph))
                verts += pack_v(x, y, z, u, v, cr, cg, cbv)
        nv += (ca + 1) * (cb + 1)
        for i in range(ca):
            for j in range(cb):
                p = base + i * (cb + 1) + j
                q = p + cb + 1
                faces += pack_f(3, p, q, p + 1)
                faces += pack_f(3, p + 1, q, q + 1)
nf = len(faces) // 13
hdr = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
       "property float u\nproperty float v\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
       "element face %d\nproperty list uchar uint vertex_indices\nend_header\n") % (nv, nf)
with open(out, 'wb') as f:
    f.write(hdr.encode()); f.write(verts); f.write(faces)
print(nv, nf)
