"""The Python package against the real library: numpy in and out, files in and out (the same
bytes as the command line), every method on the CPU, the GPU backend on the machine's adapter
(lavapipe in CI), progress and errors. Run by .ci/run after `pip install .` in a fresh venv:

    python -m venv /tmp/venv && /tmp/venv/bin/pip install '.[test]'
    /tmp/venv/bin/python -m pytest python/tests
"""

import _thread
import os
import subprocess
import signal
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import meshslim

ROOT = Path(__file__).resolve().parents[2]
CLI = Path(os.environ.get("MESHSLIM_CLI", ROOT / "target" / "release" / "meshslim"))


def torus(nu=96, nv=48, r=1.0, t=0.35, noise=0.002, seed=3):
    """A closed torus with a little noise (so every collapse has a cost), (V, F) as numpy."""
    u = np.linspace(0, 2 * np.pi, nu, endpoint=False)
    v = np.linspace(0, 2 * np.pi, nv, endpoint=False)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    x = (r + t * np.cos(vv)) * np.cos(uu)
    y = (r + t * np.cos(vv)) * np.sin(uu)
    z = t * np.sin(vv)
    V = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    V += np.random.default_rng(seed).normal(scale=noise, size=V.shape)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a = i * nv + j
    b = ((i + 1) % nu) * nv + j
    c = ((i + 1) % nu) * nv + (j + 1) % nv
    d = i * nv + (j + 1) % nv
    F = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                        np.stack([a, c, d], -1).reshape(-1, 3)])
    return V, F


def painted(V):
    """Sharp stripes over a smooth band: colours a collapse can smear."""
    stripes = (np.floor(V[:, 0] * 6) % 2)[:, None]
    band = 0.5 + 0.5 * np.sin(3 * V[:, 1])[:, None]
    return np.hstack([stripes, band, 1 - band]).clip(0, 1)


def test_arrays_in_and_out():
    V, F = torus()
    res = meshslim.simplify(V, F, ratio=0.1)
    target = res.report["target_faces"]
    assert target == round(0.1 * len(F))
    assert len(res.faces) in (target, target - 1)  # exactly, or one below (an interior collapse)
    assert res.vertices.dtype == np.float32 and res.faces.dtype == np.uint32
    assert res.vertices.shape[1] == 3 and res.faces.max() < len(res.vertices)
    assert res.report["output_faces"] == len(res.faces)
    assert res.report["stop_reason"] == "target-reached"
    # float32 / int32 / uint32 inputs give the same result as float64 / int64.
    same = meshslim.simplify(V.astype(np.float32), F.astype(np.int32), ratio=0.1)
    assert np.array_equal(same.faces, res.faces)
    assert np.array_equal(same.vertices, res.vertices)
    by_count = meshslim.simplify(V, F.astype(np.uint32), target_faces=500)
    assert len(by_count.faces) in (500, 499)


def test_every_method_on_the_cpu():
    V, F = torus()
    m = meshslim.mesh(V, F)
    for method in meshslim.METHODS:
        for backend in ("cpu", "cpu-parallel"):
            if method == "decimate" and backend != "cpu":
                continue
            res = meshslim.simplify(m, ratio=0.2, method=method, backend=backend)
            assert 0 < len(res.faces) < len(F), (method, backend)
            assert res.report["backend"] is not None


def test_colours_are_weighed_and_kept_in_range():
    V, F = torus()
    C = painted(V)
    on = meshslim.simplify(V, F, ratio=0.1, colors=C)
    off = meshslim.simplify(V, F, ratio=0.1, colors=C, color_weight=0)
    assert on.colors.shape == (len(on.vertices), 4)
    assert (on.colors >= 0).all() and (on.colors <= 1).all()
    original = meshslim.mesh(V, F, colors=C)
    err = lambda r: meshslim.compare(original, r.mesh)["appearance"]["color"]["mean"]
    assert err(on) < 0.7 * err(off)


def test_read_simplify_write_gives_the_command_lines_bytes(tmp_path):
    V, F = torus()
    src = tmp_path / "in.ply"
    meshslim.write(src, meshslim.mesh(V, F, colors=painted(V)))
    subprocess.run([str(CLI), "simplify", str(src), str(tmp_path / "cli.ply"), "--ratio",
                    "0.05", "--quiet"], check=True)
    res = meshslim.simplify(meshslim.read(src), ratio=0.05)
    meshslim.write(tmp_path / "py.ply", res.mesh)
    assert (tmp_path / "py.ply").read_bytes() == (tmp_path / "cli.ply").read_bytes()


def test_compare_measures_the_distance():
    V, F = torus()
    a = meshslim.mesh(V, F)
    d = meshslim.compare(a, a)
    assert d["distance"]["two_sided"]["mean"] < 1e-12
    b = meshslim.simplify(a, ratio=0.05).mesh
    assert 0 < meshslim.compare(a, b)["distance"]["two_sided"]["mean_rel"] < 0.01


def test_levels_of_detail_in_one_run():
    V, F = torus()
    levels = meshslim.lods(meshslim.mesh(V, F, colors=painted(V)), [0.5, 0.1, 0.02])
    faces = [len(l.faces) for l in levels]
    assert faces == sorted(faces, reverse=True)
    for level, ratio in zip(levels, [0.5, 0.1, 0.02]):
        assert level.report["ratio"] == ratio
        assert len(level.faces) in (level.report["target_faces"], level.report["target_faces"] - 1)
        assert level.colors is not None
    assert levels[0].report["backend"] == "cpu"
    with pytest.raises(ValueError, match="must fall"):
        meshslim.lods(meshslim.mesh(V, F), [0.1, 0.5])


def test_remesh_makes_better_triangles():
    V, F = torus()
    a = meshslim.mesh(V, F)
    even = meshslim.remesh(a, edge_factor=2)
    assert 0 < len(even.faces) < len(F)
    assert meshslim.compare(a, even.mesh)["distance"]["two_sided"]["mean_rel"] < 0.01
    with pytest.raises(ValueError, match="one of edge_factor"):
        meshslim.remesh(a, edge_factor=2, target_faces=100)


def test_progress_is_reported_and_its_exception_stops_the_run():
    V, F = torus()
    seen = []
    meshslim.simplify(V, F, ratio=0.05, backend="cpu-parallel", progress=seen.append)
    assert seen and seen[-1] <= 1.0 and all(0 <= f <= 1 for f in seen)

    def boom(_):
        raise ZeroDivisionError("from the callback")

    with pytest.raises(ZeroDivisionError, match="from the callback"):
        meshslim.simplify(V, F, ratio=0.05, backend="cpu-parallel", progress=boom)


def test_other_threads_run_and_ctrl_c_cancels():
    V, F = torus(400, 200)  # 160,000 faces: long enough to look at
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    start = time.perf_counter()
    meshslim.simplify(V, F, ratio=0.01, backend="cpu-parallel")
    end = time.perf_counter()
    done.set()
    counter.join()
    # The GIL was released: the other thread kept ticking while the call ran.
    assert sum(start < t < end for t in ticks) > 10

    # Ctrl+C (a pending SIGINT) during the run cancels it at the next progress report and
    # raises KeyboardInterrupt: the interrupt arrives at the first report, and no other follows.
    seen = []

    def interrupt_once(f):
        seen.append(f)
        if len(seen) == 1:
            _thread.interrupt_main()

    # Python's own Ctrl+C handler, whatever this process inherited: a shell's background job
    # starts with SIGINT ignored, and Python then leaves it so (interrupt_main does nothing).
    inherited = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            meshslim.simplify(V, F, ratio=0.001, backend="cpu-parallel", progress=interrupt_once)
    finally:
        signal.signal(signal.SIGINT, inherited)
    assert len(seen) == 1 and seen[0] < 0.5


def test_the_gpu_backend_runs_on_the_adapter():
    V, F = torus()
    try:
        gpu = meshslim.simplify(V, F, ratio=0.1, backend="gpu")
    except RuntimeError as e:
        if os.environ.get("CI") == "true":
            raise  # CI installs lavapipe: a missing adapter is a failure there
        pytest.skip(f"no GPU adapter: {e}")
    cpu = meshslim.simplify(V, F, ratio=0.1, backend="cpu-parallel")
    assert len(gpu.faces) == len(cpu.faces)
    assert "rounds" in gpu.report


def test_the_gpu_backend_prints_nothing_the_user_did_not_ask_for():
    """On a headless machine with no runtime folder, a fresh process that simplifies on the GPU
    writes nothing to stderr (Mesa's Wayland probe printed a line twice)."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("XDG_RUNTIME_DIR", "WAYLAND_DISPLAY", "WAYLAND_SOCKET")}
    code = ("import numpy as np, meshslim\n"
            "from test_meshslim import torus\n"
            "V, F = torus()\n"
            "r = meshslim.simplify(V, F, ratio=0.1, backend='gpu')\n"
            "print(len(r.faces))\n")
    run = subprocess.run([sys.executable, "-c", code], env=env,
                         cwd=Path(__file__).parent, capture_output=True, text=True, timeout=300)
    if run.returncode != 0 and "no GPU adapter" in run.stderr and os.environ.get("CI") != "true":
        pytest.skip(f"no GPU adapter: {run.stderr.strip()}")
    assert run.returncode == 0, run.stderr
    assert int(run.stdout) > 0
    assert run.stderr == "", run.stderr


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda V, F: meshslim.simplify(V[:, :2], F), r"vertices: expected an \(n, 3\)"),
        (lambda V, F: meshslim.simplify(V, F[:, :2]), r"faces: expected an \(n, 3\)"),
        (lambda V, F: meshslim.simplify(V, np.where(F == 7, len(V), F)),
         r"faces: row \d+ .* out of range"),
        (lambda V, F: meshslim.simplify(V, np.where(F == 7, -1, F)), r"faces: row \d+ has a negative"),
        (lambda V, F: meshslim.simplify(V, F.astype(float)), r"faces: expected integer"),
        (lambda V, F: meshslim.simplify(np.where(np.arange(len(V))[:, None] == 5, np.nan, V), F),
         r"vertices: row 5 is not finite"),
        (lambda V, F: meshslim.simplify(V, F, ratio=0), r"ratio must be in \(0, 1\]"),
        (lambda V, F: meshslim.simplify(V, F, ratio=1.5), r"ratio must be in \(0, 1\]"),
        (lambda V, F: meshslim.simplify(V, F, colors=painted(V)[:-1]), r"colors: \d+ rows for"),
        (lambda V, F: meshslim.simplify(V, F, colors=painted(V) * 2), r"colors: row \d+ is outside"),
        (lambda V, F: meshslim.simplify(V, F, method="magic"), r"method: unknown \"magic\""),
        (lambda V, F: meshslim.simplify(V, F, backend="tpu"), r"backend: unknown \"tpu\""),
        (lambda V, F: meshslim.simplify(V, F, color_weight=-1), r"color"),
        (lambda V, F: meshslim.simplify(V, F, ratio=0.5, target_faces=10), r"not both"),
        (lambda V, F: meshslim.simplify(V), r"faces: needed"),
    ],
)
def test_bad_input_raises_value_error_naming_it(call, message):
    V, F = torus(24, 12)
    with pytest.raises(ValueError, match=message):
        call(V, F)


def test_bad_files_raise_with_the_path(tmp_path):
    with pytest.raises(OSError, match="nope.ply"):
        meshslim.read(tmp_path / "nope.ply")
    bad = tmp_path / "bad.ply"
    bad.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n")
    with pytest.raises(ValueError, match="bad.ply"):
        meshslim.read(bad)
    with pytest.raises(ValueError, match="unsupported file extension"):
        meshslim.write(tmp_path / "out.xyz", meshslim.mesh(*torus(24, 12)))


def test_help_teaches():
    doc = meshslim.simplify.__doc__
    for word in ("ratio", "target_faces", "method", "backend", "color_weight", "progress"):
        assert word in doc
    assert "Mesh(" in repr(meshslim.mesh(*torus(24, 12)))


def test_trimesh_keeps_vertex_colours_and_uvs():
    trimesh = pytest.importorskip("trimesh")
    from meshslim import trimesh as mt

    V, F = torus()
    rgba = np.hstack([painted(V), np.ones((len(V), 1))])
    coloured = trimesh.Trimesh(V, F, vertex_colors=(rgba * 255).astype(np.uint8), process=False)
    small = mt.simplify(coloured, ratio=0.1)
    assert len(small.faces) in (round(0.1 * len(F)), round(0.1 * len(F)) - 1)
    assert small.visual.kind == "vertex" and len(small.visual.vertex_colors) == len(small.vertices)

    uv = np.stack([np.arange(len(V)) % 97 / 96.0, np.arange(len(V)) // 97 / 96.0], 1) % 1.0
    image = pytest.importorskip("PIL.Image").fromarray(np.zeros((4, 4, 3), np.uint8))
    material = trimesh.visual.material.SimpleMaterial(image=image)
    textured = trimesh.Trimesh(V, F, visual=trimesh.visual.TextureVisuals(uv=uv, material=material),
                               process=False)
    small = mt.simplify(textured, ratio=0.1)
    assert small.visual.kind == "texture"
    assert small.visual.uv.shape == (len(small.vertices), 2)
    assert (small.visual.uv >= uv.min(0) - 1e-6).all() and (small.visual.uv <= uv.max(0) + 1e-6).all()


SPOT = ROOT.parent / "shared" / "models" / "spot" / "spot_triangulated.obj"


@pytest.mark.skipif(not SPOT.exists(), reason="../shared/models/spot is not beside the project")
def test_trimesh_round_trip_of_spot_keeps_its_uvs():
    trimesh = pytest.importorskip("trimesh")
    from meshslim import trimesh as mt

    spot = trimesh.load(SPOT, process=False)
    small = mt.simplify(spot, ratio=0.1)
    assert small.visual.kind == "texture"
    assert small.visual.uv.shape == (len(small.vertices), 2)
    assert abs(len(small.faces) - 0.1 * len(spot.faces)) <= 1


def edges_used(F):
    """How many faces use each undirected edge of F (a closed manifold: every edge twice)."""
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0, return_counts=True)[1]


def test_dag_arrays_cuts_and_file_match_the_command_line(tmp_path):
    V, F = torus()
    seen = []
    lod = meshslim.dag(V, F, progress=seen.append)
    assert seen and seen[-1] == 1.0
    c, g = lod.clusters, lod.groups
    k = len(c["error"])
    assert k == lod.report["clusters"] and len(g["error"]) == lod.report["groups"]
    for name in ("first_triangle", "triangle_count", "depth", "group", "parent_group"):
        assert c[name].dtype == np.uint32 and c[name].shape == (k,), name
    assert c["bounds"].shape == (k, 4) and c["lod_sphere"].dtype == np.float32
    assert (c["triangle_count"] <= 128).all()
    assert c["triangle_count"][c["depth"] == 0].sum() == len(F)
    assert lod.report["root_groups"] == 1 and lod.report["stuck_groups"] == 0
    # Errors only grow: a cluster's group errs at least as much as the cluster.
    inner = c["group"] != meshslim.Dag.NONE
    assert (g["error"][c["group"][inner]] >= c["error"][inner]).all()
    coarse = None
    for e in (0.0, 0.002, 0.01, 0.05):
        cut = lod.cut(error=e)
        assert (edges_used(cut.faces) == 2).all(), f"a crack at {e}"
        assert coarse is None or len(cut.faces) <= coarse
        coarse = len(cut.faces)
    assert len(lod.cut(error=0.0).faces) == len(F)
    near = lod.cut(camera=(2.0, 0.0, 0.5), pixels=1.0, height=720)
    assert (edges_used(near.faces) == 2).all()
    assert len(lod.cut(triangles=1000).faces) <= 1000
    ids = lod.cut_clusters(error=0.01)
    assert ids.dtype == np.uint32 and c["triangle_count"][ids].sum() == len(lod.cut(error=0.01).faces)
    # The file reads back, and the command line cuts it to the bytes Python writes.
    path = tmp_path / "torus.mslod"
    lod.write(path)
    back = meshslim.read_dag(path)
    for name in c:
        assert np.array_equal(back.clusters[name], c[name]), name
    subprocess.run([str(CLI), "dag", "cut", str(path), str(tmp_path / "cli.ply"), "--error",
                    "0.01"], check=True, capture_output=True)
    meshslim.write(tmp_path / "py.ply", back.cut(error=0.01))
    assert (tmp_path / "py.ply").read_bytes() == (tmp_path / "cli.ply").read_bytes()


def test_dag_errors_name_what_is_wrong(tmp_path):
    V, F = torus(24, 12)
    lod = meshslim.dag(V, F)
    for kwargs, message in [
        ({}, "give one of"),
        ({"error": 0.01, "triangles": 10}, "give one of"),
        ({"error": -1.0}, "0 or more"),
        ({"camera": (0, 0, 5)}, "camera and pixels"),
        ({"camera": (0, 0), "pixels": 1.0}, r"camera: expected \(x, y, z\)"),
        ({"camera": (0, 0, 5), "pixels": 1.0, "fov": 200}, "field of view"),
        ({"triangles": -3}, "triangles"),
    ]:
        with pytest.raises(ValueError, match=message):
            lod.cut(**kwargs)
    with pytest.raises(ValueError, match="group size"):
        meshslim.dag(V, F, group_size=1)
    with pytest.raises(ValueError, match="backend"):
        meshslim.dag(V, F, backend="tpu")
    with pytest.raises(OSError, match="nope.mslod"):
        meshslim.read_dag(tmp_path / "nope.mslod")
    path = tmp_path / "d.mslod"
    lod.write(path)
    data = bytearray(path.read_bytes())
    data[-20] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(ValueError, match="d.mslod"):
        meshslim.read_dag(path)
