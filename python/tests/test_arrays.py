"""Arrays in: every dtype and order gives the same result; every bad input is a ValueError naming it."""
import numpy as np
import pytest

import qem


def reference(mesh):
    v, f = mesh
    return qem.simplify(v, f, target_faces=500, refit="none")


@pytest.mark.parametrize("vdtype", [np.float32, np.float64, np.float16])
@pytest.mark.parametrize("fdtype", [np.int32, np.int64, np.uint32, np.uint64, np.int16])
@pytest.mark.parametrize("order", ["C", "F"])
def test_every_dtype_and_order(small_torus, vdtype, fdtype, order):
    v, f = small_torus
    v_in = np.asarray(v, dtype=vdtype, order=order)
    f_in = np.asarray(f, dtype=fdtype, order=order)
    r = qem.simplify(v_in, f_in, target_faces=500, refit="none")
    # The same coordinates (as doubles) give the same output whatever the container.
    expected = qem.simplify(v_in.astype(np.float64), f, target_faces=500, refit="none")
    assert r.vertices.dtype == np.float64 and r.faces.dtype == np.int32
    assert r.vertices.shape[1] == 3 and r.faces.shape == (len(r.faces), 3)
    np.testing.assert_array_equal(r.vertices, expected.vertices)
    np.testing.assert_array_equal(r.faces, expected.faces)


def test_strided_views_and_lists(small_torus):
    v, f = small_torus
    wide = np.zeros((len(v), 6))
    wide[:, ::2] = v  # a non-contiguous view
    r = qem.simplify(wide[:, ::2], f, target_faces=500, refit="none")
    expected = reference(small_torus)
    np.testing.assert_array_equal(r.faces, expected.faces)
    r2 = qem.simplify(v.tolist(), f.tolist(), target_faces=500, refit="none")
    np.testing.assert_array_equal(r2.faces, expected.faces)


def test_outputs_own_their_memory(small_torus):
    r = reference(small_torus)
    for a in (r.vertices, r.faces):
        assert a.flags.c_contiguous
        a[0] = a[0]  # writable
    # Handed over from the library's vectors (a capsule frees them), not copied.
    assert type(r.vertices.base).__name__ == "PyCapsule" and type(r.faces.base).__name__ == "PyCapsule"
    v2 = r.vertices
    del r
    assert np.isfinite(v2).all()  # still valid after the result is gone


@pytest.mark.parametrize(
    "make, name, words",
    [
        (lambda v, f: (v[:, :2], f), "vertices", "shape"),
        (lambda v, f: (v.ravel(), f), "vertices", "shape"),
        (lambda v, f: (v, f[:, :2]), "faces", "shape"),
        (lambda v, f: (v, f.astype(np.float64)), "faces", "integer"),
        (lambda v, f: (v.astype(str), f), "vertices", "float"),
        (lambda v, f: (v, np.where(f == 5, len(v), f)), "faces", "out of range"),
        (lambda v, f: (v, np.where(f == 5, -1, f)), "faces", "out of range"),
        (lambda v, f: (v, np.where(f == 5, -1, f).astype(np.int64)), "faces", "out of range"),
        (lambda v, f: (np.where(np.arange(len(v))[:, None] == 3, np.nan, v), f), "vertices", "nan"),
        (lambda v, f: (np.where(np.arange(len(v))[:, None] == 3, np.inf, v), f), "vertices", "inf"),
        (lambda v, f: (None, f), "vertices", "None"),
        (lambda v, f: ("abc", f), "vertices", ""),
    ],
)
def test_bad_arrays(small_torus, make, name, words):
    v, f = make(*small_torus)
    with pytest.raises(ValueError) as e:
        qem.simplify(v, f, target_faces=100)
    assert str(e.value).startswith(name), str(e.value)
    assert words in str(e.value), str(e.value)


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(), "no stop criterion"),
        (dict(target_ratio=-0.1), "target_ratio"),
        (dict(target_faces=-3), "target_faces"),
        (dict(target_faces=1.5), "target_faces"),
        (dict(target_ratio=1.5), "target_ratio"),
        (dict(target_ratio=float("nan")), "target_ratio"),
        (dict(max_error=-1), "max_error"),
        (dict(target_faces=10, weighting="areal"), "weighting"),
        (dict(target_faces=10, placement=3), "placement"),
        (dict(target_faces=10, threads=-1), "threads"),
        (dict(target_faces=10, refit="heavy"), "refit"),
        (dict(target_faces=10, record=True, refit="full"), "refit"),
        (dict(target_faces=10, progress=3), "progress"),
        (dict(target_faces=10, attributes=[1]), "attributes"),
        (dict(target_faces=10, attributes={"COLOR_0": np.zeros((3, 3))}), "attributes['COLOR_0']"),
        (dict(target_faces=10, attributes={"x": (np.zeros((3600, 3)), "colour")}), "attributes['x']"),
    ],
)
def test_bad_options(small_torus, kwargs, name):
    with pytest.raises(ValueError) as e:
        qem.simplify(*small_torus, **kwargs)
    assert name in str(e.value), str(e.value)


def test_library_errors_are_qem_error(small_torus):
    assert issubclass(qem.Error, ValueError)
    with pytest.raises(qem.Error, match="inversion angle"):
        qem.simplify(*small_torus, target_faces=10, max_turn=95)
    with pytest.raises(qem.Error):
        qem.load("/nonexistent/mesh.ply")


def test_vertex_lock_keeps_the_locked_vertices(small_torus):
    v, f = small_torus
    lock = np.zeros(len(v), bool)
    lock[::37] = True
    r = qem.simplify(v, f, target_faces=300, vertex_lock=lock, return_mapping=True)
    out = r.output_vertex_of_input[lock]
    assert (out >= 0).all()
    assert np.array_equal(r.vertices[out], v[lock])
    with pytest.raises(ValueError, match="vertex_lock"):
        qem.simplify(v, f, target_faces=10, vertex_lock=np.zeros(5, bool))


def test_empty_and_tiny_meshes_do_not_crash():
    for v, f in [(np.zeros((0, 3)), np.zeros((0, 3), np.int32)),
                 (np.eye(3), np.array([[0, 1, 2]])),
                 (np.zeros((3, 3)), np.array([[0, 1, 2]]))]:
        try:
            r = qem.simplify(v, f, target_faces=1)
            assert len(r.faces) <= 1
        except ValueError:
            pass


def test_attributes_are_checked_and_passed(small_torus):
    v, f = small_torus
    r = qem.simplify(v, f, target_faces=500, attributes={"NORMAL": v / np.linalg.norm(v, axis=1)[:, None],
                                                         "TEXCOORD_0": v[:, :2].astype(np.float32),
                                                         "k1": v[:, 0]})
    assert set(r.attributes) == {"NORMAL", "TEXCOORD_0", "k1"}
    n = r.attributes["NORMAL"]
    assert n.shape == (len(r.vertices), 3)
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0)
    assert r.attributes["TEXCOORD_0"].shape == (len(r.vertices), 2)
    # The weights change the result; a bad kind is named.
    heavy = qem.simplify(v, f, target_faces=500, attributes={"NORMAL": v / np.linalg.norm(v, axis=1)[:, None]},
                         attribute_weights={"normal": 10.0})
    light = qem.simplify(v, f, target_faces=500, attributes={"NORMAL": v / np.linalg.norm(v, axis=1)[:, None]},
                         attribute_weights={"normal": 0.0})
    assert not np.array_equal(heavy.vertices, light.vertices)
    # By default the normal weight grows to the output's spacing; a normal weight given alone is the
    # weight, as normal_per_spacing 0 makes it.
    normals = {"NORMAL": v / np.linalg.norm(v, axis=1)[:, None]}
    by_default = qem.simplify(v, f, target_faces=100, attributes=normals)
    fixed = qem.simplify(v, f, target_faces=100, attributes=normals, attribute_weights={"normal": 0.01})
    unscaled = qem.simplify(v, f, target_faces=100, attributes=normals, attribute_weights={"normal_per_spacing": 0.0})
    assert not np.array_equal(by_default.vertices, fixed.vertices)
    assert np.array_equal(fixed.vertices, unscaled.vertices)
    # The colour weight likewise (three spacings, up to 0.4).
    colours = {"COLOR_0": np.random.default_rng(7).random((len(v), 3))}
    by_default = qem.simplify(v, f, target_faces=100, attributes=colours)
    fixed = qem.simplify(v, f, target_faces=100, attributes=colours, attribute_weights={"color": 0.1})
    unscaled = qem.simplify(v, f, target_faces=100, attributes=colours, attribute_weights={"color_per_spacing": 0.0})
    assert not np.array_equal(by_default.vertices, fixed.vertices)
    assert np.array_equal(fixed.vertices, unscaled.vertices)
    # The result says which weights the run used.
    assert by_default.color_weight > 0.1 and fixed.color_weight == 0.1
    assert by_default.normal_weight == 0 and fixed.normal_weight == 0
    with pytest.raises(ValueError, match="gloss"):
        qem.simplify(v, f, target_faces=500, attributes={"NORMAL": v}, attribute_weights={"gloss": 1.0})
    with pytest.raises(ValueError, match="record"):
        qem.simplify(v, f, target_faces=500, attributes={"NORMAL": v}, record=True)


def test_bad_input_to_the_other_functions(small_torus):
    v, f = small_torus
    bad_f = f.copy()
    bad_f[7, 1] = len(v)
    for call in (lambda: qem.info(v, bad_f), lambda: qem.cluster(v, bad_f, grid=(4, 4, 4)),
                 lambda: qem.lod(v, bad_f, ratios=[0.5]), lambda: qem.save("/tmp/x.ply", (v, bad_f))):
        with pytest.raises(ValueError, match="faces"):
            call()
    with pytest.raises(ValueError, match="approx.faces"):
        qem.measure((v, f), (v, bad_f))
    with pytest.raises(ValueError, match="original"):
        qem.measure(42, (v, f))
    with pytest.raises(ValueError, match="grid"):
        qem.cluster(v, f, grid=(4, 4))
    with pytest.raises(ValueError, match="exactly one"):
        qem.cluster(v, f)
    with pytest.raises(ValueError, match="ratios"):
        qem.lod(v, f, ratios=[1.5])
    with pytest.raises(ValueError, match="samples"):
        qem.measure((v, f), (v, f), samples=0)
    with pytest.raises(qem.Error):
        qem.Record.from_bytes(b"not a record")


def test_measure_reports_the_attribute_error(small_torus):
    v, f = small_torus
    normals = v / np.linalg.norm(v, axis=1)[:, None]
    original = qem.Mesh(v, f, {"NORMAL": normals})
    r = qem.simplify(v, f, target_faces=500, attributes={"NORMAL": normals})
    m = qem.measure(original, r, samples=20000)
    assert m.normal_rms_deg is not None and 0 < m.normal_rms_deg < 30
    assert m.uv_rms is None and m.color_rms is None
    assert m.seam_cracks == 0
    assert qem.measure(original, original, samples=20000).normal_rms_deg < 1e-3


def test_attribute_fit_lowers_the_colour_error_and_keeps_the_geometry(small_torus):
    # A colour that varies faster than the output's faces: the fit after the run (fit_attributes,
    # the CLI's --attribute-fit) sets each vertex's values by least squares against the input, so
    # the measured colour error falls while positions and faces stay those of the run without it.
    v, f = small_torus
    colour = np.stack([0.5 + 0.5 * np.sin(9 * v[:, 0]) * np.cos(7 * v[:, 1]), 0.5 + 0.4 * np.tanh(v[:, 2]),
                       np.full(len(v), 0.2)], axis=1)
    original = qem.Mesh(v, f, {"COLOR_0": colour})
    plain = qem.simplify(v, f, target_faces=500, attributes={"COLOR_0": colour})
    fitted = qem.simplify(v, f, target_faces=500, attributes={"COLOR_0": colour}, fit_attributes=True)
    assert np.array_equal(plain.vertices, fitted.vertices) and np.array_equal(plain.faces, fitted.faces)
    assert not np.array_equal(plain.attributes["COLOR_0"], fitted.attributes["COLOR_0"])
    before = qem.measure(original, plain, samples=50000).color_rms
    after = qem.measure(original, fitted, samples=50000).color_rms
    assert after < 0.95 * before, (before, after)
    assert fitted.attributes["COLOR_0"].min() >= 0 and fitted.attributes["COLOR_0"].max() <= 1
