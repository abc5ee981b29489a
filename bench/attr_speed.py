#!/usr/bin/python3
"""Time and memory of qem with appearance attributes against qem on the same geometry alone.

usage: bench/attr_speed.py [--qem build/qem] [--faces 1000000] [--runs 5] [--ratio 0.1] [--dir /tmp]

Writes `qem generate sphere --faces N` (positions only) and the same sphere with `--attributes`
(smooth normals and a latitude/longitude UV set with its seam: the same positions and faces, the
seam positions split into several vertices), both binary PLY, then runs `qem simplify --ratio R`
(default options) on each, alternating, RUNS times under /usr/bin/time -v and `nice -n 10`.
Prints the medians of wall time, of the simplifier's own time (`simplify_s` of --json: without
reading and writing) and of peak RSS, and the ratios attributes / geometry.
"""
import argparse
import json
import os
import statistics
import subprocess


def timed(cmd):
    r = subprocess.run(['nice', '-n', '10', '/usr/bin/time', '-v'] + cmd, capture_output=True, text=True, check=True)
    rep = json.loads([l for l in r.stdout.splitlines() if l.startswith('{')][-1])
    stats = {}
    for line in r.stderr.splitlines():
        line = line.strip()
        if line.startswith('Maximum resident set size'):
            stats['rss_mb'] = int(line.split(':')[-1]) / 1024
        elif line.startswith('Elapsed (wall clock) time'):
            t = line.split(': ')[-1].split(':')
            stats['wall_s'] = sum(float(x) * 60 ** i for i, x in enumerate(reversed(t)))
    stats['simplify_s'] = rep['simplify_s']
    stats['out_faces'] = rep['out_faces']
    return stats


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--qem', default=os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'build', 'qem'))
    ap.add_argument('--faces', type=int, default=1000000)
    ap.add_argument('--runs', type=int, default=5)
    ap.add_argument('--ratio', type=float, default=0.1)
    ap.add_argument('--dir', default='/tmp')
    ap.add_argument('--qem-arg', action='append', default=[], help='extra argument of qem simplify (repeat)')
    args = ap.parse_args()
    files = {}
    for kind, extra in (('geometry', []), ('attributes', ['--attributes'])):
        path = os.path.join(args.dir, f'attr_speed_{kind}_{args.faces}.ply')
        if not os.path.exists(path):
            subprocess.run([args.qem, 'generate', 'sphere', '--faces', str(args.faces)] + extra + [path], check=True)
        files[kind] = path
    runs = {k: [] for k in files}
    for i in range(args.runs):
        for kind, path in files.items():
            out = os.path.join(args.dir, f'attr_speed_{kind}_out.ply')
            runs[kind].append(timed([args.qem, 'simplify', '--json', '-q', '-r', str(args.ratio)] + args.qem_arg + [path, out]))
    med = {k: {m: statistics.median(r[m] for r in v) for m in ('wall_s', 'simplify_s', 'rss_mb')} for k, v in runs.items()}
    print(f'| input ({args.faces}+ faces, ratio {args.ratio:g}) | wall s | simplify s | peak RSS MB |')
    print('|---|---|---|---|')
    for k, m in med.items():
        print(f"| {k} | {m['wall_s']:.2f} | {m['simplify_s']:.2f} | {m['rss_mb']:.0f} |")
    g, a = med['geometry'], med['attributes']
    print(f"| attributes / geometry | {a['wall_s'] / g['wall_s']:.2f}x | {a['simplify_s'] / g['simplify_s']:.2f}x | "
          f"{a['rss_mb'] / g['rss_mb']:.2f}x |")
    print(json.dumps({'runs': runs, 'median': med}))


if __name__ == '__main__':
    main()
