"""meshslim: triangle-mesh simplification on the GPU and the CPU.

Quadric edge collapse (a greedy f64 reference, ``backend="cpu"``, and rounds of parallel
collapses on any Vulkan/Metal/DX12 GPU, ``backend="gpu"``, with their CPU twin
``"cpu-parallel"``), vertex clustering (``method="cluster"``, ``"floating-cell"``, and
``"hybrid"``, clustering then QEM) and vertex decimation (``"decimate"``). Colours and UVs are
weighed in the cost, so a painted scan keeps its painting.

>>> import meshslim
>>> mesh = meshslim.read("scan.ply")
>>> res = meshslim.simplify(mesh, ratio=0.01)
>>> meshslim.write("scan-1.ply", res.mesh)
>>> res = meshslim.simplify(V, F, ratio=0.1, colors=C)      # numpy arrays in and out
>>> res.vertices, res.faces, res.colors, res.report["output_faces"]
>>> lod = meshslim.dag(mesh)                                # a Nanite-style cluster DAG
>>> lod.clusters["error"], lod.cut(error=0.001)             # arrays, and a cut as a Mesh
"""

from __future__ import annotations

import json
import os
from typing import Any, Callable, Optional

import numpy as np


def _quiet_wayland_probe() -> None:
    """Mesa's device-select layer asks libwayland for a compositor whenever wgpu opens a
    Vulkan device, and libwayland prints ``error: XDG_RUNTIME_DIR is invalid or not set in the
    environment.`` on a headless machine though nothing failed. As the command line does
    (``compute::context::quiet_wayland_probe``): with no Wayland display named and no valid
    runtime folder, point the probe at an empty private folder of our own, removed at exit;
    with any of them set nothing is touched."""
    env = os.environ
    runtime = env.get("XDG_RUNTIME_DIR", "")
    if env.get("WAYLAND_DISPLAY") or env.get("WAYLAND_SOCKET") or os.path.isabs(runtime):
        return
    import atexit
    import shutil
    import tempfile

    folder = tempfile.mkdtemp(prefix="meshslim-runtime-")  # 0700, as XDG asks
    env["XDG_RUNTIME_DIR"] = folder
    atexit.register(shutil.rmtree, folder, True)


# Before the extension loads: no device exists before it.
_quiet_wayland_probe()

from . import _meshslim  # noqa: E402
from ._meshslim import Mesh, __version__  # noqa: E402

__all__ = ["Mesh", "Result", "Dag", "mesh", "read", "write", "simplify", "lods", "remesh",
           "compare", "dag", "read_dag", "__version__"]

METHODS = ("qem", "cluster", "floating-cell", "hybrid", "decimate")
BACKENDS = ("cpu", "cpu-parallel", "gpu", "auto")


def _array(name: str, a: Any, dtype: Any, cols: tuple) -> np.ndarray:
    """`a` as a C-contiguous 2-D array of `dtype` (no copy when it already is one)."""
    arr = np.asarray(a)
    if arr.ndim != 2 or arr.shape[1] not in cols:
        want = " or ".join(f"(n, {c})" for c in cols)
        raise ValueError(f"{name}: expected an {want} array, got shape {arr.shape}")
    if np.issubdtype(dtype, np.integer):
        if not np.issubdtype(arr.dtype, np.integer):
            raise ValueError(f"{name}: expected integer vertex indices, got {arr.dtype}")
        if arr.size and arr.min() < 0:
            row = int(np.argwhere(arr < 0)[0][0])
            raise ValueError(f"{name}: row {row} has a negative index: {arr[row].tolist()}")
        if arr.size and arr.max() > np.iinfo(np.uint32).max:
            row = int(np.argwhere(arr > np.iinfo(np.uint32).max)[0][0])
            raise ValueError(f"{name}: row {row} has an index beyond 2**32 - 1")
    elif not (np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)):
        raise ValueError(f"{name}: expected numbers, got {arr.dtype}")
    return np.ascontiguousarray(arr, dtype=dtype)


def mesh(vertices: Any, faces: Any, *, normals: Any = None, uvs: Any = None,
         colors: Any = None) -> Mesh:
    """A :class:`Mesh` from arrays: ``vertices`` (n, 3), ``faces`` (m, 3) vertex indices, and
    optional per-vertex ``normals`` (n, 3), ``uvs`` (n, 2) and ``colors`` (n, 3) or (n, 4) in
    0..1. Raises ``ValueError`` naming the argument and the first offending row."""
    opt = lambda name, a, cols: None if a is None else _array(name, a, np.float32, cols)
    return Mesh(
        _array("vertices", vertices, np.float32, (3,)),
        _array("faces", faces, np.uint32, (3,)),
        normals=opt("normals", normals, (3,)),
        uvs=opt("uvs", uvs, (2,)),
        colors=opt("colors", colors, (3, 4)),
    )


class Result:
    """What :func:`simplify` returns: the simplified ``mesh`` (also as ``vertices``, ``faces``,
    ``normals``, ``uvs``, ``colors`` arrays) and its ``report``, the command line's report as a
    dict (faces and vertices in and out, stop reason, error, timings of the backend)."""

    def __init__(self, mesh: Mesh, report: dict):
        self.mesh = mesh
        self.report = report

    vertices = property(lambda self: self.mesh.vertices)
    faces = property(lambda self: self.mesh.faces)
    normals = property(lambda self: self.mesh.normals)
    uvs = property(lambda self: self.mesh.uvs)
    colors = property(lambda self: self.mesh.colors)

    def __repr__(self) -> str:
        return f"meshslim.Result({len(self.mesh.faces)} faces)"


def read(path: str) -> Mesh:
    """Reads a mesh file: OBJ, PLY (ascii or binary), STL, glTF or GLB. Raises ``OSError`` when
    the file cannot be read and ``ValueError`` when it does not parse (with the place)."""
    return _meshslim.read(str(path))


def write(path: str, mesh: Mesh) -> None:
    """Writes ``mesh`` to ``path``, the format from its extension (.ply, .obj, .stl, .glb,
    .gltf); the file appears whole or not at all."""
    _meshslim.write(str(path), mesh)


def _input(mesh_or_vertices: Any, faces: Any, normals: Any, uvs: Any, colors: Any,
           progress: Any) -> Mesh:
    """The mesh a call was given, as a :class:`Mesh` or as arrays, and its progress callback
    checked: what :func:`simplify` and :func:`dag` take alike."""
    if isinstance(mesh_or_vertices, Mesh):
        if faces is not None or colors is not None or uvs is not None or normals is not None:
            raise ValueError("faces, colors, uvs and normals go with a vertex array, not a Mesh")
        m = mesh_or_vertices
    else:
        if faces is None:
            raise ValueError("faces: needed with a vertex array")
        m = mesh(mesh_or_vertices, faces, normals=normals, uvs=uvs, colors=colors)
    if progress is not None and not callable(progress):
        raise ValueError("progress: expected a callable taking the fraction done")
    return m


def simplify(mesh_or_vertices: Any, faces: Any = None, *, ratio: Optional[float] = None,
             target_faces: Optional[int] = None, max_error: Optional[float] = None,
             method: str = "qem", backend: str = "cpu", lock_border: bool = False,
             colors: Any = None, uvs: Any = None, normals: Any = None,
             color_weight: Optional[float] = None, uv_weight: Optional[float] = None,
             normal_weight: Optional[float] = None,
             progress: Optional[Callable[[float], Any]] = None) -> Result:
    """Simplifies a mesh to ``ratio`` of its faces (default 0.1) or to ``target_faces``.

    ``mesh_or_vertices``: a :class:`Mesh`, or an (n, 3) vertex array with ``faces`` (m, 3) and
    optional ``colors``/``uvs``/``normals`` arrays. ``max_error``: stop before any collapse moves
    the surface further than this (relative to the bounding-box diagonal).

    ``method``: ``"qem"`` (quadric edge collapse, the best surface), ``"cluster"`` and
    ``"floating-cell"`` (vertex clustering: fastest, may change topology), ``"hybrid"``
    (clustering, then QEM: near QEM's quality faster; greedy on ``"cpu"``/``"auto"``, rounds on
    ``"cpu-parallel"``/``"gpu"``), ``"decimate"`` (removes vertices, keeps
    the rest unmoved). ``backend``: ``"cpu"`` (greedy, f64), ``"cpu-parallel"``, ``"gpu"`` (any
    Vulkan/Metal/DX12 adapter), ``"auto"``. ``lock_border``: keep open borders exactly.

    ``color_weight`` (default 0.04), ``uv_weight`` (0.3), ``normal_weight`` (0): how much a
    change of colour, UV or normal counts against moving the surface (a difference of 1 costs
    like ``weight`` bounding-box diagonals); 0 lets the attribute ride along.

    ``progress``: called with the fraction done, from the simplifying thread. Ctrl+C cancels
    (``KeyboardInterrupt``). Other Python threads run meanwhile (the GIL is released). Bad
    arguments raise ``ValueError`` naming them.
    """
    m = _input(mesh_or_vertices, faces, normals, uvs, colors, progress)
    out, report = _meshslim.simplify(
        m, ratio=ratio, target_faces=target_faces, max_error=max_error, method=method,
        backend=backend, lock_border=lock_border, color_weight=color_weight,
        uv_weight=uv_weight, normal_weight=normal_weight, progress=progress)
    return Result(out, json.loads(report))


def lods(mesh: Mesh, ratios: Any, *, method: str = "qem", backend: str = "cpu",
         lock_border: bool = False, color_weight: Optional[float] = None,
         uv_weight: Optional[float] = None, normal_weight: Optional[float] = None,
         progress: Optional[Callable[[float], Any]] = None) -> list:
    """Levels of detail at falling ``ratios`` (each in (0, 1]) of ``mesh``'s faces, made in one
    run: each level goes on from the one before, so the chain costs about one simplification
    to the coarsest. ``method`` is ``"qem"`` (any backend), ``"hybrid"`` or ``"decimate"``.
    Returns a :class:`Result` per level; each report holds ``ratio``, ``target_faces``,
    ``output_faces``, ``stop_reason``, ``max_error`` (the chain's largest so far, relative to
    the diagonal), ``seconds`` (since the start) and ``backend``."""
    if progress is not None and not callable(progress):
        raise ValueError("progress: expected a callable taking the fraction done")
    levels, backend_ran = _meshslim.lods(
        mesh, [float(r) for r in ratios], method=method, backend=backend,
        lock_border=lock_border, color_weight=color_weight, uv_weight=uv_weight,
        normal_weight=normal_weight, progress=progress)
    return [Result(m, dict(json.loads(facts), backend=backend_ran)) for m, facts in levels]


def remesh(mesh: Mesh, *, edge_factor: Optional[float] = None,
           edge_length: Optional[float] = None, target_faces: Optional[int] = None,
           iterations: int = 5, feature_angle: float = 45.0,
           lock_border: bool = False) -> Result:
    """Isotropic remeshing (Botsch & Kobbelt 2004): near-equilateral triangles of one edge
    length, ``edge_factor`` times the mean edge, an absolute ``edge_length``, or the length that
    gives about ``target_faces`` (default: the mean edge); creases sharper than
    ``feature_angle`` degrees and borders kept (``lock_border``: borders not touched at all).
    The report holds the iterations' counts and timings."""
    out, report = _meshslim.remesh(
        mesh, edge_factor=edge_factor, edge_length=edge_length, target_faces=target_faces,
        iterations=iterations, feature_angle=feature_angle, lock_border=lock_border)
    return Result(out, json.loads(report))


def compare(a: Mesh, b: Mesh, *, samples: Optional[int] = None,
            seed: Optional[int] = None) -> dict:
    """Measures how far ``b`` is from ``a``: the two-sided Metro distance (absolute and
    relative to the diagonal), colour and normal deviation, area, volume, triangle quality and
    topology of each, as ``meshslim compare --json`` prints them."""
    return json.loads(_meshslim.compare(a, b, samples=samples, seed=seed))


class Dag:
    """A cluster DAG (B. Karis et al., "A Deep Dive into Nanite Virtualized Geometry", 2021), as
    :func:`dag` builds it and ``meshslim dag build`` writes it: clusters of at most 128
    triangles, grouped and simplified level after level down to one root, every level's
    triangles over one set of vertices.

    ``mesh``: the vertices and, cluster after cluster, the triangles of every level.
    ``clusters``: a dict of arrays, one entry per cluster: ``first_triangle``,
    ``triangle_count``, ``depth`` (0 for the input's), ``group`` (the group that simplifies it;
    ``NONE`` for a root), ``parent_group`` (the group that made it; ``NONE`` at depth 0), all
    uint32; ``bounds`` and ``lod_sphere`` (k, 4) float32 spheres (centre, radius); ``error``
    float32, in mesh units. ``groups``: ``depth``, ``sphere`` (g, 4), ``error``. ``diagonal``:
    the input's bounding-box diagonal. ``report``: the build's report (levels,
    triangles_per_level, clusters, groups, root_groups, dag_triangles, stuck_groups, seconds),
    or None for a DAG read from a file."""

    NONE = 2**32 - 1

    def __init__(self, native: Any, report: Optional[dict] = None):
        self._native = native
        self.report = report
        self.clusters = native.clusters()
        self.groups = native.groups()

    mesh = property(lambda self: self._native.mesh)
    diagonal = property(lambda self: self._native.diagonal)

    def cut_clusters(self, *, error: Optional[float] = None, triangles: Optional[int] = None,
                     camera: Any = None, pixels: Optional[float] = None, fov: float = 60.0,
                     height: float = 1080.0) -> np.ndarray:
        """The ids (uint32) of the clusters one cut draws; the arguments are :meth:`cut`'s."""
        return self._cut(error, triangles, camera, pixels, fov, height)[0]

    def cut(self, *, error: Optional[float] = None, triangles: Optional[int] = None,
            camera: Any = None, pixels: Optional[float] = None, fov: float = 60.0,
            height: float = 1080.0) -> Mesh:
        """One cut of the DAG as a :class:`Mesh`; give one of:

        - ``error``: object space, a fraction of the bounding-box diagonal: the clusters whose
          own error is at most it and whose group's is over it;
        - ``triangles``: the finest object-space cut with at most that many triangles;
        - ``camera`` (x, y, z) with ``pixels``: the view-dependent cut whose projected error is
          at most ``pixels`` for a camera there (``fov`` degrees vertically, ``height`` pixels).

        Every cut of a closed mesh is closed: no cracks between clusters of different levels."""
        return self._native.mesh_of(self._cut(error, triangles, camera, pixels, fov, height)[0])

    def _cut(self, error, triangles, camera, pixels, fov, height):
        if triangles is not None and (not isinstance(triangles, (int, np.integer))
                                      or triangles < 0):
            raise ValueError(f"triangles: expected a count, 0 or more, got {triangles!r}")
        if camera is not None:
            eye = np.asarray(camera, dtype=np.float64).reshape(-1)
            if eye.shape != (3,):
                raise ValueError(f"camera: expected (x, y, z), got {camera!r}")
            camera = [float(x) for x in eye]
        if (camera is None) != (pixels is None):
            raise ValueError("camera and pixels go together")
        return self._native.cut_clusters(
            error=None if error is None else float(error),
            triangles=None if triangles is None else int(triangles), camera=camera,
            pixels=None if pixels is None else float(pixels), fov=float(fov),
            height=float(height))

    def write(self, path: str) -> None:
        """Writes the DAG as a .mslod file (docs/MSLOD.md), which ``meshslim dag cut`` reads;
        the file appears whole or not at all."""
        self._native.write(str(path))

    def __repr__(self) -> str:
        return repr(self._native)


def dag(mesh_or_vertices: Any, faces: Any = None, *, backend: str = "cpu",
        cluster_triangles: int = 128, cluster_vertices: int = 255, group_size: int = 16,
        colors: Any = None, uvs: Any = None, normals: Any = None,
        color_weight: Optional[float] = None, uv_weight: Optional[float] = None,
        normal_weight: Optional[float] = None,
        progress: Optional[Callable[[float], Any]] = None) -> Dag:
    """Builds a Nanite-style cluster DAG of a mesh (``meshslim dag build``): clusters of at most
    ``cluster_triangles`` triangles and ``cluster_vertices`` vertices, groups of up to
    ``group_size`` neighbouring clusters, each group simplified to half with its border to the
    other groups pinned, level after level down to one root. Returns a :class:`Dag`.

    ``backend``: ``"cpu"`` (the greedy on many groups at once across the cores), or
    ``"cpu-parallel"`` / ``"gpu"`` (the rounds; the same bytes as each other), or ``"auto"``.
    The arguments otherwise are :func:`simplify`'s."""
    m = _input(mesh_or_vertices, faces, normals, uvs, colors, progress)
    for name, n in (("cluster_triangles", cluster_triangles),
                    ("cluster_vertices", cluster_vertices), ("group_size", group_size)):
        if not isinstance(n, (int, np.integer)) or n < 0:
            raise ValueError(f"{name}: expected a count, got {n!r}")
    native, report = _meshslim.dag_build(
        m, backend=backend, cluster_triangles=int(cluster_triangles),
        cluster_vertices=int(cluster_vertices), group_size=int(group_size),
        color_weight=color_weight, uv_weight=uv_weight, normal_weight=normal_weight,
        progress=progress)
    return Dag(native, json.loads(report))


def read_dag(path: str) -> Dag:
    """Reads a .mslod file (as ``meshslim dag build`` writes it). Raises ``OSError`` when it
    cannot be read and ``ValueError`` naming the byte offset when it is damaged."""
    return Dag(_meshslim.read_dag(str(path)))
