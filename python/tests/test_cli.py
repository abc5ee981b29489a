"""The same results as the command line on the same input: byte-identical meshes; load/save of
every format; measure, cluster, info and lod against their commands."""
import json
import subprocess

import numpy as np
import pytest

import qem


def run(cli, *args):
    return subprocess.run([cli, *map(str, args)], check=True, capture_output=True, text=True).stdout


@pytest.mark.parametrize("mesh, args, kwargs", [
    ("gh_bunny_zipper.ply", ["--ratio", "0.1"], dict(target_ratio=0.1)),
    ("gh_bunny_zipper.ply", ["--faces", "500", "--no-refit", "--weighting", "uniform"],
     dict(target_faces=500, refit="none", weighting="uniform")),
    ("gh_cow.obj", ["--faces", "1000", "--refit", "--lock-border"], dict(target_faces=1000, refit="full", lock_border=True)),
    ("gh_foot_bones.off", ["--faces", "250", "--threshold-rel", "0.01"], dict(target_faces=250, threshold_relative=0.01)),
    ("stanford_bunny_soup.stl", ["--faces", "2000"], dict(target_faces=2000)),
])
def test_simplify_same_bytes_as_cli(cli, shared_data, tmp_path, mesh, args, kwargs):
    src = shared_data / mesh
    out_cli = tmp_path / "cli.ply"
    run(cli, "simplify", src, out_cli, "--quiet", *args)
    m = qem.load(src)
    r = qem.simplify(m.vertices, m.faces, **kwargs)
    out_py = tmp_path / "py.ply"
    qem.save(out_py, r)
    assert out_py.read_bytes() == out_cli.read_bytes()


@pytest.mark.parametrize("ext", ["ply", "obj", "stl", "off"])
def test_save_load_every_format(small_torus, tmp_path, ext):
    v, f = small_torus
    path = tmp_path / f"m.{ext}"
    qem.save(path, (v, f))
    m = qem.load(path)
    assert m.faces.shape == f.shape and m.vertices.dtype == np.float64
    if ext != "stl":  # STL is welded on read: the same mesh, possibly renumbered
        np.testing.assert_array_equal(m.faces, f)
        np.testing.assert_allclose(m.vertices, v, rtol=1e-6, atol=1e-6)
    qem.save(tmp_path / f"ascii.{ext}", m, binary=False)
    assert len(qem.load(tmp_path / f"ascii.{ext}").faces) == len(f)


def test_measure_matches_cli(cli, shared_data, tmp_path):
    src = shared_data / "gh_bunny_zipper.ply"
    approx = tmp_path / "a.ply"
    run(cli, "simplify", src, approx, "--ratio", "0.05", "--quiet")
    expected = json.loads(run(cli, "measure", src, approx, "--samples", "100000", "--json"))
    got = qem.measure(qem.load(src), qem.load(approx), samples=100000)
    for key in ("E", "hausdorff", "rms"):
        assert got.__dict__[key] == pytest.approx(expected[key], rel=1e-12), key


def test_cluster_matches_cli(cli, shared_data, tmp_path):
    src = shared_data / "gh_bunny_zipper.ply"
    run(cli, "cluster", src, tmp_path / "cli.ply", "--grid", "20", "20", "20")
    m = qem.load(src)
    c = qem.cluster(m.vertices, m.faces, grid=(20, 20, 20))
    qem.save(tmp_path / "py.ply", c)
    assert (tmp_path / "py.ply").read_bytes() == (tmp_path / "cli.ply").read_bytes()


def test_info_matches_cli(cli, shared_data):
    src = shared_data / "gh_foot_bones.off"
    expected = json.loads(run(cli, "info", src, "--json"))
    m = qem.load(src)
    i = qem.info(m.vertices, m.faces)
    for key in ("components", "faces", "boundary_edges", "non_manifold_edges", "genus"):
        if key in expected:
            assert i.__dict__[key] == expected[key], key


def test_lod_matches_cli(cli, shared_data, tmp_path):
    src = shared_data / "gh_bunny_zipper.ply"
    run(cli, "lod", src, tmp_path, "--ratios", "0.5,0.1", "--quiet")
    m = qem.load(src)
    levels = qem.lod(m.vertices, m.faces, ratios=[0.5, 0.1])
    assert [len(l.faces) for l in levels] == sorted((len(l.faces) for l in levels), reverse=True)
    for i, level in enumerate(levels):
        qem.save(tmp_path / f"py{i}.ply", level)
        assert (tmp_path / f"py{i}.ply").read_bytes() == (tmp_path / f"gh_bunny_zipper_lod{i}.ply").read_bytes()


def test_lod_of_a_two_sided_input_matches_cli(cli, shared_data, tmp_path):
    # 87 reversed duplicates: each level is a run of its own (a record holds no twins), the same
    # bytes as `qem simplify --faces` at the level's target and as qem.lod.
    src = shared_data / "trimesh_bunny_messy.ply"
    run(cli, "lod", src, tmp_path, "--ratios", "0.5,0.1", "--quiet")
    manifest = json.loads((tmp_path / "manifest.json").read_text())
    m = qem.load(src)
    levels = qem.lod(m.vertices, m.faces, ratios=[0.5, 0.1])
    for i, (entry, level) in enumerate(zip(manifest["levels"], levels)):
        run(cli, "simplify", src, tmp_path / f"s{i}.ply", "--faces", entry["target_faces"], "--quiet")
        lod_bytes = (tmp_path / entry["path"]).read_bytes()
        assert lod_bytes == (tmp_path / f"s{i}.ply").read_bytes()
        qem.save(tmp_path / f"py{i}.ply", level)
        assert (tmp_path / f"py{i}.ply").read_bytes() == lod_bytes
    assert qem.simplify(m.vertices, m.faces, target_faces=manifest["levels"][1]["target_faces"]).twin_faces > 0


def test_record_file_replays_with_cli(cli, shared_data, tmp_path):
    src = shared_data / "gh_bunny_zipper.ply"
    m = qem.load(src)
    r = qem.simplify(m.vertices, m.faces, target_faces=300, record=True)
    r.record.save(tmp_path / "r.qemr")
    run(cli, "replay", tmp_path / "r.qemr", "--faces", "3000", tmp_path / "cli.ply")
    qem.save(tmp_path / "py.ply", qem.Record.load(tmp_path / "r.qemr").replay(3000))
    assert (tmp_path / "py.ply").read_bytes() == (tmp_path / "cli.ply").read_bytes()


@pytest.mark.parametrize("kwargs, args", [
    (dict(target_ratio=0.1), ["--ratio", "0.1"]),
    (dict(target_ratio=0.25, per_mesh=True, seams="creases"), ["--ratio", "0.25", "--per-mesh", "--seams", "creases"]),
])
def test_simplify_gltf_same_bytes_as_cli(cli, shared_data, tmp_path, kwargs, args):
    # The document path: the same output bytes and the same per-primitive report as `qem simplify
    # in.glb out.glb`; a bad option or file is refused and writes nothing.
    src = shared_data / "CesiumMilkTruck.glb"
    out_cli, out_py = tmp_path / "cli.glb", tmp_path / "py.glb"
    report_cli = json.loads(run(cli, "simplify", src, out_cli, "--quiet", "--json", *args))
    r = qem.simplify_gltf(src, out_py, **kwargs)
    assert out_py.read_bytes() == out_cli.read_bytes()
    assert r["faces_out"] == report_cli["out_faces"] and r["faces_in"] == report_cli["in_faces"]
    assert [p["faces_out"] for p in r["primitives"]] == [e["out_faces"] for e in report_cli["each"]]
    assert [p["status"] for p in r["primitives"]] == [e["status"] for e in report_cli["each"]]
    assert r["simplified"] >= 3
    with pytest.raises(ValueError, match="unknown option"):
        qem.simplify_gltf(src, tmp_path / "x.glb", target_ratio=0.5, ratio=0.5)
    with pytest.raises(qem.Error):
        qem.simplify_gltf(tmp_path / "missing.glb", tmp_path / "y.glb", target_ratio=0.5)
    assert not (tmp_path / "x.glb").exists() and not (tmp_path / "y.glb").exists()
