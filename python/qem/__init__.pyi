"""Type stubs of the qem package (the documentation is in the docstrings of qem/__init__.py)."""

from os import PathLike
from typing import Any, Callable, Iterator, Literal, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, PathLike[str]]
_Float = npt.NDArray[np.floating[Any]]
_Int = npt.NDArray[np.integer[Any]]
_Vertices = Union[_Float, _Int, Sequence[Sequence[float]]]
_Faces = Union[_Int, Sequence[Sequence[int]]]
_MeshLike = Any  # an object with .vertices and .faces, an Open3D TriangleMesh, or (vertices, faces)
_Refit = Union[Literal["light", "full", "none"], bool, None, Tuple[int, float]]

class Error(ValueError): ...

class Mesh:
    vertices: npt.NDArray[np.float64]
    faces: npt.NDArray[np.int32]
    attributes: dict[str, npt.NDArray[np.float64]]
    attribute_kinds: dict[str, str]
    def __init__(
        self,
        vertices: npt.NDArray[np.float64],
        faces: npt.NDArray[np.int32],
        attributes: Optional[Mapping[str, npt.NDArray[np.float64]]] = ...,
        attribute_kinds: Optional[Mapping[str, str]] = ...,
    ) -> None: ...
    def __iter__(self) -> Iterator[np.ndarray]: ...

class _LoadedMesh(Mesh):
    double_precision: bool  # a PLY that stored double coordinates
    warnings: list[str]  # what the reader accepted leniently

class Record:
    def replay(self, faces: int) -> Mesh: ...
    def save(self, path: _Path) -> None: ...
    @staticmethod
    def load(path: _Path) -> Record: ...
    def to_bytes(self) -> bytes: ...
    @staticmethod
    def from_bytes(data: bytes) -> Record: ...
    def __len__(self) -> int: ...
    @property
    def base_faces(self) -> int: ...
    @property
    def base_vertices(self) -> int: ...
    @property
    def final_faces(self) -> int: ...

class SimplifyResult(Mesh):
    max_error: float
    max_error_relative: float
    stop_reason: Literal[
        "target reached", "error limit reached", "no valid contraction left", "input already at or below target", "cancelled"
    ]
    stop_detail: str
    contractions: int
    input_faces: int
    input_vertices: int
    refit_rounds: int
    refit_rms_before: float
    refit_rms_after: float
    edge_flips: int
    vertex_moves: int
    dropped_degenerate_faces: int
    dropped_duplicate_faces: int
    rejected_component: int
    input_components: int
    output_components: int
    pruned_components: int
    output_to_input_distance: float
    output_to_input_distance_relative: float
    rejected_distance: int
    vertex_source: Optional[npt.NDArray[np.int32]]
    face_source: Optional[npt.NDArray[np.int32]]
    output_vertex_of_input: Optional[npt.NDArray[np.int32]]
    record: Optional[Record]

class Measure:
    E: float
    E_rel: float
    rms: float
    rms_rel: float
    mean: float
    mean_rel: float
    hausdorff: float
    hausdorff_rel: float
    h_original_to_approx: float
    h_approx_to_original: float
    bbox_diag: float
    area_original: float
    area_approx: float
    samples_original: int
    samples_approx: int
    uv_rms: Optional[float]
    normal_rms_deg: Optional[float]
    color_rms: Optional[float]
    seam_cracks: int

class Info:
    vertices: int
    faces: int
    unreferenced_vertices: int
    edges: int
    boundary_edges: int
    boundary_loops: int
    non_manifold_edges: int
    non_manifold_vertices: int
    components: int
    duplicate_faces: int
    degenerate_faces: int
    zero_area_faces: int
    orientation_conflicts: int
    euler: int
    genus: int
    watertight: bool
    manifold: bool
    bbox_min: list[float]
    bbox_max: list[float]
    diagonal: float

class Level(Mesh):
    target_faces: int
    contractions: int
    max_error: float

def option_names(option: Literal["weighting", "placement", "scheme", "inversion", "two_sided", "seams"]) -> list[str]: ...
def simplify(
    vertices: _Vertices,
    faces: _Faces,
    *,
    target_faces: Optional[int] = ...,
    target_ratio: Optional[float] = ...,
    target_vertices: Optional[int] = ...,
    max_error: Optional[float] = ...,
    max_error_relative: Optional[float] = ...,
    max_distance: Optional[float] = ...,
    max_distance_relative: Optional[float] = ...,
    threshold: float = ...,
    threshold_relative: Optional[float] = ...,
    weighting: Literal["area", "uniform", "angle"] = ...,
    placement: Literal["optimal", "segment", "midpoint", "endpoints"] = ...,
    boundary_weight: float = ...,
    lock_border: bool = ...,
    inversion: Literal["forbid", "penalize", "off"] = ...,
    max_turn: float = ...,
    allow_non_manifold: bool = ...,
    scheme: Literal["greedy", "passes"] = ...,
    forget: float = ...,
    forget_attributes: bool = ...,
    refit: _Refit = ...,
    threads: int = ...,
    keep_components: bool = ...,
    prune: Optional[float] = ...,
    prune_relative: Optional[float] = ...,
    exact_border: bool = ...,
    attributes: Optional[Mapping[str, Union[np.ndarray, Tuple[np.ndarray, str]]]] = ...,
    attribute_weights: Optional[Mapping[str, float]] = ...,
    fit_attributes: bool = ...,
    vertex_lock: Optional[npt.ArrayLike] = ...,
    return_mapping: bool = ...,
    far_repair: Optional[bool] = ...,
    two_sided: Literal["rims", "all", "none"] = ...,
    seams: Literal["junctions", "strict", "creases", "permissive"] = ...,
    record: bool = ...,
    progress: Optional[Callable[[float], Optional[bool]]] = ...,
) -> SimplifyResult: ...
def simplify_gltf(
    input: _Path,
    output: _Path,
    *,
    target_faces: Optional[int] = ...,
    target_ratio: Optional[float] = ...,
    target_vertices: Optional[int] = ...,
    max_error: Optional[float] = ...,
    max_error_relative: Optional[float] = ...,
    max_distance: Optional[float] = ...,
    max_distance_relative: Optional[float] = ...,
    per_mesh: bool = ...,
    seams: Literal["junctions", "strict", "creases", "permissive"] = ...,
    attribute_weights: Optional[Mapping[str, float]] = ...,
    refit: _Refit = ...,
    far_repair: Optional[bool] = ...,
    threads: int = ...,
    **options: Any,
) -> dict: ...
def load(path: _Path, *, weld: Literal["auto", "on", "off"] = ...) -> _LoadedMesh: ...
def save(path: _Path, mesh: _MeshLike, *, binary: bool = ..., double: Optional[bool] = ...) -> None: ...
def measure(original: _MeshLike, approx: _MeshLike, *, samples: int = ..., seed: int = ..., threads: int = ...) -> Measure: ...
def cluster(
    vertices: _Vertices,
    faces: _Faces,
    *,
    grid: Optional[Tuple[int, int, int]] = ...,
    cell: Optional[float] = ...,
    cell_relative: Optional[float] = ...,
    placement: Literal["quadric", "mean"] = ...,
) -> Mesh: ...
def info(vertices: _Vertices, faces: _Faces) -> Info: ...
def lod(
    vertices: _Vertices,
    faces: _Faces,
    *,
    ratios: Optional[Sequence[float]] = ...,
    target_faces: Optional[Sequence[int]] = ...,
    refit: _Refit = ...,
    **options: Any,
) -> list[Level]: ...
