#!/usr/bin/env python3
"""Out of core under tight limits, over the whole catalogue of ../shared/data.

Each mesh (OBJ, PLY, STL, OFF) is copied as a binary PLY (what streams: qem.load, qem.save), then
simplified with `qem simplify --ratio R --memory-limit L --json` under L = 180 bytes a face (the
in-core need) divided by 2 and by 4, at least 100 KB, so that every mesh goes out of core in
miniature. Per run: the face target and the faces reached, the method, and the boundary edges of
the input and of the output welded by position (`qem info --json --weld on`): an output boundary
edge the input did not have is a crack. Prints one line a run and a summary: out-of-core runs
above their target, out-of-core runs with a crack (inputs too small to leave memory run in core).

  PYTHONPATH=build/python python3 bench/ooc_sweep.py --qem build/qem --ratio 0.01 --out /tmp/ooc_sweep
"""
import argparse
import glob
import json
import os
import subprocess
import sys


def info(qem, path):
    out = subprocess.run([qem, "info", "--json", "--weld", "on", path], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--qem", default="build/qem")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data"))
    ap.add_argument("--ratio", type=float, default=0.1)
    ap.add_argument("--out", default="/tmp/ooc_sweep")
    args = ap.parse_args()
    import qem  # the Python module (PYTHONPATH=build/python), for the lossless binary PLY copies

    os.makedirs(args.out, exist_ok=True)
    meshes = sorted(p for ext in ("obj", "ply", "stl", "off") for p in glob.glob(os.path.join(args.data, "*." + ext)))
    above, cracked, runs = [], [], 0
    for path in meshes:
        name = os.path.basename(path)
        copy = os.path.join(args.out, name + ".in.ply")
        if not os.path.exists(copy):
            try:
                qem.save(copy, qem.load(path))
            except Exception as e:  # a file the reader refuses is the corpus sweep's concern
                print(f"{name}: skipped ({e})")
                continue
        before = info(args.qem, copy)
        for share in (2, 4):
            limit = max(100000, before["faces"] * 180 // share)
            out = os.path.join(args.out, f"{name}.{share}.ply")
            run = subprocess.run([args.qem, "simplify", copy, out, "--ratio", str(args.ratio), "--memory-limit",
                                  str(limit), "--json"], capture_output=True, text=True)
            if run.returncode != 0:
                print(f"{name} 1/{share}: failed: {run.stderr.strip()[-200:]}")
                cracked.append(name)
                continue
            r = json.loads(run.stdout.strip().splitlines()[-1])
            after = info(args.qem, out)
            method = r.get("method", "in core") if r.get("out_of_core") else "in core"
            target = r.get("target_faces", 0)
            crack = after["boundary_edges"] > before["boundary_edges"]
            runs += 1
            if method != "in core" and r["out_faces"] > target:
                above.append(f"{name} 1/{share}")
            if crack and method != "in core":  # an in-core run (a tiny input) is another sweep's
                cracked.append(f"{name} 1/{share}")
            print(f"{name:32s} 1/{share} {method:10s} target {target:7d} out {r['out_faces']:7d} "
                  f"boundary edges {before['boundary_edges']:5d} -> {after['boundary_edges']:5d}"
                  f"{'  CRACK' if crack else ''}{'  relaxed' if r.get('topology_relaxed') else ''}")
    print(f"{runs} runs: {len(above)} out of core above their target ({', '.join(above)}); "
          f"{len(cracked)} with a crack or a failure ({', '.join(cracked)})")


if __name__ == "__main__":
    sys.exit(main())
