#!/usr/bin/env python3
"""Compact comparison of qem against the peer simplifiers, from the CSV(s) written by the peer
benchmark runner (run.py / run.sh of the shared bench harness).

For each (mesh, target) case: one row per simplifier with status, output faces, E/diag^2 (GH97
section 6.1, measured by the harness's independent metric), Hausdorff/diag, simplify_s (wall time
of the simplification call only), simplify CPU s and peak RSS; then the ratios

  qem/meshopt time        qem's simplify_s over meshoptimizer's
  qem/fastest-other time  over the fastest peer that is not meshoptimizer (named)
  qem E / best peer E     qem's E over the lowest E of any peer (named)

Usage: scripts/bench_summary.py RESULTS.csv [MORE.csv ...] [--ours qem] [--baseline BASE.csv]
Rows of later files replace rows of earlier ones for the same (mesh, target, peer); --baseline
adds peer rows from an earlier peers-only run for peers missing from the main CSV(s).
Standard library only.
"""
import argparse
import csv
import sys


def num(row, key):
    try:
        v = float(row.get(key, "") or "nan")
    except ValueError:
        return None
    return None if v != v else v


def fmt(v, kind):
    if v is None:
        return "-"
    if kind == "e":
        return "%.3g" % v
    if kind == "s":
        return "%.3f" % v if v < 10 else "%.1f" % v
    if kind == "mb":
        return "%.0f" % v
    if kind == "x":
        return "%.2fx" % v
    return str(v)


def load(paths):
    rows = {}
    order = []
    for p in paths:
        with open(p, newline="") as f:
            for r in csv.DictReader(f):
                key = (r["mesh"], int(r["target"]), r["peer"])
                if key not in rows:
                    order.append(key)
                rows[key] = r
    return rows, order


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv", nargs="+", help="CSV file(s) written by the bench runner")
    ap.add_argument("--ours", default="qem", help="peer name of our simplifier (default qem)")
    ap.add_argument("--baseline", action="append", default=[],
                    help="earlier CSV whose peer rows fill in peers absent from the main CSV(s)")
    a = ap.parse_args()

    rows, order = load(a.csv)
    if a.baseline:
        base, border = load(a.baseline)
        cases = {(m, t) for (m, t, _) in order}
        for key in border:
            if key not in rows and (key[0], key[1]) in cases and key[2] != a.ours:
                rows[key] = dict(base[key], peer=key[2] + "*")
                order.append(key)

    cases = []
    for m, t, _ in order:
        if (m, t) not in cases:
            cases.append((m, t))
    if not cases:
        print("no rows in %s" % ", ".join(a.csv), file=sys.stderr)
        return 1

    summary = []
    for mesh, target in cases:
        peers = [rows[k] for k in order if k[0] == mesh and k[1] == target]
        label = peers[0].get("target_label", "")
        print("\n### %s (%s faces) -> %d (%s)\n" % (mesh, peers[0].get("in_faces", "?"), target, label))
        print("| simplifier | status | faces | E/diag² | Hausdorff/diag | simplify s | cpu s | peak RSS MB |")
        print("|---|---|---|---|---|---|---|---|")
        ok = [r for r in peers if r["status"] in ("ok",) and num(r, "E_rel") is not None]
        for r in sorted(peers, key=lambda r: (r["peer"] != a.ours, r["peer"])):
            name = "**%s**" % r["peer"] if r["peer"] == a.ours else r["peer"]
            status = r["status"] + ((" (" + r["note"][:60] + ")") if r["status"] != "ok" and r["note"] else "")
            print("| %s | %s | %s | %s | %s | %s | %s | %s |" % (
                name, status, r.get("out_faces") or "-", fmt(num(r, "E_rel"), "e"), fmt(num(r, "hausdorff_rel"), "e"),
                fmt(num(r, "simplify_s"), "s"), fmt(num(r, "simplify_cpu_s"), "s"), fmt(num(r, "peak_rss_mb"), "mb")))

        ours = next((r for r in peers if r["peer"] == a.ours), None)
        others = [r for r in ok if r["peer"] != a.ours]
        line = {"case": "%s -> %d" % (mesh, target)}
        if ours is not None and ours["status"] == "ok":
            t_ours, e_ours = num(ours, "simplify_s"), num(ours, "E_rel")
            mo = next((r for r in others if r["peer"].rstrip("*") == "meshopt"), None)
            if mo and t_ours and num(mo, "simplify_s"):
                line["vs_meshopt"] = t_ours / num(mo, "simplify_s")
            timed = [r for r in others if r["peer"].rstrip("*") != "meshopt" and num(r, "simplify_s")]
            if timed and t_ours:
                fastest = min(timed, key=lambda r: num(r, "simplify_s"))
                line["vs_fastest"] = t_ours / num(fastest, "simplify_s")
                line["fastest"] = fastest["peer"]
            if others and e_ours is not None:
                best = min(others, key=lambda r: num(r, "E_rel"))
                line["vs_bestE"] = e_ours / num(best, "E_rel")
                line["bestE"] = best["peer"]
        elif others:
            best = min(others, key=lambda r: num(r, "E_rel"))
            line["bestE"] = best["peer"]
            line["best_E_rel"] = num(best, "E_rel")
        line["ours_status"] = ours["status"] if ours is not None else "absent"
        summary.append(line)

    print("\n### %s against the peers\n" % a.ours)
    print("| case | %s status | %s/meshopt time | %s/fastest other peer time | %s E / best peer E |" % (
        (a.ours,) * 4))
    print("|---|---|---|---|---|")
    for s in summary:
        if s["ours_status"] != "ok":
            extra = " (best peer E: %s %s)" % (s.get("bestE", "-"), fmt(s.get("best_E_rel"), "e")) if s.get(
                "bestE") else ""
            print("| %s | %s%s | - | - | - |" % (s["case"], s["ours_status"], extra))
            continue
        print("| %s | ok | %s | %s (%s) | %s (%s) |" % (
            s["case"], fmt(s.get("vs_meshopt"), "x"), fmt(s.get("vs_fastest"), "x"), s.get("fastest", "-"),
            fmt(s.get("vs_bestE"), "x"), s.get("bestE", "-")))
    if a.baseline:
        print("\n`*` = peer row taken from the baseline CSV (another run, possibly under different load).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
