"""qem: triangle mesh simplification with quadric error metrics (Garland & Heckbert 1997), on numpy.

    import qem
    mesh = qem.load("bunny.ply")
    result = qem.simplify(mesh.vertices, mesh.faces, target_ratio=0.1)
    qem.save("bunny_10.ply", result)
    print(result.max_error, result.stop_detail, qem.measure(mesh, result).E)

Arrays in: vertices (n, 3) of any float (or integer) dtype, faces (m, 3) of any integer dtype, in C
or Fortran order. float64 vertices and int32/uint32 faces in C order are read in place (no copy);
anything else is converted once. Arrays out: vertices float64 (n, 3), faces int32 (m, 3) (int64
only for meshes of 2**31 vertices or more), maps int32; all of them own their memory.

Bad input raises ValueError naming the argument (shape, dtype, index out of range, NaN); what the
library refuses raises qem.Error, a subclass of ValueError.
"""

from __future__ import annotations

import inspect as _inspect
import math as _math
import re as _re
from typing import Callable, Optional

from . import _qem

__all__ = [
    "Error",
    "Mesh",
    "SimplifyResult",
    "Record",
    "Measure",
    "Level",
    "simplify",
    "simplify_gltf",
    "load",
    "save",
    "measure",
    "cluster",
    "info",
    "lod",
    "option_names",
]

Error = _qem.Error
Error.__doc__ = "A failure the library reports (bad option, unreadable file, bad mesh); a ValueError."
# The command line's forgetting factor (qem::kRecommendedForget), the default here too.
_FORGET = _qem.RECOMMENDED_FORGET


class Mesh:
    """A triangle mesh: `vertices` (n, 3) float64, `faces` (m, 3) int32, `attributes` {name: array}.

    Any object with `.vertices` and `.faces` (or a `(vertices, faces)` pair) is accepted where a
    mesh is expected; this class is what qem returns.
    """

    __slots__ = ("vertices", "faces", "attributes", "attribute_kinds")

    def __init__(self, vertices, faces, attributes=None, attribute_kinds=None):
        self.vertices = vertices
        self.faces = faces
        self.attributes = dict(attributes or {})
        self.attribute_kinds = dict(attribute_kinds or {})

    def __iter__(self):  # so that `vertices, faces = mesh` works
        return iter((self.vertices, self.faces))

    def __repr__(self):
        return f"qem.Mesh({len(self.vertices)} vertices, {len(self.faces)} faces)"


def _mesh_from_dict(d, cls=None, **extra):
    attributes = {name: a["values"] for name, a in d["attributes"].items()}
    kinds = {name: a["kind"] for name, a in d["attributes"].items()}
    m = (cls or Mesh).__new__(cls or Mesh)
    Mesh.__init__(m, d["vertices"], d["faces"], attributes, kinds)
    for k, v in extra.items():
        setattr(m, k, v)
    return m


class Record:
    """The progressive record of one run (GH97 §3): the base mesh and its contraction sequence.

    `record.replay(faces)` rebuilds, bit for bit, the mesh `simplify` returns for a target of
    `faces` (with the same options, refit off), for any count between `final_faces` and
    `base_faces`. `save(path)` / `Record.load(path)` use the file format of
    docs/record-format.md, which `qem replay` and `qem lod` read too.
    """

    __slots__ = ("_record",)

    def __init__(self, record):
        if not isinstance(record, _qem.Record):
            raise TypeError("qem.Record is made by qem.simplify(..., record=True) or Record.load(path)")
        self._record = record

    def replay(self, faces: int) -> Mesh:
        """The mesh after the shortest prefix of contractions that leaves at most `faces` faces."""
        if faces < 0:
            raise ValueError(f"faces: must not be negative, got {faces}")
        return _mesh_from_dict(self._record.replay(int(faces)))

    def save(self, path: str) -> None:
        """Writes the record (atomically: a temporary file beside `path`, then renamed)."""
        self._record.save(str(path))

    @staticmethod
    def load(path: str) -> "Record":
        """Reads and validates a record file; qem.Error if it is malformed."""
        return Record(_qem.Record.load(str(path)))

    def to_bytes(self) -> bytes:
        """The record file's bytes."""
        return self._record.to_bytes()

    @staticmethod
    def from_bytes(data: bytes) -> "Record":
        """Parses and validates a record held in memory."""
        return Record(_qem.Record.from_bytes(bytes(data)))

    def __len__(self):
        """The number of contractions."""
        return len(self._record)

    @property
    def base_faces(self) -> int:
        """Faces of the base mesh (the input without degenerate and duplicate faces)."""
        return self._record.base_faces

    @property
    def base_vertices(self) -> int:
        """Vertices of the base mesh (the input's referenced vertices)."""
        return self._record.base_vertices

    @property
    def final_faces(self) -> int:
        """Faces after every contraction: the smallest count a replay reaches."""
        return self._record.final_faces

    def __repr__(self):
        return f"qem.Record({len(self)} contractions, {self.base_faces} -> {self.final_faces} faces)"


class SimplifyResult(Mesh):
    """What `simplify` returns: a Mesh plus how the run went.

    vertices, faces, attributes: the approximation (attributes only as given to simplify).
    max_error: the largest contraction error made (distance units); max_error_relative: over the
      bounding-box diagonal.
    stop_reason: "target reached", "error limit reached", "no valid contraction left",
      "input already at or below target" or "cancelled" (the CLI's --json "stop");
      stop_detail: a sentence saying why.
    contractions, input_faces, input_vertices, refit_rounds, refit_rms_before, refit_rms_after,
      edge_flips, vertex_moves, vertex_relocations, dropped_degenerate_faces, dropped_duplicate_faces,
      twin_faces: counts as in qem::SimplifyResult.
    input_components, output_components: connected components of the input and the output
      (vertex-connected); pruned_components: removed by `prune`; rejected_component: contractions
      refused because a component would have dropped below its floor (keep_components).
    output_to_input_distance (model units) and output_to_input_distance_relative (over the
      diagonal): with max_distance, the largest sampled distance from the output to the input
      (0 without); rejected_distance: contractions refused for the bound.
    normal_weight, color_weight: the attribute weights the run used, after the spacing rules of
      attribute_weights (0 when the input has no normals, no colours).
    With return_mapping=True (else None):
      vertex_source: (n_out,) int32, the input vertex each output vertex started from;
      face_source: (m_out,) int32, the input face each output face is;
      output_vertex_of_input: (n_in,) int32, the output vertex each input vertex was contracted
        into, -1 for unreferenced input vertices and parts that vanished.
    record: a qem.Record with record=True, else None.
    """

    __slots__ = (
        "max_error", "max_error_relative", "stop_reason", "stop_detail", "contractions", "input_faces",
        "input_vertices", "refit_rounds", "refit_rms_before", "refit_rms_after", "edge_flips", "vertex_moves", "vertex_relocations", "dropped_degenerate_faces",
        "dropped_duplicate_faces", "twin_faces", "rejected_component", "input_components", "output_components",
        "pruned_components", "output_to_input_distance", "output_to_input_distance_relative",
        "rejected_distance", "normal_weight", "color_weight", "vertex_source", "face_source",
        "output_vertex_of_input", "record",
    )

    def __repr__(self):
        return (f"qem.SimplifyResult({len(self.vertices)} vertices, {len(self.faces)} faces, "
                f"max_error={self.max_error:.4g}, stop_reason={self.stop_reason!r})")


def option_names(option: str) -> list:
    """The accepted values of `weighting`, `placement`, `scheme`, `inversion`, `two_sided` or `seams`."""
    if option not in _OPTION_NAMES:
        raise ValueError(f"option: expected weighting, placement, scheme, inversion, two_sided or seams, got {option!r}")
    return list(_OPTION_NAMES[option])


# The library's names (src/option_names.cpp): one list, written once.
_OPTION_NAMES = {option: tuple(_qem.option_names(option)) for option in ("weighting", "placement", "scheme", "inversion",
                                                                             "two_sided", "seams")}

# The command line's default refit (cli/algorithm_options.h): two rounds, about 8 input vertices
# per output vertex, fewer at mild reductions (SimplifyOptions::refit_by_reduction), made only
# with optimal placement. "full" is `--refit`: 3 rounds, every vertex.
_REFIT = {"light": (2, 8.0), "full": (3, 0.0), "none": (0, 0.0)}

_KIND_OF_NAME = [
    (r"NORMAL", "normal"),
    (r"TEXCOORD_\d+", "texcoord"),
    (r"COLOR_\d+", "color"),
    (r"JOINTS_\d+", "joint_indices"),
    (r"WEIGHTS_\d+", "joint_weights"),
    (r"TANGENT", "tangent"),
]


def _attribute_list(attributes):
    """[(name, kind, values)] from {name: values or (values, kind)}; the kind from glTF names."""
    if attributes is None:
        return []
    if not isinstance(attributes, dict):
        raise ValueError("attributes: expected a dict {name: (n, k) array} or {name: (array, kind)}")
    out = []
    for name, value in attributes.items():
        if not isinstance(name, str):
            raise ValueError(f"attributes: names must be strings, got {name!r}")
        kind = None
        if isinstance(value, tuple) and len(value) == 2 and isinstance(value[1], str):
            value, kind = value
        if kind is None:
            kind = next((k for pattern, k in _KIND_OF_NAME if _re.fullmatch(pattern, name)), "scalar")
        out.append((name, kind, value))
    return out


def _options(*, target_faces, target_ratio, target_vertices, max_error, max_error_relative, threshold,
             max_distance=None, max_distance_relative=None,
             threshold_relative, weighting, placement, boundary_weight, lock_border, inversion, max_turn,
             allow_non_manifold, scheme, refit, threads, record, keep_components=True, prune=None,
             prune_relative=None, exact_border=True, forget=_FORGET, forget_attributes=False, two_sided="rims",
             seams="junctions"):
    o = _qem.SimplifyOptions()

    def count(name, value):
        if value is None:
            return 0
        if isinstance(value, bool) or not isinstance(value, (int,)) and not hasattr(value, "__index__"):
            raise ValueError(f"{name}: expected an integer, got {value!r}")
        value = int(value)
        if value < 0:
            raise ValueError(f"{name}: must not be negative, got {value}")
        return value

    def number(name, value):
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"{name}: expected a number, got {value!r}") from None
        if _math.isnan(value):
            raise ValueError(f"{name}: expected a number, got nan")
        return value

    # A target of 0 means "as far as the checks allow" (the library's as_far_as_possible).
    o.target_faces = count("target_faces", target_faces)
    o.target_vertices = count("target_vertices", target_vertices)
    if target_ratio is not None:
        r = number("target_ratio", target_ratio)
        if not 0 <= r <= 1:
            raise ValueError(f"target_ratio: the fraction of faces kept must be in [0, 1], got {r}")
        o.target_ratio = r
    o.as_far_as_possible = target_faces == 0 or target_vertices == 0 or target_ratio == 0
    o.keep_components = bool(keep_components)
    if prune is not None and prune_relative is not None:
        raise ValueError("give prune or prune_relative, not both")
    for name, value, relative in (("prune", prune, False), ("prune_relative", prune_relative, True)):
        if value is not None:
            d = number(name, value)
            if not 0 <= d < _math.inf:
                raise ValueError(f"{name}: expected a finite distance >= 0, got {d}")
            o.prune_size, o.prune_size_is_relative = d, relative
    if max_error is not None and max_error_relative is not None:
        raise ValueError("give max_error or max_error_relative, not both")
    for name, value, relative in (("max_error", max_error, False), ("max_error_relative", max_error_relative, True)):
        if value is not None:
            e = number(name, value)
            if e < 0:
                raise ValueError(f"{name}: must not be negative, got {e}")
            o.max_error, o.max_error_is_relative = e, relative
    if max_distance is not None and max_distance_relative is not None:
        raise ValueError("give max_distance or max_distance_relative, not both")
    for name, value, relative in (("max_distance", max_distance, False),
                                  ("max_distance_relative", max_distance_relative, True)):
        if value is not None:
            d = number(name, value)
            if not 0 <= d < _math.inf:
                raise ValueError(f"{name}: expected a finite distance >= 0, got {d}")
            o.max_distance, o.max_distance_is_relative = d, relative
    if (target_faces, target_ratio, target_vertices, max_error, max_error_relative, max_distance,
            max_distance_relative) == (None,) * 7:
        raise ValueError("no stop criterion: give target_faces, target_ratio, target_vertices, max_error, "
                         "max_error_relative, max_distance or max_distance_relative")
    if threshold and threshold_relative:
        raise ValueError("give threshold or threshold_relative, not both")
    if threshold_relative:
        o.threshold, o.threshold_is_relative = number("threshold_relative", threshold_relative), True
    else:
        o.threshold = number("threshold", threshold)
    for name, value in (("weighting", weighting), ("placement", placement), ("inversion", inversion),
                        ("scheme", scheme), ("two_sided", two_sided), ("seams", seams)):
        if not isinstance(value, str):
            raise ValueError(f"{name}: expected one of {', '.join(_OPTION_NAMES[name])}, got {value!r}")
        setattr(o, name, value)
    o.boundary_weight = number("boundary_weight", boundary_weight)
    o.lock_border = bool(lock_border)
    o.exact_border = bool(exact_border)
    o.max_normal_turn_degrees = number("max_turn", max_turn)
    o.preserve_topology = not allow_non_manifold
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 0:
        raise ValueError(f"threads: expected a count >= 0 (0 = all cores), got {threads!r}")
    o.threads = threads
    if isinstance(forget, bool) or not isinstance(forget, (int, float)) or not 0 <= forget < 1:
        raise ValueError(f"forget: expected a factor in [0, 1) (0 = never), got {forget!r}")
    o.forget = float(forget)
    o.forget_attributes = bool(forget_attributes)

    if refit in (None, False):
        refit = "none"
    if refit is True:
        refit = "full"
    if isinstance(refit, str):
        if refit not in _REFIT:
            raise ValueError(f"refit: expected 'light', 'full', 'none' or (rounds, points_per_vertex), got {refit!r}")
        explicit = refit == "full"
        rounds, points = _REFIT[refit]
        # The light default follows the command line: only with optimal placement (others keep
        # their vertices where they put them) and never with a record.
        if refit == "light" and (placement != "optimal" or record):
            rounds = 0
    else:
        try:
            rounds, points = refit
            rounds, points = int(rounds), float(points)
        except (TypeError, ValueError):
            raise ValueError(f"refit: expected 'light', 'full', 'none' or (rounds, points_per_vertex), "
                             f"got {refit!r}") from None
        explicit = rounds > 0
    if record and explicit:
        raise ValueError("refit: a record replays the contractions and the refit moves every vertex after them, "
                         "so record=True cannot be combined with a refit; use qem.lod, which refits each level")
    o.refit_rounds, o.refit_points_per_vertex = rounds, points
    o.refit_by_reduction = refit == "light"  # as the command line's: it follows the reduction
    o.far_repair = rounds > 0  # as the command line's: the repair of the far places finishes the refit
    return o


def simplify(vertices, faces, *, target_faces: Optional[int] = None, target_ratio: Optional[float] = None,
             target_vertices: Optional[int] = None, max_error: Optional[float] = None,
             max_error_relative: Optional[float] = None, max_distance: Optional[float] = None,
             max_distance_relative: Optional[float] = None, threshold: float = 0.0,
             threshold_relative: Optional[float] = None, weighting: str = "area", placement: str = "optimal",
             boundary_weight: float = 1.0, lock_border: bool = False, inversion: str = "forbid",
             max_turn: float = 75.0, allow_non_manifold: bool = False, scheme: str = "passes",
             forget: float = _FORGET, forget_attributes: bool = False, refit="light", threads: int = 0, keep_components: bool = True, prune: Optional[float] = None,
             prune_relative: Optional[float] = None, exact_border: bool = True, attributes: Optional[dict] = None,
             attribute_weights: Optional[dict] = None, fit_attributes: bool = False, vertex_lock=None,
             return_mapping: bool = False, far_repair: Optional[bool] = None, two_sided: str = "rims",
             seams: str = "junctions", record: bool = False, progress: Optional[Callable[[float], Optional[bool]]] = None) -> SimplifyResult:
    """Simplifies a triangle mesh by quadric-error pair contraction (Garland & Heckbert 1997).

    vertices: (n, 3) array, any float dtype; faces: (m, 3) array of vertex indices, any integer dtype.
    Stop criteria (at least one; they combine and the first reached wins):
      target_faces: stop at or below this many faces.
      target_ratio: the fraction of the input's faces kept, in [0, 1] (0.1 keeps 10 %).
      target_vertices: stop at or below this many vertices.
      A target of 0 means as far as the checks allow (topology, inversion, components, max_error).
      max_error: never make a contraction whose error exceeds this distance (model units): the
        weighted RMS distance of the new vertex to the planes it stands for.
      max_error_relative: the same as a fraction of the bounding-box diagonal.
      max_distance: no point of the output farther than this from the input surface (model units):
        each contraction's new faces are certified against the input (--max-distance); alone it
        means as few faces as the bound allows. max_distance_relative: the same over the diagonal.
        result.output_to_input_distance says what was reached.
    The algorithm (the command line's defaults, so the same options give the same bytes as `qem simplify`;
    the one difference: this is always the in-core run, `--partition off`, while the command line cuts
    meshes of 1M faces or more into parts by default, docs/parallel.md):
      threshold: vertices closer than this (model units) are pairs too, so separate parts can join
        (GH97 §3.2; 0 = edges only); threshold_relative: the same over the bounding-box diagonal.
      weighting: "area" (HG99), "uniform" (GH97), "angle".
      placement: "optimal", "segment", "midpoint", "endpoints".
      boundary_weight: weight of the planes that hold open borders in place (0 = none).
      lock_border: border vertices never move.
      exact_border: True (the default): border vertices stay on the input's border lines (at input
        vertices or sliding along input border edges); border ends and junctions fixed, corners
        (turns above 45 degrees) kept until the error reaches their size, holes down to three
        vertices closed once the error reaches their size (README, Boundaries). False = GH97's
        penalty planes alone (boundary_weight), as --penalty-borders.
      inversion: "forbid", "penalize" or "off": contractions that turn a face by more than max_turn degrees.
      allow_non_manifold: skip the link condition (edge collapses may make non-manifold edges).
      scheme: "passes" (fast) or "greedy" (GH97's heap: strictly cheapest first).
      forget: each time the faces fall by this factor, every quadric is made again from the current
        faces and border edges, so later contractions are ranked by what they do to the current
        surface (a lower mean error; not below 700 faces, not with max_error, with attributes only
        with forget_attributes); 0 = GH97's quadrics, which remember every plane.
      forget_attributes: with attributes, forget too: the attribute quadrics and seam planes are
        renewed with the positions' (a lower E on most assets; attribute errors may rise on some).
      refit: after the last contraction move the vertices to fit the input surface, faces fixed:
        "light" (default, as the command line: 2 rounds on ~8 input vertices per output vertex, fewer
        or none at mild reductions, only with optimal placement, without record and without texture
        coordinates or normals), "full" (3 rounds, every vertex), "none", or
        (rounds, points_per_vertex).
      far_repair: after the refit, flip edges, move interior vertices and relocate vertices from
        flat places to far ones where that lowers the local Hausdorff distance to the input without
        raising the local error (borders stay on the input's, seams stay); None (default): with the
        refit, as the command line.
      two_sided: where the input makes a sheet two-sided by a reversed copy of each face, one side
        is simplified and the copies come back on the output faces along the rims ("rims": the rims
        stay closed), on every output face whose input face had one ("all": both sides, for
        renderers that cull back faces), or on none ("none"); counted in the target
        (qem::SimplifyOptions::two_sided).
      threads: threads for the parallel parts (0 = all cores); the result is the same for any count.
      keep_components: every connected part keeps at least one face (a closed one four); False lets
        a part contract to nothing (GH97 as published).
      prune: remove whole the parts whose bounding-box diagonal is below this distance (model units);
        prune_relative: the same over the whole mesh's diagonal.
    Data carried along:
      attributes: {name: (n, k) array} of per-vertex data, or {name: (array, kind)}; the kind
        (normal, texcoord, color, joint_indices, joint_weights, tangent, scalar) follows glTF names
        (NORMAL, TEXCOORD_0, COLOR_0, ...) when not given. Returned in result.attributes by the
        simplified mesh: one vertex per wedge (a position may carry several attribute sets, split at
        seams), seams kept closed and in place, normals unit, colours in [0, 1].
      seams: "junctions" (the default): a collapse runs along a seam only, both sides together,
        but a vertex where three or more charts, creases or colours meet may merge into a
        neighbouring such vertex where the error allows (docs/attributes.md, "Seam junctions");
        "strict": those vertices never move;
        "creases": as strict along UV seams and material boundaries, but a normal crease or a colour
        boundary may be crossed where the error allows (lower E on hard-surface assets);
        "permissive": UV seams too, at the risk of smearing a texture (docs/attributes.md,
        "Permissive seams").
      attribute_weights: {"normal": w, "uv": w, "color": w, "scalar": w}: what a unit of each
        attribute costs against a unit of distance (1/w costs one bounding-box diagonal); the
        library's defaults otherwise. By default the normal weight is at least
        "normal_per_spacing" (1) times the spacing of the target's faces, sqrt(area / faces) in
        diagonals, so that coarse outputs keep small sharply turning parts, and the colour weight
        at least "color_per_spacing" (3) times it, up to 0.4; a "normal" or "color" given without
        its spacing factor is used as it is.
      fit_attributes: after the run (and the refit), fit each off-seam vertex's attribute values by
        least squares to the input's values at the points of the output closest to the input's
        faces (Hoppe 1996 §4.2; the command line's --attribute-fit). Positions and faces stay; seam
        and locked vertices keep their values. Off by default (docs/attributes.md, "The attribute fit").
      vertex_lock: (n,) truth values: a locked vertex never moves and is never removed.
      return_mapping: fill result.vertex_source, face_source and output_vertex_of_input.
      record: keep the contraction sequence in result.record (a qem.Record; no refit then).
    progress: called with the fraction done (0..1) every few thousand contractions; returning
      False cancels (result.stop_reason == "cancelled"). An exception it raises, or Ctrl-C
      (KeyboardInterrupt), cancels the run and is raised. The GIL is released while the library works.

    Returns a qem.SimplifyResult: vertices (float64), faces (int32), attributes, max_error,
    stop_reason, stop_detail and, with return_mapping, the provenance maps.
    Raises ValueError naming a bad argument, qem.Error for what the library refuses.
    """
    if attribute_weights is not None and not isinstance(attribute_weights, dict):
        raise ValueError("attribute_weights: expected a dict {kind: weight} with kinds normal, uv, color, scalar, "
                         "normal_per_spacing, color_per_spacing")
    if record and attributes:
        raise ValueError("record: a record keeps positions and faces only, and the attributes would be lost "
                         "on replay; simplify without record=True, or carry them with return_mapping")
    if progress is not None and not callable(progress):
        raise ValueError(f"progress: expected a callable taking the fraction done, got {progress!r}")
    options = _options(target_faces=target_faces, target_ratio=target_ratio, target_vertices=target_vertices,
                       max_error=max_error, max_error_relative=max_error_relative, max_distance=max_distance,
                       max_distance_relative=max_distance_relative, threshold=threshold,
                       threshold_relative=threshold_relative, weighting=weighting, placement=placement,
                       boundary_weight=boundary_weight, lock_border=lock_border, inversion=inversion,
                       max_turn=max_turn, allow_non_manifold=allow_non_manifold, scheme=scheme, refit=refit,
                       forget=forget, forget_attributes=forget_attributes, threads=threads, record=record, keep_components=keep_components, prune=prune,
                       prune_relative=prune_relative, exact_border=exact_border, two_sided=two_sided,
                       seams=seams)
    # The light default follows the command line here too: not on a mesh with texture coordinates
    # or normals, where it lowers E but raises their errors a little (docs/attributes.md, "Seams,
    # locks and the refit"); colours alone keep it; "full" or (rounds, points) still refits them,
    # holding every seam position.
    attribute_list = _attribute_list(attributes)
    if refit == "light" and any(kind in ("texcoord", "normal") for _, kind, _ in attribute_list):
        options.refit_rounds = 0
    if record and far_repair:
        raise ValueError("far_repair: a record replays the contractions, and the repair changes the mesh after them, "
                         "so record=True cannot be combined with far_repair=True")
    options.far_repair = options.refit_rounds > 0 if far_repair is None else bool(far_repair)
    options.map_input_vertices = bool(return_mapping)
    options.fit_attributes = bool(fit_attributes)
    if attribute_weights is not None:
        options.attribute_weights = attribute_weights
    d = _qem.simplify(vertices, faces, options, attribute_list, bool(record), progress, vertex_lock)
    result = _mesh_from_dict(d, SimplifyResult)
    for key in SimplifyResult.__slots__:
        if key in ("record",):
            continue
        setattr(result, key, d[key])
    if not return_mapping:
        result.vertex_source = result.face_source = result.output_vertex_of_input = None
    result.record = Record(d["record"]) if d["record"] is not None else None
    return result


def simplify_gltf(input, output, *, target_faces: Optional[int] = None, target_ratio: Optional[float] = None,
                  target_vertices: Optional[int] = None, max_error: Optional[float] = None,
                  max_error_relative: Optional[float] = None, max_distance: Optional[float] = None,
                  max_distance_relative: Optional[float] = None, per_mesh: bool = False, seams: str = "junctions",
                  attribute_weights: Optional[dict] = None, refit="none", far_repair: Optional[bool] = None,
                  threads: int = 0, **options) -> dict:
    """Simplifies a glTF document (.glb, or .gltf with its buffers) into another, as `qem simplify
    in.glb out.glb` does: every triangle primitive with its attributes (normals, texture coordinates,
    colours, skin weights, morph targets), materials, textures, nodes, skins, animations and
    extensions passed through. The target is the scene's, every primitive stopping at about the same
    error in world units (max_error and max_distance in world units too; *_relative of the scene's
    diagonal); per_mesh=True applies it to each primitive. Primitives of one mesh that meet are
    simplified together, so no crack opens between them. No refit by default (a document's
    primitives carry normals or texture coordinates, which the light refit would raise), as on the
    command line; refit="full" or (rounds, points) asks for one. The other keywords are
    qem.simplify's (weighting, placement, forget, max_turn...). The output is written to a temporary
    file and renamed: a failed run leaves none.

    Returns a dict: faces_in, faces_out, target_faces, world_threshold, max_world_error,
    simplified / unchanged / kept (counts of primitives), primitives (per primitive: mesh,
    primitive, status, faces_in, faces_out, world_scale, world_error, stop_reason, note) and notes
    (what was dropped or kept, about the input).
    Raises ValueError naming a bad argument, qem.Error for a file or options the library refuses.
    """
    unknown = set(options) - set(_GLTF_PASSED)
    if unknown:
        raise ValueError(f"simplify_gltf: unknown option(s) {', '.join(sorted(unknown))}")
    defaults = {**_GLTF_PASSED, **options}
    if attribute_weights is not None and not isinstance(attribute_weights, dict):
        raise ValueError("attribute_weights: expected a dict {kind: weight} with kinds normal, uv, color, scalar, "
                         "normal_per_spacing, color_per_spacing")
    o = _options(target_faces=target_faces, target_ratio=target_ratio, target_vertices=target_vertices,
                 max_error=max_error, max_error_relative=max_error_relative, max_distance=max_distance,
                 max_distance_relative=max_distance_relative, refit=refit, threads=threads, record=False,
                 seams=seams, **defaults)
    o.far_repair = o.refit_rounds > 0 if far_repair is None else bool(far_repair)
    if attribute_weights is not None:
        o.attribute_weights = attribute_weights
    return _qem.simplify_gltf(str(input), str(output), o, bool(per_mesh), threads)


# simplify's keywords that simplify_gltf passes on, with simplify's defaults (one place for them).
_GLTF_PASSED = {name: p.default for name, p in _inspect.signature(simplify).parameters.items()
                if name in ("threshold", "threshold_relative", "weighting", "placement", "boundary_weight",
                            "lock_border", "inversion", "max_turn", "allow_non_manifold", "scheme", "forget",
                            "forget_attributes", "keep_components", "prune", "prune_relative", "exact_border",
                            "two_sided")}


def load(path, *, weld: str = "auto") -> Mesh:
    """Reads a mesh file: OBJ, PLY (ASCII, binary little and big endian), STL (ASCII, binary), OFF.

    The format follows the extension (then the content). Polygons are triangulated (fan).
    weld: "auto" (STL only: its triangles store their own corners), "on" or "off": merge exactly
    coincident vertices. Returns a qem.Mesh (float64 vertices, int32 faces) with `double_precision`
    (a PLY that stored doubles) and `warnings` (what was read leniently). Raises qem.Error on a
    malformed or unreadable file, naming the file and the line.
    """
    return _loaded(_qem.load(str(path), weld))


class _LoadedMesh(Mesh):
    __slots__ = ("double_precision", "warnings")


def _loaded(d):
    m = _mesh_from_dict(d, _LoadedMesh)
    m.double_precision, m.warnings = d["double_precision"], list(d["warnings"])
    return m


def save(path, mesh, *, binary: bool = True, double: Optional[bool] = None) -> None:
    """Writes a mesh: OBJ, PLY, STL or OFF, by extension, atomically (temporary file, then renamed).

    mesh: a qem.Mesh / SimplifyResult, anything with .vertices and .faces (or an Open3D
    TriangleMesh), or a (vertices, faces) pair. binary: PLY and STL binary (little endian) or ASCII.
    double: PLY coordinates as double (default: as the loaded mesh was stored, else float; the
    command line writes a double PLY's simplification with doubles: pass double=True for that).
    The result of qem.simplify saved with the defaults is the same bytes as `qem simplify`'s output.
    """
    vertices, faces, attributes = _mesh_arrays(mesh, "mesh")
    if double is None:
        double = bool(getattr(mesh, "double_precision", False))
    _qem.save(str(path), vertices, faces, _attribute_list(attributes), bool(binary), bool(double))


def _mesh_arrays(mesh, name):
    if isinstance(mesh, (tuple, list)) and len(mesh) == 2:
        return mesh[0], mesh[1], None
    if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        attributes = getattr(mesh, "attributes", None)
        kinds = getattr(mesh, "attribute_kinds", {}) or {}
        if attributes:
            attributes = {k: (v, kinds[k]) if k in kinds else v for k, v in attributes.items()}
        return mesh.vertices, mesh.faces, attributes
    if hasattr(mesh, "vertices") and hasattr(mesh, "triangles"):  # Open3D TriangleMesh
        import numpy as np
        return np.asarray(mesh.vertices), np.asarray(mesh.triangles), None
    raise ValueError(f"{name}: expected a mesh (.vertices, .faces) or a (vertices, faces) pair, got {type(mesh).__name__}")


class Measure:
    """What `measure` returns (GH97 §6.1): distances in model units, *_rel over the original's diagonal.

    E: mean squared distance over both sample sets; rms = sqrt(E); mean; hausdorff (symmetric) and
    its one-sided parts h_original_to_approx, h_approx_to_original; bbox_diag, areas, sample counts;
    with attributes, uv_rms (UV units), normal_rms_deg, color_rms (None where either mesh lacks the
    attribute), and seam_cracks (open edges of the approximation, welded by position, beyond the
    original's: cracks_out - cracks_in).
    """

    def __init__(self, d):
        self.__dict__.update(d)

    def __repr__(self):
        return f"qem.Measure(E={self.E:.6g}, hausdorff={self.hausdorff:.6g}, rms={self.rms:.6g})"


def measure(original, approx, *, samples: int = 1_000_000, seed: int = 1, threads: int = 0) -> Measure:
    """The error between two surfaces from `samples` points spread uniformly by area over both.

    original, approx: meshes (.vertices and .faces, an Open3D TriangleMesh, or (vertices, faces)).
    Returns a qem.Measure with E (mean squared distance, GH97 §6.1), hausdorff, rms, mean and their
    *_rel over the original's bounding-box diagonal. Deterministic for a seed, any thread count.
    """
    if samples <= 0:
        raise ValueError(f"samples: must be positive, got {samples}")
    original_arrays, approx_arrays = _mesh_arrays(original, "original"), _mesh_arrays(approx, "approx")
    return Measure(_qem.measure(original_arrays[:2], approx_arrays[:2], int(samples), int(seed), int(threads),
                                _attribute_list(original_arrays[2]), _attribute_list(approx_arrays[2])))


def cluster(vertices, faces, *, grid=None, cell: Optional[float] = None, cell_relative: Optional[float] = None,
            placement: str = "quadric") -> Mesh:
    """Vertex clustering (Rossignac & Borrel 1993), the baseline GH97 compares against.

    grid: (nx, ny, nz) cells over the bounding box; or cell: the cells' edge length (model units);
    or cell_relative: the same as a fraction of the bounding-box diagonal. placement: "quadric"
    (Lindstrom 2000) or "mean". Returns a qem.Mesh.
    """
    given = [x is not None for x in (grid, cell, cell_relative)]
    if sum(given) != 1:
        raise ValueError("give exactly one of grid, cell and cell_relative")
    size = cell if cell is not None else cell_relative
    d = _qem.cluster(vertices, faces, list(grid) if grid is not None else [], float(size or 0),
                     cell_relative is not None, placement)
    return _mesh_from_dict(d)


class Info:
    """What `info` returns: counts (vertices, faces, edges, boundary_edges, boundary_loops,
    non_manifold_edges, non_manifold_vertices, components, duplicate_faces, degenerate_faces,
    zero_area_faces, orientation_conflicts, unreferenced_vertices), euler, genus (-1 unless a
    closed oriented manifold), watertight, manifold, bbox_min, bbox_max, diagonal."""

    def __init__(self, d):
        self.__dict__.update(d)

    def __repr__(self):
        return "qem.Info(" + ", ".join(f"{k}={v!r}" for k, v in self.__dict__.items()) + ")"


def info(vertices, faces) -> Info:
    """Topological and geometric facts about a mesh, as `qem info` prints them."""
    return Info(_qem.info(vertices, faces))


class Level(Mesh):
    """One level of `lod`: a Mesh plus target_faces, contractions (prefix length) and max_error."""

    __slots__ = ("target_faces", "contractions", "max_error")


def lod(vertices, faces, *, ratios=None, target_faces=None, refit="light", two_sided="rims", **options) -> list:
    """An LOD chain from one recorded run: levels finest first, as `qem lod` writes them.

    ratios: fractions of the input's faces kept, e.g. [0.5, 0.25, 0.1]; or target_faces: face
    counts (0: as far as the checks allow). Every other option of `simplify` (weighting, placement, threshold, ..., threads)
    applies; each level is refitted as `refit` says (the light refit by default, as the CLI).
    two_sided as in `simplify`: an input with reversed duplicate faces gets each level from a run of
    its own (a record holds no twins), as `qem lod` does.
    Returns a list of qem.Level (vertices, faces, target_faces, contractions, max_error).
    """
    if (ratios is None) == (target_faces is None):
        raise ValueError("give the levels as either ratios or target_faces")
    for bad in ("target_ratio", "target_vertices", "max_error", "max_error_relative", "record", "progress",
                "attributes", "return_mapping", "attribute_weights", "vertex_lock"):
        if bad in options:
            raise ValueError(f"{bad}: not an option of lod (the levels are its targets)")
    defaults = dict(threshold=0.0, threshold_relative=None, weighting="area", placement="optimal",
                    boundary_weight=1.0, lock_border=False, inversion="forbid", max_turn=75.0,
                    allow_non_manifold=False, scheme="passes", threads=0, keep_components=True, prune=None,
                    prune_relative=None, exact_border=True, forget=_FORGET)
    unknown = set(options) - set(defaults)
    if unknown:
        raise TypeError(f"lod() got unexpected keyword arguments: {', '.join(sorted(unknown))}")
    defaults.update(options)
    o = _options(target_faces=None, target_ratio=1.0, target_vertices=None, max_error=None,
                 max_error_relative=None, refit=refit, record=False, two_sided=two_sided, **defaults)
    o.target_ratio = 0
    levels = _qem.lod(vertices, faces, o, [int(n) for n in (target_faces or [])], [float(r) for r in (ratios or [])])
    out = []
    for d in levels:
        level = _mesh_from_dict(d, Level)
        level.target_faces, level.contractions, level.max_error = d["target_faces"], d["contractions"], d["max_error"]
        out.append(level)
    return out
