#!/usr/bin/env python3
"""Times the partitioned run (qem simplify --partition, docs/parallel.md) on 1 and 2 threads beside
the in-core run and meshoptimizer 0.18 (../shared/bench's peer_meshopt), in the same run, rounds
interleaved so that the machine's load falls on all of them alike; then measures each output's E
and Hausdorff distance against the input with `qem measure`. Prints a Markdown table of medians.

On a shared machine the wall times of 2-thread runs say little (the second core is often taken),
so the table also gives CPU seconds and, for the partitioned 2-thread run, the wall time two free
cores would give by its CPU accounts: all CPU seconds outside the parts counted as serial (an
upper bound: the final pass and the refit use both threads in part), plus the parts' CPU seconds
of the thread that had the most (`busiest_thread_cpu_s`). For a 1-thread run CPU seconds are the
free-core wall time.

  bench/partition_bench.py MESH.ply [--ratios 0.1,0.01] [--repeat 3] [--qem build/qem]
      [--meshopt /tmp/bench-build/peer_meshopt] [--parts auto] [--out /tmp/qem-partition]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys


def run_json(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mesh")
    ap.add_argument("--ratios", default="0.1,0.01")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--qem", default=os.path.join(os.path.dirname(__file__), "..", "build", "qem"))
    ap.add_argument("--meshopt", default="/tmp/bench-build/peer_meshopt")
    ap.add_argument("--parts", default="auto")
    ap.add_argument("--out", default="/tmp/qem-partition")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    in_faces = run_json([a.qem, "info", a.mesh, "--json"])["faces"]
    configs = [  # name, command maker
        ("in-core, 1 thread", lambda o, r: [a.qem, "simplify", a.mesh, o, "--ratio", str(r), "--partition", "off",
                                             "--threads", "1", "--json", "--quiet", "--force"]),
        ("in-core, 2 threads", lambda o, r: [a.qem, "simplify", a.mesh, o, "--ratio", str(r), "--partition", "off",
                                              "--threads", "2", "--json", "--quiet", "--force"]),
        ("parts, 1 thread", lambda o, r: [a.qem, "simplify", a.mesh, o, "--ratio", str(r), "--partition", a.parts,
                                           "--threads", "1", "--json", "--quiet", "--force"]),
        ("parts, 2 threads", lambda o, r: [a.qem, "simplify", a.mesh, o, "--ratio", str(r), "--partition", a.parts,
                                            "--threads", "2", "--json", "--quiet", "--force"]),
        ("meshopt 0.18", lambda o, r: [a.meshopt, a.mesh, o, str(int(r * in_faces))]),
    ]
    rows = []
    for r in [float(x) for x in a.ratios.split(",")]:
        times = {name: [] for name, _ in configs}
        cpus = {name: [] for name, _ in configs}
        info = {}
        for rep in range(a.repeat):
            for i, (name, make) in enumerate(configs):
                out = os.path.join(a.out, f"r{r}_{i}.ply")
                j = run_json(make(out, r))
                times[name].append(j["simplify_s"])
                cpu = j["simplify_cpu_s"]
                if name == "parts, 2 threads":  # the free-core estimate (see the top)
                    cpu = cpu - j["parts_cpu_s"] + j["busiest_thread_cpu_s"]
                cpus[name].append(cpu)
                info[name] = (out, j)
                print(f"ratio {r} round {rep + 1}: {name}: {j['simplify_s']:.2f} s", file=sys.stderr)
        measured = {}
        for name, (out, j) in info.items():
            m = run_json([a.qem, "measure", a.mesh, out, "--json"])
            measured[name] = (m["E"], m["hausdorff"], j.get("out_faces"), j.get("parts", ""))
        base = statistics.median(times["in-core, 1 thread"])
        mo = statistics.median(times["meshopt 0.18"])
        base_cpu = statistics.median(cpus["in-core, 1 thread"])
        parts1_cpu = statistics.median(cpus["parts, 1 thread"])
        mo_cpu = statistics.median(cpus["meshopt 0.18"])
        e0, h0 = measured["in-core, 1 thread"][:2]
        for name, _ in configs:
            t = statistics.median(times[name])
            e, h, faces, parts = measured[name]
            c = statistics.median(cpus[name])
            free = "" if name == "in-core, 2 threads" else f"{c:.2f}"
            free_up = "" if name == "in-core, 2 threads" else f"{base_cpu / c:.2f} / {parts1_cpu / c:.2f} / {c / mo_cpu:.2f}"
            rows.append(f"| {r:g} | {name} | {parts} | {faces} | {t:.2f} | {base / t:.2f} | {t / mo:.2f} | "
                        f"{free} | {free_up} | {e / e0:.3f} | {h / h0:.3f} |")
    print(f"{a.mesh}: {in_faces} faces, median of {a.repeat} interleaved rounds\n")
    print("| ratio | run | parts | out faces | wall s | wall speed-up vs in-core 1 thread | wall / meshopt | "
          "free-core s | free-core speed-up vs in-core 1 thread / vs parts 1 thread, and / meshopt | "
          "E / in-core | Hausdorff / in-core |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
