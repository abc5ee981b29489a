#!/usr/bin/env python3
"""qem from Python against Open3D's simplify_quadric_decimation, and qem's Python call against the
C++ call (the CLI's --json simplify_s), side by side on the same meshes in the same run.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_peers.py MESH... [--ratios 0.1,0.01]
        [--repeat 3] [--samples 1000000] [--cli build/qem] [--markdown]

Per mesh and ratio: the median wall time of each tool's simplification call (loading and array
conversion outside the timing, for every tool), and E (GH97 §6.1 mean squared distance, over the
diagonal², measured with qem.measure on the same samples for every tool). Rows:
  qem (C++ call)       `qem simplify --json`'s simplify_s: the library call inside the CLI
  qem (Python)         qem.simplify on numpy arrays, defaults (the CLI's light refit)
  qem (Python, no refit)  refit="none": GH97 as published, as Open3D
  open3d               TriangleMesh.simplify_quadric_decimation (Debian's python3-open3d)
The machine may be shared: compare ratios within one run, not times across runs.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import qem


def median_time(fn, repeat):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def cli_simplify_s(cli, path, faces, repeat, tmp):
    times = []
    for _ in range(repeat):
        out = subprocess.run([cli, "simplify", path, os.path.join(tmp, "cli.ply"), "--faces", str(faces), "--json",
                              "--quiet", "--force"], check=True, capture_output=True, text=True).stdout
        times.append(json.loads(out)["simplify_s"])
    return statistics.median(times), qem.load(os.path.join(tmp, "cli.ply"))


def overhead(args):
    """Pairs of runs, CLI then Python, so that both see the same machine load."""
    with tempfile.TemporaryDirectory() as tmp:
        for path in args.meshes:
            mesh = qem.load(path)
            for ratio in [float(r) for r in args.ratios.split(",")]:
                target = max(4, int(ratio * len(mesh.faces)))
                wall, cpu = [], []
                for _ in range(args.repeat):
                    out = subprocess.run([args.cli, "simplify", path, os.path.join(tmp, "c.ply"), "--faces", str(target),
                                          "--json", "--quiet", "--force"], check=True, capture_output=True,
                                         text=True).stdout
                    c = json.loads(out)
                    t0, c0 = time.perf_counter(), time.process_time()
                    qem.simplify(mesh.vertices, mesh.faces, target_faces=target)
                    wall.append((time.perf_counter() - t0) / c["simplify_s"])
                    cpu.append((time.process_time() - c0) / c["simplify_cpu_s"])
                print(f"{os.path.basename(path)} {len(mesh.faces)} faces -> {target}: Python / C++ call, median of "
                      f"{args.repeat} pairs: wall {statistics.median(wall):.3f} (pairs {min(wall):.2f}-{max(wall):.2f}), "
                      f"CPU {statistics.median(cpu):.3f} (pairs {min(cpu):.2f}-{max(cpu):.2f})")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("meshes", nargs="+")
    ap.add_argument("--ratios", default="0.1,0.01")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--cli", default=os.path.join(os.path.dirname(__file__), "..", "build", "qem"))
    ap.add_argument("--no-open3d", action="store_true")
    ap.add_argument("--overhead", action="store_true",
                    help="only the Python call against the C++ call: CLI and Python runs alternate, and the "
                         "median of the pairs' ratios (wall and CPU time) is printed")
    args = ap.parse_args()
    if args.overhead:
        return overhead(args)
    o3d = None
    if not args.no_open3d:
        import open3d as o3d  # noqa: F811  (Debian's python3-open3d)
        o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)

    print(f"# load average {os.getloadavg()[0]:.1f}, {os.cpu_count()} cores, median of {args.repeat}")
    print("| mesh | faces in | target | tool | faces out | time s | time / qem Python | E (rel) | E / open3d |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for path in args.meshes:
            mesh = qem.load(path)
            name = os.path.basename(path)
            for ratio in [float(r) for r in args.ratios.split(",")]:
                target = max(4, int(ratio * len(mesh.faces)))
                rows = []
                if os.access(args.cli, os.X_OK):
                    t, out = cli_simplify_s(args.cli, path, target, args.repeat, tmp)
                    rows.append(("qem (C++ call, CLI simplify_s)", t, out))
                t, out = median_time(lambda: qem.simplify(mesh.vertices, mesh.faces, target_faces=target), args.repeat)
                rows.append(("qem (Python)", t, out))
                t, out = median_time(
                    lambda: qem.simplify(mesh.vertices, mesh.faces, target_faces=target, refit="none"), args.repeat)
                rows.append(("qem (Python, no refit)", t, out))
                if o3d is not None:
                    m3 = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(mesh.vertices),
                                                   o3d.utility.Vector3iVector(mesh.faces))
                    t, out3 = median_time(lambda: m3.simplify_quadric_decimation(target_number_of_triangles=target),
                                          args.repeat)
                    out = qem.Mesh(np.asarray(out3.vertices), np.asarray(out3.triangles))
                    rows.append(("open3d simplify_quadric_decimation", t, out))
                errors = {tool: qem.measure(mesh, out, samples=args.samples).E_rel for tool, _, out in rows}
                t_py = next(t for tool, t, _ in rows if tool == "qem (Python)")
                e_o3d = errors.get("open3d simplify_quadric_decimation")
                for tool, t, out in rows:
                    e = errors[tool]
                    print(f"| {name} | {len(mesh.faces)} | {target} | {tool} | {len(out.faces)} | {t:.3f} | "
                          f"{t / t_py:.2f} | {e:.3e} | {e / e_o3d if e_o3d else float('nan'):.2f} |")
                sys.stdout.flush()


if __name__ == "__main__":
    main()
