"""Memory: simplifying a 1M-face mesh from Python costs at most 1.2x the command line's peak (both in
core: the command line would cut a mesh this size into parts by default, Python's simplify does not)."""
import json
import os
import subprocess
import sys

import pytest

SCRIPT = """
import resource, sys
import qem
m = qem.load(sys.argv[1])
r = qem.simplify(m.vertices, m.faces, target_ratio=0.1)
qem.save(sys.argv[2], r)
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
"""


def test_peak_memory_against_cli(cli, tmp_path):
    src = tmp_path / "sphere.ply"
    subprocess.run([cli, "generate", "sphere", str(src), "--faces", "1000000"], check=True, capture_output=True)
    out = subprocess.run([cli, "simplify", str(src), str(tmp_path / "cli.ply"), "--ratio", "0.1", "--partition", "off",
                          "--json", "--quiet"],
                         check=True, capture_output=True, text=True).stdout
    cli_mb = json.loads(out)["peak_rss_mb"]
    py = subprocess.run([sys.executable, "-c", SCRIPT, str(src), str(tmp_path / "py.ply")], check=True,
                        capture_output=True, text=True, env=os.environ)
    py_mb = float(py.stdout.strip().splitlines()[-1])
    print(f"peak RSS: CLI {cli_mb:.0f} MB, Python {py_mb:.0f} MB ({py_mb / cli_mb:.2f}x)")
    assert (tmp_path / "py.ply").read_bytes() == (tmp_path / "cli.ply").read_bytes()
    assert py_mb <= 1.2 * cli_mb, (py_mb, cli_mb)
