"""Shared fixtures: the CLI to compare with, the shared meshes, and procedural meshes made in numpy."""
import os
import pathlib
import shutil

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


def cli_path():
    """The `qem` executable: $QEM_CLI (set by ctest), else the build tree's."""
    for p in (os.environ.get("QEM_CLI"), REPO / "build" / "qem", shutil.which("qem")):
        if p and os.access(str(p), os.X_OK):
            return str(p)
    return None


@pytest.fixture(scope="session")
def cli():
    p = cli_path()
    if p is None:
        pytest.skip("no qem executable (set QEM_CLI or build build/qem)")
    return p


@pytest.fixture(scope="session")
def shared_data():
    d = pathlib.Path(os.environ.get("QEM_SHARED_DIR", REPO.parent / "shared")) / "data"
    if not d.is_dir():
        pytest.skip(f"no shared data at {d}")
    return d


def torus(n_major, n_minor, bumps=0.0):
    """A closed torus grid: 2 * n_major * n_minor faces, optionally bumpy (so the error is not 0)."""
    u = np.linspace(0, 2 * np.pi, n_major, endpoint=False)
    v = np.linspace(0, 2 * np.pi, n_minor, endpoint=False)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    r = 0.3 * (1 + bumps * np.sin(7 * uu) * np.sin(5 * vv))
    x = (1 + r * np.cos(vv)) * np.cos(uu)
    y = (1 + r * np.cos(vv)) * np.sin(uu)
    z = r * np.sin(vv)
    vertices = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n_major), np.arange(n_minor), indexing="ij")
    a = i * n_minor + j
    b = ((i + 1) % n_major) * n_minor + j
    c = ((i + 1) % n_major) * n_minor + (j + 1) % n_minor
    d = i * n_minor + (j + 1) % n_minor
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return vertices, faces.astype(np.int32)


@pytest.fixture(scope="session")
def small_torus():
    return torus(60, 30, bumps=0.2)  # 3,600 faces


@pytest.fixture(scope="session")
def large_torus():
    return torus(700, 600, bumps=0.1)  # 840,000 faces
