#!/usr/bin/python3
"""qem against meshoptimizer's simplifyWithAttributes (and `gltf-transform simplify`) on the
textured and coloured assets of ../shared/data: one table of E ratios, UV / normal / colour errors
and seam cracks, measured by `qem measure` and cross-checked with attr_metric.py.

usage: bench/attr_compare.py [--qem build/qem] [--peer /tmp/jspeer] [--out DIR] [--ratios 0.5,0.1,0.01]
                             [--assets a,b,...] [--qem-arg ARG ...] [--no-check] [--samples N]
                             [--size-tol 0.01]

Equal size: the goal is a lower error at the same face count, so when qem's output and
meshoptimizer's differ by more than --size-tol (1 %, either way; both are asked for the same target,
but a tool that cannot reach it stops where its rules do), qem is run again with `-f` set to
meshoptimizer's face count and the row is judged on that output ("qem at peer size"; on a glTF
document, whose measured count includes every instance of a mesh, -f is corrected up to four
times, by the reached/asked ratio and then along the line through the last two tries). The faces
column then reads "qem asked / qem at peer size / meshopt / gltft" and "E q/m asked" keeps the first run's E ratio; every other qem column is the judged output. If qem
cannot reach the peer's size (it stops above it), the faces column marks it with "!" and the row
does not meet the goal (a larger mesh's lower error proves nothing); the summary lists it. E q/g compares
the first qem run with gltf-transform (both asked for the same target).

The peer folder is a copy of ../shared/bench/peers/js after `npm ci` (it holds
peer_meshopt_attr.mjs and node_modules/.bin/gltf-transform). Every run's numbers go to
DIR/rows.jsonl; the peers' outputs and measurements are cached in DIR (keyed by asset, ratio and
tool), so a sweep over qem's options (--qem-arg) re-runs and re-measures qem only.

Inputs: each tool reads the file itself where it can. The peer script reads .glb and .obj (v/vt/vn)
but no vertex colours and no materials in OBJ and no attributes in PLY, so the PLY assets and the
vertex-coloured OBJ are given to the peers as a .glb written here from qem's lossless OBJ copy
(one primitive per material, i.e. per face colour; COLOR_0, NORMAL, TEXCOORD_0 as float). qem and
both metrics always read the original file. On .glb files qem keeps the document (one error budget
shared by the primitives); the peers simplify each primitive to the same fraction and keep the
document.
"""
import argparse
import json
import math
import os
import struct
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.normpath(os.path.join(HERE, '..', '..', 'shared', 'data'))
ATTR_METRIC = os.path.normpath(os.path.join(HERE, '..', '..', 'shared', 'bench', 'metric', 'attr_metric.py'))
ASSETS = ['Duck.glb', 'CesiumMan.glb', 'CesiumMilkTruck.glb', 'SheenCloth.glb', 'tiny_cube_vcolor.glb',
          'spot.obj', 'beast.obj', 'boat.obj', 'pizza.obj', 'human_neutral.obj', 'trimesh_chair.obj',
          'trimesh_reference_vcolor.obj', 'tiny_sphere_vcolor.ply', 'trimesh_cycloidal.ply', 'hoppe_cessna.ply',
          'hoppe_spheretext.ply']


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({r.returncode}): {r.stderr.strip()[-500:]}")
    return r.stdout


def last_json(text):
    return json.loads([l for l in text.splitlines() if l.startswith('{')][-1])


def obj_to_glb(obj_path, glb_path):
    """OBJ (v [r g b], vt, vn, usemtl, f v/vt/vn) -> .glb, one primitive per material."""
    v, col, vt, vn, groups, cur = [], [], [], [], {}, ''
    for line in open(obj_path):
        f = line.split()
        if not f:
            continue
        if f[0] == 'v':
            v.append(tuple(map(float, f[1:4])))
            col.append(tuple(map(float, f[4:7])) if len(f) >= 7 else None)
        elif f[0] == 'vt':
            vt.append((float(f[1]), float(f[2]) if len(f) > 2 else 0.0))
        elif f[0] == 'vn':
            vn.append(tuple(map(float, f[1:4])))
        elif f[0] == 'usemtl':
            cur = f[1] if len(f) > 1 else ''
        elif f[0] == 'f':
            corners = []
            for c in f[1:]:
                p = (c.split('/') + ['', ''])[:3]
                corners.append(tuple(int(x) - 1 if x else -1 for x in p))
            for i in range(1, len(corners) - 1):
                groups.setdefault(cur, []).append((corners[0], corners[i], corners[i + 1]))
    has_c = any(c is not None for c in col)
    has_t = bool(vt)
    has_n = bool(vn)
    bin_, views, accs, prims, mats = bytearray(), [], [], [], []

    def add(data, fmt, count, gltype, comp, target, minmax=None):
        while len(bin_) % 4:
            bin_.append(0)
        views.append({'buffer': 0, 'byteOffset': len(bin_), 'byteLength': len(data), 'target': target})
        bin_.extend(data)
        a = {'bufferView': len(views) - 1, 'componentType': comp, 'count': count, 'type': gltype}
        if minmax:
            a['min'], a['max'] = minmax
        accs.append(a)
        return len(accs) - 1

    for name, tris in groups.items():
        key, pos, cc, tt, nn, idx = {}, [], [], [], [], []
        for t in tris:
            for c in t:
                if c not in key:
                    key[c] = len(pos)
                    pos.append(v[c[0]])
                    cc.append(col[c[0]] or (1.0, 1.0, 1.0))
                    tt.append(vt[c[1]] if c[1] >= 0 else (0.0, 0.0))
                    nn.append(vn[c[2]] if c[2] >= 0 else (0.0, 0.0, 1.0))
                idx.append(key[c])
        flat = lambda rows: [x for r in rows for x in r]
        lo = [min(p[k] for p in pos) for k in range(3)]
        hi = [max(p[k] for p in pos) for k in range(3)]
        attrs = {'POSITION': add(struct.pack(f'<{3 * len(pos)}f', *flat(pos)), 'f', len(pos), 'VEC3', 5126, 34962, (lo, hi))}
        if has_n:
            attrs['NORMAL'] = add(struct.pack(f'<{3 * len(nn)}f', *flat(nn)), 'f', len(nn), 'VEC3', 5126, 34962)
        if has_t:
            attrs['TEXCOORD_0'] = add(struct.pack(f'<{2 * len(tt)}f', *flat(tt)), 'f', len(tt), 'VEC2', 5126, 34962)
        if has_c:
            attrs['COLOR_0'] = add(struct.pack(f'<{3 * len(cc)}f', *flat(cc)), 'f', len(cc), 'VEC3', 5126, 34962)
        ind = add(struct.pack(f'<{len(idx)}I', *idx), 'I', len(idx), 'SCALAR', 5125, 34963)
        mats.append({'name': name})
        prims.append({'attributes': attrs, 'indices': ind, 'material': len(mats) - 1, 'mode': 4})
    while len(bin_) % 4:
        bin_.append(0)
    js = {'asset': {'version': '2.0', 'generator': 'qem bench/attr_compare.py'}, 'scene': 0,
          'scenes': [{'nodes': [0]}], 'nodes': [{'mesh': 0}], 'meshes': [{'primitives': prims}],
          'materials': mats, 'buffers': [{'byteLength': len(bin_)}], 'bufferViews': views, 'accessors': accs}
    j = json.dumps(js).encode()
    j += b' ' * (-len(j) % 4)
    out = struct.pack('<III', 0x46546C67, 2, 12 + 8 + len(j) + 8 + len(bin_))
    out += struct.pack('<II', len(j), 0x4E4F534A) + j + struct.pack('<II', len(bin_), 0x004E4942) + bytes(bin_)
    open(glb_path, 'wb').write(out)


def peer_input(asset, path, qem, work):
    """The file the peers read: the asset itself, or a .glb copy (see the module's doc)."""
    if path.endswith('.glb'):
        return path
    if path.endswith('.obj'):
        info = json.loads(run([qem, 'info', '--json', path]))
        if not any(a['kind'] == 'color' for a in info['attributes']) and info['materials'] <= 1:
            return path
    glb = os.path.join(work, asset + '.peer.glb')
    if not os.path.exists(glb):
        obj = os.path.join(work, asset + '.copy.obj')
        run([qem, 'simplify', '-q', '--no-refit', '-r', '1', path, obj])
        obj_to_glb(obj, glb)
    return glb


def measure(qem, orig, approx, samples, check):
    m = last_json(run([qem, 'measure', '--json', '--samples', str(samples), orig, approx]))
    row = {k: m.get(k) for k in ('approx_faces', 'E', 'E_rel', 'hausdorff_rel', 'uv_rms', 'normal_rms_deg', 'color_rms',
                                 'seam_cracks')}
    if check:
        a = last_json(run(['/usr/bin/python3', ATTR_METRIC, orig, approx]))
        row.update({'py_' + k: a.get(k) for k in ('rms_dist_rel', 'uv_rms', 'normal_rms_deg', 'color_rms', 'seam_cracks')})
    return row


def tool_run(tool, asset, path, ratio, faces, args, work):
    """Simplifies with one tool ('qem_eq': qem asked for the peer's size); returns (output path, its JSON
    report or {})."""
    stem = os.path.join(work, f'{asset}.{ratio:g}.{tool}')
    ext = '.glb' if tool == 'gltft' or path.endswith('.glb') else os.path.splitext(path)[1]
    if tool in ('qem', 'qem_eq'):
        out = stem + ext
        return out, last_json(run([args.qem, 'simplify', '--json', '-q', '-f', str(faces)] + args.qem_arg + [path, out]))
    src = peer_input(asset, path, args.qem, work)
    out = stem + (os.path.splitext(src)[1] if tool == 'meshopt' else '.glb')
    if tool == 'meshopt':
        return out, last_json(run(['node', os.path.join(args.peer, 'peer_meshopt_attr.mjs'), src, out, str(faces), 'attr']))
    if not src.endswith('.glb'):
        src = os.path.join(work, asset + '.peer.glb')
        if not os.path.exists(src):
            obj = os.path.join(work, asset + '.copy.obj')
            run([args.qem, 'simplify', '-q', '--no-refit', '-r', '1', path, obj])
            obj_to_glb(obj, src)
    run([os.path.join(args.peer, 'node_modules', '.bin', 'gltf-transform'), 'simplify', src, out, '--ratio', f'{ratio:g}',
         '--error', '1'])
    return out, {}


def fmt(x, digits=3):
    if x is None:
        return '-'
    if isinstance(x, int):
        return str(x)
    return f'{x:.{digits}g}'


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--qem', default=os.path.join(HERE, '..', 'build', 'qem'))
    ap.add_argument('--peer', default='/tmp/jspeer')
    ap.add_argument('--out', default='/tmp/qem_attr_compare')
    ap.add_argument('--ratios', default='0.5,0.1,0.01')
    ap.add_argument('--assets', default=','.join(ASSETS))
    ap.add_argument('--tools', default='qem,meshopt,gltft')
    ap.add_argument('--qem-arg', action='append', default=[], help='extra argument of qem simplify (repeat)')
    ap.add_argument('--samples', type=int, default=1000000, help='samples of qem measure')
    ap.add_argument('--no-check', action='store_true', help='skip attr_metric.py (qem measure only)')
    ap.add_argument('--tag', default='', help='label of this run in rows.jsonl')
    ap.add_argument('--size-tol', type=float, default=0.01,
                    help="face counts of qem and meshoptimizer further apart than this fraction re-run qem at "
                         "meshoptimizer's count (0: always when they differ; negative: never)")
    args = ap.parse_args()
    args.qem = os.path.abspath(args.qem)
    os.makedirs(args.out, exist_ok=True)
    cache_path = os.path.join(args.out, 'peer_cache.json')
    cache = json.load(open(cache_path)) if os.path.exists(cache_path) else {}
    tools = args.tools.split(',')
    rows = []
    print(HEADER)
    for asset in args.assets.split(','):
        path = os.path.join(DATA, asset)
        in_faces = json.loads(run([args.qem, 'info', '--json', path]))['faces']
        for ratio in map(float, args.ratios.split(',')):
            faces = max(1, round(ratio * in_faces))
            row = {'asset': asset, 'ratio': ratio, 'in_faces': in_faces, 'target': faces, 'tag': args.tag,
                   'qem_args': ' '.join(args.qem_arg)}
            for tool in tools:
                key = f'{asset}|{ratio:g}|{tool}|{args.samples}|{not args.no_check}'
                if tool != 'qem' and key in cache:
                    row[tool] = cache[key]
                    continue
                try:
                    out, rep = tool_run(tool, asset, path, ratio, faces, args, args.out)
                    m = measure(args.qem, path, out, args.samples, not args.no_check)
                    m['simplify_s'] = rep.get('simplify_s')
                except RuntimeError as e:
                    m = {'error': str(e)}
                    print(f'{asset} {ratio:g} {tool}: {e}', file=sys.stderr)
                row[tool] = m
                if tool != 'qem':
                    cache[key] = m
                    json.dump(cache, open(cache_path, 'w'))
            peer_faces = row.get('meshopt', {}).get('approx_faces')
            if args.size_tol >= 0 and unequal(row.get('qem', {}).get('approx_faces'), peer_faces, args.size_tol):
                m = qem_at_size(asset, path, ratio, peer_faces, args)
                row['qem_eq'] = m
                row['qem_eq_unequal'] = unequal(m.get('approx_faces'), peer_faces, args.size_tol)
            rows.append(row)
            with open(os.path.join(args.out, 'rows.jsonl'), 'a') as f:
                f.write(json.dumps(row) + '\n')
            print(line(row, tools), flush=True)
    print(verdict(rows))


def qem_at_size(asset, path, ratio, peer_faces, args):
    """qem re-run with `-f` = meshoptimizer's face count. On a glTF document qem's target counts each mesh
    once while the measured output counts every instance (the truck's wheels), so a miss is corrected
    up to four times: first by the reached/asked ratio, then along the line through the last two
    tries (the instances add faces in steps, not in proportion); the output closest to the peer's
    count is kept. A run that stops above the peer's count at every -f (its seams and borders allow
    no more) is reported as such."""
    best, f, tried, last = None, peer_faces, set(), None
    for _ in range(5):
        if f in tried or f < 1:
            break
        tried.add(f)
        try:
            out, rep = tool_run('qem_eq', asset, path, ratio, f, args, args.out)
            m = measure(args.qem, path, out, args.samples, False)
        except RuntimeError as e:
            print(f'{asset} {ratio:g} qem at {peer_faces} faces: {e}', file=sys.stderr)
            return best or {'error': str(e)}
        m['simplify_s'], m['asked_faces'] = rep.get('simplify_s'), f
        got = m.get('approx_faces')
        if best is None or abs(got - peer_faces) < abs(best['approx_faces'] - peer_faces):
            best = m
        if not got or not unequal(got, peer_faces, args.size_tol):
            break
        step = f * peer_faces / got
        if last and last[1] != got:
            step = f + (peer_faces - got) * (f - last[0]) / (got - last[1])
        last, f = (f, got), round(step)
    if best and args.no_check is False:
        out, _ = tool_run('qem_eq', asset, path, ratio, best['asked_faces'], args, args.out)
        best = dict(best, **measure(args.qem, path, out, args.samples, True))
    return best


HEADER = ('| asset | target | faces q / q@m / m / g | E q/m | E q/m asked | E q/g | UV q / m | normal° q / m |'
          ' colour q / m | cracks q / m / g | check |\n|---|---|---|---|---|---|---|---|---|---|---|')


def ratio_of(a, b):
    return None if a is None or not b else a / b


def unequal(a, b, tol):
    """Face counts a and b further apart than tol of b (either way); False when either is missing."""
    return a is not None and b is not None and abs(a - b) > tol * b


def judged(row):
    """The qem output a row is judged on: the one at meshoptimizer's size when qem was re-run."""
    return row['qem_eq'] if 'qem_eq' in row else row.get('qem', {})


def line(row, tools):
    q0, m, g = row.get('qem', {}), row.get('meshopt', {}), row.get('gltft', {})
    q = judged(row)
    pair = lambda k, d=3: f"{fmt(q.get(k), d)} / {fmt(m.get(k), d)}" if (q.get(k) is not None or m.get(k) is not None) else '-'
    # check: the largest relative difference between qem measure and attr_metric.py over the
    # attribute errors of qem's and meshopt's outputs (sampling noise is a few %).
    diffs = []
    # .glb: only meshoptimizer's output is cross-checked (as when qem's was one merged scene-space mesh).
    for r in ((m,) if row['asset'].endswith('.glb') else (q, m)):
        for k in ('uv_rms', 'normal_rms_deg', 'color_rms'):
            a, b = r.get(k), r.get('py_' + k)
            if a is not None and b is not None and max(a, b) > 0:
                diffs.append(abs(a - b) / max(a, b))
        if r.get('seam_cracks') is not None and r.get('py_seam_cracks') is not None and r['seam_cracks'] != r['py_seam_cracks']:
            diffs.append(float('inf'))
    check = '-' if not diffs else ('cracks differ' if max(diffs) == float('inf') else f'{100 * max(diffs):.0f}%')
    er = lambda a, b: fmt(ratio_of(a.get('E'), b.get('E')), 2)
    eq = '-' if 'qem_eq' not in row else fmt(q.get('approx_faces')) + ('!' if row.get('qem_eq_unequal') else '')
    return (f"| {row['asset']} | {row['ratio']:g} | {fmt(q0.get('approx_faces'))} / {eq} / {fmt(m.get('approx_faces'))} / "
            f"{fmt(g.get('approx_faces'))} | {er(q, m)} | {er(q0, m) if 'qem_eq' in row else '-'} | {er(q0, g)} | "
            f"{pair('uv_rms')} | {pair('normal_rms_deg', 2)} | "
            f"{pair('color_rms')} | {fmt(q.get('seam_cracks'))} / {fmt(m.get('seam_cracks'))} / {fmt(g.get('seam_cracks'))} | {check} |")


EXACT_E_REL = 1e-12


def verdict(rows):
    """The issue's goal per row: E <= 0.9x meshopt's, attribute errors <= meshopt's, no cracks; judged at
    meshoptimizer's size where qem was re-run there."""
    fails, above = [], 0
    for row in rows:
        q, m = judged(row), row.get('meshopt', {})
        why = []
        e = ratio_of(q.get('E'), m.get('E'))
        # An output exact to rounding (E below 1e-12 of the diagonal: the 12-face cube of a subdivided
        # cube, whose E is 1e-16 noise in either tool) cannot be bettered; the ratio of two noises says nothing.
        if e is not None and e > 0.9 and not (q.get('E_rel') is not None and q['E_rel'] < EXACT_E_REL):
            why.append(f'E {e:.2f}x')
        for k in ('uv_rms', 'normal_rms_deg', 'color_rms'):
            if q.get(k) is not None and m.get(k) is not None and q[k] > m[k] + 1e-9:  # 1e-9: rounding noise
                why.append(f'{k} {q[k]:.3g} > {m[k]:.3g}')
        if q.get('seam_cracks'):
            why.append(f"{q['seam_cracks']} cracks")
        qf, mf = q.get('approx_faces'), m.get('approx_faces')
        if row.get('qem_eq_unequal') and qf is not None and mf is not None and qf > mf:
            why.append(f'stops at {qf} faces, above meshoptimizer\'s {mf}')  # a larger mesh's error proves nothing
            above += 1
        if why:
            fails.append(f"{row['asset']} {row['ratio']:g}: " + ', '.join(why))
    er = [ratio_of(judged(r).get('E'), r.get('meshopt', {}).get('E')) for r in rows]
    er = [x for x in er if x]
    gm = math.exp(sum(map(math.log, er)) / len(er)) if er else float('nan')
    n_eq = sum('qem_eq' in r for r in rows)
    return (f'{len(rows) - len(fails)} of {len(rows)} rows meet the goal ({n_eq} judged with qem re-run at '
            f"meshoptimizer's size), geometric mean E q/m {gm:.3f}" +
            (f"; not met ({above} of them stopping above meshoptimizer's size): " + '; '.join(fails) if fails else ''))


if __name__ == '__main__':
    main()
