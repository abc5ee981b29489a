#!/usr/bin/env python3
"""Paired timing rounds of qem builds against meshoptimizer's driver on one mesh.

Each round runs meshopt and every qem build once (the order rotating from round to round), reads
`simplify_cpu_s` from each one's JSON line, and takes each build's ratio to meshopt's time in that
round; the medians of those per-round ratios are what docs/benchmarks.md reports. On a loaded
machine the CPU time is the steadier measure, and pairing cancels most of the load's drift.

  bench/paired_rounds.py --mesh bunny.ply --faces 6945,695 --rounds 15 \
      --meshopt /tmp/bench-build/peer_meshopt before=/tmp/qem_before after=build/qem
"""
import argparse
import json
import statistics
import subprocess
import tempfile


def cpu_seconds(cmd):
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    for line in out.splitlines():
        if line.startswith("{"):
            return json.loads(line)["simplify_cpu_s"]
    raise RuntimeError("no JSON line from " + " ".join(cmd))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mesh", required=True)
    ap.add_argument("--faces", required=True, help="comma-separated face targets")
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--meshopt", required=True, help="the harness's peer_meshopt driver")
    ap.add_argument("builds", nargs="+", help="NAME=PATH of a qem binary")
    a = ap.parse_args()
    builds = [b.split("=", 1) for b in a.builds]
    with tempfile.TemporaryDirectory() as tmp:
        for faces in a.faces.split(","):
            runs = [("meshopt", [a.meshopt, a.mesh, f"{tmp}/m.ply", faces])]
            runs += [(name, [path, "simplify", a.mesh, f"{tmp}/{name}.ply", "--faces", faces, "--json", "-q"])
                     for name, path in builds]
            times = {name: [] for name, _ in runs}
            for r in range(a.rounds):
                k = r % len(runs)
                for name, cmd in runs[k:] + runs[:k]:
                    times[name].append(cpu_seconds(cmd))
            line = [f"faces {faces}, {a.rounds} rounds: meshopt {statistics.median(times['meshopt']):.4f} s"]
            for name, _ in builds:
                ratios = [t / m for t, m in zip(times[name], times["meshopt"])]
                line.append(f"{name} {statistics.median(times[name]):.4f} s, "
                            f"{statistics.median(ratios):.2f}x ({min(ratios):.2f}-{max(ratios):.2f})")
            print("; ".join(line))


if __name__ == "__main__":
    main()
