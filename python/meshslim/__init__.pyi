"""Type stubs for meshslim: triangle-mesh simplification on the GPU and the CPU."""

from typing import Any, Callable, Optional

import numpy as np
import numpy.typing as npt

__version__: str
METHODS: tuple
BACKENDS: tuple

class Mesh:
    """A triangle mesh: positions, faces and the per-vertex attributes it has."""

    def __init__(
        self,
        vertices: npt.NDArray[np.float32],
        faces: npt.NDArray[np.uint32],
        *,
        normals: Optional[npt.NDArray[np.float32]] = ...,
        uvs: Optional[npt.NDArray[np.float32]] = ...,
        colors: Optional[npt.NDArray[np.float32]] = ...,
    ) -> None: ...
    @property
    def vertices(self) -> npt.NDArray[np.float32]:
        """Positions, (n, 3) float32."""
    @property
    def faces(self) -> npt.NDArray[np.uint32]:
        """Triangles, (m, 3) uint32 vertex indices."""
    @property
    def normals(self) -> Optional[npt.NDArray[np.float32]]:
        """Per-vertex normals, (n, 3), or None."""
    @property
    def uvs(self) -> Optional[npt.NDArray[np.float32]]:
        """Per-vertex texture coordinates, (n, 2), or None."""
    @property
    def colors(self) -> Optional[npt.NDArray[np.float32]]:
        """Per-vertex RGBA colours in 0..1, (n, 4), or None."""

class Result:
    """The simplified mesh and the report of the run."""

    mesh: Mesh
    report: dict
    @property
    def vertices(self) -> npt.NDArray[np.float32]: ...
    @property
    def faces(self) -> npt.NDArray[np.uint32]: ...
    @property
    def normals(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def uvs(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def colors(self) -> Optional[npt.NDArray[np.float32]]: ...

def mesh(
    vertices: Any,
    faces: Any,
    *,
    normals: Any = ...,
    uvs: Any = ...,
    colors: Any = ...,
) -> Mesh:
    """A Mesh from arrays; ValueError names the argument and the first offending row."""

def read(path: str) -> Mesh:
    """Reads OBJ, PLY, STL, glTF or GLB."""

def write(path: str, mesh: Mesh) -> None:
    """Writes the format the extension names."""

def simplify(
    mesh_or_vertices: Any,
    faces: Any = ...,
    *,
    ratio: Optional[float] = ...,
    target_faces: Optional[int] = ...,
    max_error: Optional[float] = ...,
    method: str = ...,
    backend: str = ...,
    lock_border: bool = ...,
    colors: Any = ...,
    uvs: Any = ...,
    normals: Any = ...,
    color_weight: Optional[float] = ...,
    uv_weight: Optional[float] = ...,
    normal_weight: Optional[float] = ...,
    progress: Optional[Callable[[float], Any]] = ...,
) -> Result:
    """Simplifies to `ratio` of the faces (default 0.1) or to `target_faces`."""

def lods(
    mesh: Mesh,
    ratios: Any,
    *,
    method: str = ...,
    backend: str = ...,
    lock_border: bool = ...,
    color_weight: Optional[float] = ...,
    uv_weight: Optional[float] = ...,
    normal_weight: Optional[float] = ...,
    progress: Optional[Callable[[float], Any]] = ...,
) -> list[Result]:
    """Levels of detail at falling ratios, in one run."""

def remesh(
    mesh: Mesh,
    *,
    edge_factor: Optional[float] = ...,
    edge_length: Optional[float] = ...,
    target_faces: Optional[int] = ...,
    iterations: int = ...,
    feature_angle: float = ...,
    lock_border: bool = ...,
) -> Result:
    """Isotropic remeshing to one edge length."""

def compare(a: Mesh, b: Mesh, *, samples: Optional[int] = ..., seed: Optional[int] = ...) -> dict:
    """Two-sided Metro distance, appearance, area, volume, quality and topology."""

class Dag:
    """A cluster DAG: clusters and groups as numpy arrays, cuts as meshes."""

    NONE: int
    report: Optional[dict]
    clusters: dict[str, np.ndarray]
    groups: dict[str, np.ndarray]
    @property
    def mesh(self) -> Mesh: ...
    @property
    def diagonal(self) -> float: ...
    def cut(
        self,
        *,
        error: Optional[float] = ...,
        triangles: Optional[int] = ...,
        camera: Any = ...,
        pixels: Optional[float] = ...,
        fov: float = ...,
        height: float = ...,
    ) -> Mesh:
        """One cut: at an object-space error, a triangle budget, or from a camera."""
    def cut_clusters(
        self,
        *,
        error: Optional[float] = ...,
        triangles: Optional[int] = ...,
        camera: Any = ...,
        pixels: Optional[float] = ...,
        fov: float = ...,
        height: float = ...,
    ) -> npt.NDArray[np.uint32]:
        """The ids of the clusters one cut draws."""
    def write(self, path: str) -> None:
        """Writes a .mslod file."""

def dag(
    mesh_or_vertices: Any,
    faces: Any = ...,
    *,
    backend: str = ...,
    cluster_triangles: int = ...,
    cluster_vertices: int = ...,
    group_size: int = ...,
    colors: Any = ...,
    uvs: Any = ...,
    normals: Any = ...,
    color_weight: Optional[float] = ...,
    uv_weight: Optional[float] = ...,
    normal_weight: Optional[float] = ...,
    progress: Optional[Callable[[float], Any]] = ...,
) -> Dag:
    """Builds a Nanite-style cluster DAG."""

def read_dag(path: str) -> Dag:
    """Reads a .mslod file."""
