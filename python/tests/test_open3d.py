"""Open3D interoperability: a TriangleMesh in and out, as the README shows."""
import numpy as np
import pytest

import qem

o3d = pytest.importorskip("open3d")


def test_open3d_mesh_in_and_out():
    mesh = o3d.geometry.TriangleMesh.create_sphere(radius=1.0, resolution=40)
    # In: Open3D's arrays are float64 (n, 3) and int32 (m, 3): read in place, no copy.
    r = qem.simplify(np.asarray(mesh.vertices), np.asarray(mesh.triangles), target_ratio=0.25)
    # Out: qem's int32 faces are what Vector3iVector takes.
    out = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(r.vertices), o3d.utility.Vector3iVector(r.faces))
    assert len(out.triangles) == len(r.faces) <= 0.25 * len(mesh.triangles)
    assert out.is_edge_manifold()
    # A TriangleMesh is accepted wherever a mesh is expected.
    e = qem.measure(mesh, out, samples=20000)
    assert 0 < e.E < 1e-3 and e.hausdorff < 0.1


def test_trimesh_and_pyvista_shapes():
    """The arrays trimesh (mesh.vertices, mesh.faces int64) and PyVista (mesh.faces flat
    [3, a, b, c, ...]) hold, without those packages: the README's one-liners."""
    sphere = o3d.geometry.TriangleMesh.create_sphere(radius=1.0, resolution=20)
    v, f = np.asarray(sphere.vertices), np.asarray(sphere.triangles).astype(np.int64)
    r = qem.simplify(v, f, target_faces=200)  # trimesh: qem.simplify(mesh.vertices, mesh.faces, ...)
    pv_faces = np.hstack([np.full((len(f), 1), 3), f]).ravel()  # PyVista's PolyData.faces
    r2 = qem.simplify(v, pv_faces.reshape(-1, 4)[:, 1:], target_faces=200)
    assert r.faces.tobytes() == r2.faces.tobytes()
    back = np.hstack([np.full((len(r2.faces), 1), 3), r2.faces]).ravel()  # pv.PolyData(r.vertices, back)
    assert back.size == 4 * len(r2.faces)
