"""simplify: results, provenance maps, records, progress and cancelling, the GIL, threads."""
import _thread
import threading
import time

import numpy as np
import pytest

import qem


def test_result_fields(small_torus):
    r = qem.simplify(*small_torus, target_ratio=0.25)
    assert len(r.faces) <= 900 and r.stop_reason == "target reached"
    assert r.max_error > 0 and r.stop_detail and r.contractions > 0
    assert r.vertex_source is None and r.record is None
    assert r.faces.min() >= 0 and r.faces.max() < len(r.vertices)
    assert "target_ratio" in qem.simplify.__doc__ and "fraction" in qem.simplify.__doc__


def test_stop_criteria(small_torus):
    r = qem.simplify(*small_torus, max_error_relative=1e-3, refit="none")
    assert r.stop_reason == "error limit reached" and r.max_error_relative <= 1e-3
    r = qem.simplify(*small_torus, target_vertices=100)
    assert len(r.vertices) <= 100


def test_distance_bound(small_torus):
    # Alone, the bound is the stop criterion; what was reached is reported and checked here with
    # qem.measure (independent samples): no output point farther than the bound from the input.
    v, f = small_torus
    r = qem.simplify(v, f, max_distance_relative=0.003)
    assert 0 < r.output_to_input_distance_relative <= 0.003
    assert r.rejected_distance > 0 and len(r.faces) < len(f)
    m = qem.measure((v, f), r, samples=200_000)
    assert m.h_approx_to_original <= 0.003 * m.bbox_diag
    absolute = qem.simplify(v, f, max_distance=0.003 * m.bbox_diag)  # the same bound, in model units
    assert 0 < absolute.output_to_input_distance <= 0.003 * m.bbox_diag
    assert abs(len(absolute.faces) - len(r.faces)) <= 0.02 * len(r.faces)
    unbounded = qem.simplify(v, f, target_ratio=0.5)
    assert unbounded.output_to_input_distance == 0 and unbounded.rejected_distance == 0
    with pytest.raises(ValueError):
        qem.simplify(v, f, max_distance=0.1, max_distance_relative=0.1)
    with pytest.raises(ValueError):
        qem.simplify(v, f, max_distance=-1)


def test_threads_give_the_same_bytes(large_torus):
    v, f = large_torus
    a = qem.simplify(v, f, target_ratio=0.1, threads=1)
    b = qem.simplify(v, f, target_ratio=0.1, threads=2)
    assert a.vertices.tobytes() == b.vertices.tobytes() and a.faces.tobytes() == b.faces.tobytes()


def test_mapping(small_torus):
    """Provenance: maps agree with each other and with the faces; an output vertex lies at its
    source (never contracted) or within the run's error of the planes of the vertices merged into it."""
    v, f = small_torus
    # forget=0: the bound below is GH97's, of quadrics that remember every input plane.
    r = qem.simplify(v, f, target_faces=400, weighting="uniform", refit="none", forget=0, return_mapping=True)
    to_out = r.output_vertex_of_input
    assert to_out.shape == (len(v),) and to_out.dtype == np.int32
    assert r.vertex_source.shape == (len(r.vertices),) and r.face_source.shape == (len(r.faces),)
    # Every output vertex's source went into it; every output face is its source face renamed.
    np.testing.assert_array_equal(to_out[r.vertex_source], np.arange(len(r.vertices)))
    np.testing.assert_array_equal(to_out[f[r.face_source]], r.faces)
    # Vertices that took part in no contraction keep their exact coordinates.
    merged = np.bincount(to_out[to_out >= 0], minlength=len(r.vertices))
    alone = merged == 1
    np.testing.assert_array_equal(r.vertices[alone], v[r.vertex_source[alone]])
    # The others: RMS distance to the planes of every input face corner merged into them (the
    # vertex's quadric, uniform weights) within the largest contraction error.
    p0, p1, p2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    n = np.cross(p1 - p0, p2 - p0)
    n /= np.linalg.norm(n, axis=1)[:, None]
    offset = -np.einsum("ij,ij->i", n, p0)
    corners_out = to_out[f]  # (m, 3): the output vertex of each corner
    d2 = np.zeros(len(r.vertices))
    count = np.zeros(len(r.vertices))
    for c in range(3):
        o = corners_out[:, c]
        dist = np.einsum("ij,ij->i", n, r.vertices[o]) + offset
        np.add.at(d2, o, dist**2)
        np.add.at(count, o, 1)
    rms = np.sqrt(d2 / count)
    assert (rms[~alone] <= r.max_error * (1 + 1e-3) + 1e-12).all(), (rms.max(), r.max_error)
    assert (np.linalg.norm(r.vertices - v[r.vertex_source], axis=1)[alone] == 0).all()


def test_mapping_carries_user_data(small_torus):
    v, f = small_torus
    colors = np.random.default_rng(1).random((len(v), 3))
    r = qem.simplify(v, f, target_ratio=0.2, return_mapping=True)
    out_colors = colors[r.vertex_source]  # the documented one-liner
    assert out_colors.shape == (len(r.vertices), 3)


def test_record_replays_exactly(small_torus):
    v, f = small_torus
    r = qem.simplify(v, f, target_faces=200, record=True)
    rec = r.record
    assert isinstance(rec, qem.Record) and len(rec) == r.contractions and rec.final_faces == len(r.faces)
    final = rec.replay(200)
    np.testing.assert_array_equal(final.vertices, r.vertices)
    np.testing.assert_array_equal(final.faces, r.faces)
    mid = rec.replay(1000)
    direct = qem.simplify(v, f, target_faces=1000, refit="none")
    assert mid.vertices.tobytes() == direct.vertices.tobytes() and mid.faces.tobytes() == direct.faces.tobytes()
    again = qem.Record.from_bytes(rec.to_bytes())
    assert again.replay(1000).faces.tobytes() == mid.faces.tobytes()


def test_progress_and_cancel(large_torus):
    seen = []
    r = qem.simplify(*large_torus, target_ratio=0.1, progress=seen.append)
    assert seen and seen[-1] == 1.0 and seen == sorted(seen)

    def stop(fraction):
        return fraction < 0.2

    r = qem.simplify(*large_torus, target_ratio=0.1, progress=stop)
    assert r.stop_reason == "cancelled" and len(r.faces) > 0.1 * len(large_torus[1])


def test_progress_exception_cancels_and_is_raised(large_torus):
    def boom(fraction):
        if fraction > 0.1:
            raise RuntimeError("from the callback")

    with pytest.raises(RuntimeError, match="from the callback"):
        qem.simplify(*large_torus, target_ratio=0.1, progress=boom)


def test_keyboard_interrupt_cancels(large_torus):
    started = threading.Event()

    def interrupt():
        started.wait(30)
        _thread.interrupt_main()  # as Ctrl-C: the signal arrives while the library runs

    threading.Thread(target=interrupt, daemon=True).start()
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        qem.simplify(*large_torus, target_faces=100, progress=lambda f: started.set())
        time.sleep(5)  # not reached when the run was cancelled
    # The interpreter goes on working normally afterwards.
    assert time.perf_counter() - t0 < 30
    assert len(qem.simplify(*large_torus, target_ratio=0.5).faces) > 0


def test_gil_is_released(large_torus):
    """A second Python thread keeps running while a large simplification runs."""
    v, f = large_torus
    ticks = []
    running = threading.Event()
    done = threading.Event()

    def other():
        running.set()
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=other)
    t.start()
    running.wait()
    t0 = time.perf_counter()
    qem.simplify(v, f, target_faces=1000, threads=1)
    t1 = time.perf_counter()
    done.set()
    t.join()
    during = [x for x in ticks if t0 <= x <= t1]
    # With the GIL held the other thread would get no tick in; released, about one a millisecond
    # (fewer on a loaded machine: the bound is loose).
    assert t1 - t0 > 0.1
    assert len(during) >= max(10, 0.05 * (t1 - t0) / 0.001), (len(during), t1 - t0)


def test_help_is_the_manual():
    for fn in (qem.simplify, qem.load, qem.save, qem.measure, qem.cluster, qem.info, qem.lod, qem.Record.replay):
        assert fn.__doc__ and len(fn.__doc__) > 40, fn


def test_option_names_are_the_librarys():
    assert qem.option_names("placement") == ["optimal", "segment", "midpoint", "endpoints"]
    assert "passes" in qem.option_names("scheme") and "forbid" in qem.option_names("inversion")
    with pytest.raises(ValueError, match="weighting"):
        qem.simplify(np.eye(3), [[0, 1, 2]], target_faces=1, weighting="areal")


def test_components_and_target_zero():
    # Two separate open squares, one tiny: kept by default, removed by prune, and a target of 0
    # goes as far as the checks allow (each square down to one face). With GH97's penalty borders
    # (exact_border=False): exact borders hold a square's four corners, so it never comes near
    # vanishing and the component guard would have nothing to refuse.
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0.1]], float)
    quad = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    v = np.vstack([square, square * 0.01 + [3, 0, 0]])
    f = np.vstack([quad, quad + 5])
    r = qem.simplify(v, f, target_faces=0, refit="none", exact_border=False)
    assert r.input_components == 2 and r.output_components == 2 and r.pruned_components == 0
    assert r.stop_reason == "no valid contraction left" and r.rejected_component > 0
    assert len(r.faces) == 2
    r = qem.simplify(v, f, target_faces=0, prune=0.1, refit="none", exact_border=False)
    assert r.pruned_components == 1 and r.output_components == 1
    gone = qem.simplify(v, f, target_faces=0, keep_components=False, refit="none", exact_border=False)
    assert len(gone.faces) == 0
    with pytest.raises(ValueError):
        qem.simplify(v, f, target_faces=-1)


def test_far_repair_follows_the_refit(small_torus):
    # On by default with the light refit (as the command line), off without it or when asked; it
    # flips edges and moves vertices, but keeps the counts.
    kept = qem.simplify(*small_torus, target_faces=200, far_repair=False)
    repaired = qem.simplify(*small_torus, target_faces=200)
    assert kept.edge_flips == kept.vertex_moves == kept.vertex_relocations == 0
    assert repaired.edge_flips + repaired.vertex_moves > 0
    assert len(kept.faces) == len(repaired.faces) and len(kept.vertices) == len(repaired.vertices)
    none = qem.simplify(*small_torus, target_faces=200, refit="none")
    assert none.edge_flips == none.vertex_moves == none.vertex_relocations == 0
    alone = qem.simplify(*small_torus, target_faces=200, refit="none", far_repair=True)
    assert alone.edge_flips + alone.vertex_moves > 0
    with pytest.raises(ValueError, match="far_repair"):
        qem.simplify(*small_torus, target_faces=200, record=True, far_repair=True)


def test_forget_follows_the_command_line(small_torus):
    # On by default (0.85, as the command line); 0 keeps GH97's remembering quadrics (the library's
    # default); a factor outside [0, 1) is refused by name.
    v, f = small_torus
    default = qem.simplify(v, f, target_faces=1000, refit="none")
    explicit = qem.simplify(v, f, target_faces=1000, refit="none", forget=0.85)
    remember = qem.simplify(v, f, target_faces=1000, refit="none", forget=0)
    assert default.vertices.tobytes() == explicit.vertices.tobytes()
    assert default.vertices.tobytes() != remember.vertices.tobytes()
    for bad in (1.0, -0.5, True, "0.5"):
        with pytest.raises(ValueError, match="forget"):
            qem.simplify(v, f, target_faces=1000, forget=bad)


def test_forget_attributes_is_asked_for(small_torus):
    # With attributes the quadrics remember unless forget_attributes asks (the library's rule).
    v, f = small_torus
    normals = {"NORMAL": v / np.linalg.norm(v, axis=1)[:, None]}
    plain = qem.simplify(v, f, target_faces=1000, refit="none", attributes=normals)
    remember = qem.simplify(v, f, target_faces=1000, refit="none", attributes=normals, forget=0)
    asked = qem.simplify(v, f, target_faces=1000, refit="none", attributes=normals, forget_attributes=True)
    assert plain.vertices.tobytes() == remember.vertices.tobytes()
    assert asked.vertices.tobytes() != plain.vertices.tobytes()
    assert np.allclose(np.linalg.norm(asked.attributes["NORMAL"], axis=1), 1.0)


def _open_edges(v, f):
    """Edges (welded by position) that only one face uses."""
    _, weld = np.unique(np.asarray(v), axis=0, return_inverse=True)
    w = weld.reshape(-1)[np.asarray(f)]
    e = np.sort(np.concatenate([w[:, [0, 1]], w[:, [1, 2]], w[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return int((counts == 1).sum())


def test_two_sided():
    # A wavy sheet made two-sided by a reversed copy of each face: its rim is closed in the input and
    # stays closed with two_sided="rims" (the default) or "all", the twins counted in the target.
    n = 16
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    v = np.stack([x.ravel(), y.ravel(), 0.1 * np.sin(5 * x.ravel()) * np.cos(4 * y.ravel())], axis=1)
    i = np.arange(n * n).reshape(n, n)
    a, b, c, d = i[:-1, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, :-1].ravel(), i[1:, 1:].ravel()
    front = np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, c], 1)])
    f = np.concatenate([front, front[:, ::-1]]).astype(np.uint32)
    assert _open_edges(v, f) == 0
    r = qem.simplify(v, f, target_faces=100)
    assert 0 < r.twin_faces < len(r.faces) / 2 and r.dropped_duplicate_faces == len(front)
    assert 90 <= len(r.faces) <= 100
    assert _open_edges(r.vertices, r.faces) == 0
    both = qem.simplify(v, f, target_faces=100, two_sided="all")
    assert 2 * both.twin_faces == len(both.faces) and 90 <= len(both.faces) <= 100
    assert _open_edges(both.vertices, both.faces) == 0
    one = qem.simplify(v, f, target_faces=100, two_sided="none")
    assert one.twin_faces == 0 and _open_edges(one.vertices, one.faces) > 0
    assert qem.option_names("two_sided") == ["rims", "all", "none"]
    with pytest.raises(ValueError, match="two_sided"):
        qem.simplify(v, f, target_faces=100, two_sided=True)


def test_seams_mode_creases_crosses_them(small_torus):
    # Every edge a normal crease (each face its own vertices and its normal): strict seams keep
    # every crease and stop far above the target; "creases" crosses them where the error allows,
    # and so does the default ("junctions": every vertex here is where six creases meet, so it may
    # merge into a neighbour); no crack opens either way.
    v, f = small_torus
    corners = np.asarray(v)[np.asarray(f)].reshape(-1, 3)
    faces = np.arange(len(corners), dtype=np.int32).reshape(-1, 3)
    n = np.cross(corners[1::3] - corners[0::3], corners[2::3] - corners[0::3])
    normals = {"NORMAL": np.repeat(n / np.linalg.norm(n, axis=1)[:, None], 3, axis=0)}
    strict = qem.simplify(corners, faces, target_faces=300, attributes=normals, seams="strict")
    creases = qem.simplify(corners, faces, target_faces=300, attributes=normals, seams="creases")
    junctions = qem.simplify(corners, faces, target_faces=300, attributes=normals)
    assert len(creases.faces) < len(strict.faces) and len(junctions.faces) < len(strict.faces)
    assert len(junctions.faces) <= 300
    for r in (strict, creases, junctions):
        assert _open_edges(r.vertices, r.faces) == 0
    with pytest.raises(ValueError, match="seams"):
        qem.simplify(corners, faces, target_faces=300, seams="loose")
