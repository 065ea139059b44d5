#!/usr/bin/env python3
"""Compare meshslim's simplification with MeshLab's quadric edge collapse, Metro-style.

Usage (from the crate root):

    pip install pymeshlab            # PyPI wheel; bundles Qt, libgomp, GLU; needs the system
                                     # libGL.so.1 / libOpenGL.so.0 (Debian: libgl1, libopengl0)
    cargo build --release
    python3 benches/meshlab_compare.py                        # every mesh in the models dir
    python3 benches/meshlab_compare.py --models horse.ply igea.ply --ratios 0.1 0.01
    python3 benches/meshlab_compare.py --ours DIR --json results.json
    python3 benches/meshlab_compare.py --agreement --json agreement.json   # issue 4's check

For every mesh of the models folder ($MESHSLIM_MODELS, else ../shared/models beside the crate)
and every ratio it:

1. simplifies with our binary, `target/release/meshslim simplify IN OUT --ratio R --json`
   (or takes `DIR/<stem>-<ratio>.ply` with `--ours DIR`, e.g. `horse-0.1.ply`; an optional
   sidecar `DIR/<stem>-<ratio>.json` may hold the time, see `ours_seconds`);
2. simplifies with MeshLab's `meshing_decimation_quadric_edge_collapse`, timing that filter call
   only, with `targetfacenum = round(ratio * faces of the original as MeshLab loaded it)`,
   `preservetopology = True` and every other parameter at its default (qualitythr 0.3,
   preserveboundary False, boundaryweight 1, preservenormal False, optimalplacement True,
   planarquadric False, qualityweight False, autoclean True);
3. measures both results against the original with MeshLab's `get_hausdorff_distance`, both
   ways (original -> simplified and simplified -> original), with `maxdist = 100%` of the
   diagonal so that no sample is ignored, after dropping unreferenced vertices (see `load`),
   in two kinds of runs (see `hausdorff`):
   - the MAX is the largest of `--repeats` runs (default 3) sampling the vertices, the edges
     and the faces (`samplevert=True, sampleedge=True, sampleface=True`) with
     `samplenum = max(10 * faces of the sampled mesh, --samplenum)` (default 1,000,000; the
     filter takes every vertex, then `samplenum` points spread evenly along the edges, then
     `samplenum` random points on the faces). Face samples alone miss the vertices, where the
     max usually is (8-9% low on horse and igea), and one run misses points along the edges
     that another finds, so the max of a few dense runs is as good as MeshLab's gets;
   - the MEAN and RMS come from one run sampling the faces only, uniformly by area
     (`sampleface=True`, vertices and edges off) with `samplenum = max(10 * faces of the sampled
     mesh, 100,000)` (Metro's default density, and the floor `meshslim compare` uses, without
     which the mean of a 14-face mesh moves by several % from run to run): the runs above average the vertex and edge samples in
     with the face samples, which biases their mean up by 3-6% and no longer estimates the mean
     over the surface. The filter takes no seed and its sampling is not repeatable: the mean
     moves by about 0.5% from run to run.

With `--agreement` it skips MeshLab's simplification and instead checks `meshslim compare`
against the filter on our own simplified meshes (issue 4: within 5% for the max and the mean,
both directions): for each mesh and ratio it runs `BINARY compare ORIGINAL OURS --json` and the
MeshLab runs above, and prints each direction's figures, in absolute units, with ours / MeshLab.

Distances are relative to the original's bounding-box diagonal. The two-sided mean is the plain
average of the two directions' means, (mean(A->B) + mean(B->A)) / 2, NOT weighted by sample
counts: the original->simplified direction has up to 100x more samples at ratio 0.01 and would
otherwise hide the other direction. The two-sided max is the larger of the two maxima
(the Hausdorff distance). RMS is combined as sqrt((rms_ab^2 + rms_ba^2) / 2).

Times: MeshLab's is the filter call alone. Ours is the simplify time our `--json` output reports
(`seconds.simplify`, or any of the keys listed in TIME_KEYS, searched recursively), else the sidecar's, else the wall time
of the whole process (reading and writing included; marked with `*` in the table).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CRATE = Path(__file__).resolve().parent.parent
MESH_EXTENSIONS = {".ply", ".obj", ".stl", ".off"}
# Keys in our JSON that may hold the simplify time, with their unit factor to seconds.
TIME_KEYS = {
    "simplify_seconds": 1.0,
    "simplify_secs": 1.0,
    "seconds": 1.0,
    "secs": 1.0,
    "elapsed_seconds": 1.0,
    "time_seconds": 1.0,
    "time_s": 1.0,
    "simplify_ms": 1e-3,
    "elapsed_ms": 1e-3,
    "time_ms": 1e-3,
    "ms": 1e-3,
}



def print_aligned(head, lines):
    """Prints rows of strings as a column-aligned table with a rule under the header."""
    widths = [max(len(x) for x in col) for col in zip(head, *lines)]
    for i, line in enumerate([head, *lines]):
        print(" | ".join(x.ljust(w) for x, w in zip(line, widths)))
        if i == 0:
            print("-+-".join("-" * w for w in widths))

def models_dir() -> Path | None:
    """Same search order as meshslim::bench::models_dir."""
    candidates = []
    if os.environ.get("MESHSLIM_MODELS"):
        candidates.append(Path(os.environ["MESHSLIM_MODELS"]))
    candidates.append(CRATE / ".." / "shared" / "models")
    candidates.append(Path("..") / "shared" / "models")
    return next((c.resolve() for c in candidates if c.is_dir()), None)


def ratio_name(ratio: float) -> str:
    # Same text as Rust's `{}` for f64: 0.1 -> "0.1", 0.01 -> "0.01", 1.0 -> "1".
    return repr(ratio).removesuffix(".0")


def find_time(value, depth: int = 0) -> float | None:
    """The first time-like key in a JSON value, in seconds."""
    if depth > 4:
        return None
    if isinstance(value, dict):
        # `meshslim simplify --json` reports {"seconds": {"load", "simplify", "save"}}.
        secs = value.get("seconds")
        if isinstance(secs, dict) and isinstance(secs.get("simplify"), (int, float)):
            return float(secs["simplify"])
        for key, factor in TIME_KEYS.items():
            if isinstance(value.get(key), (int, float)):
                return float(value[key]) * factor
        for v in value.values():
            t = find_time(v, depth + 1)
            if t is not None:
                return t
    elif isinstance(value, list):
        for v in value:
            t = find_time(v, depth + 1)
            if t is not None:
                return t
    return None


def run_ours(binary: Path, src: Path, out: Path, ratio: float) -> tuple[float, bool]:
    """Runs our CLI; returns (seconds, exact) where exact is False for a wall-clock time."""
    cmd = [str(binary), "simplify", str(src), str(out), "--ratio", str(ratio), "--json"]
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr}")
    try:
        t = find_time(json.loads(proc.stdout))
    except json.JSONDecodeError:
        t = None
    return (t, True) if t is not None else (wall, False)


def ours_from_dir(ours: Path, stem: str, ratio: float) -> tuple[Path, float | None, bool]:
    path = ours / f"{stem}-{ratio_name(ratio)}.ply"
    if not path.is_file():
        raise FileNotFoundError(f"{path} is missing (expected <stem>-<ratio>.ply in --ours)")
    sidecar = path.with_suffix(".json")
    t = None
    if sidecar.is_file():
        t = find_time(json.loads(sidecar.read_text()))
    return path, t, t is not None


# Settings of the MeshLab runs (see the module documentation); main() may change them.
MAX_REPEATS = 3
MAX_SAMPLENUM = 1_000_000
# Least samplenum of the face-only run for the mean (meshslim compare's MIN_FACE_SAMPLES).
MEAN_MIN_SAMPLENUM = 100_000


def load(ms, path: Path) -> int:
    """Loads a mesh and drops its unreferenced vertices; returns its id.

    The filter's vertex sampling takes every vertex, isolated ones included (the Stanford bunny
    has 1,113 that no face uses), and they are no part of the surface: meshslim measures the
    vertices that faces use. Dropping them changes neither the surface nor the decimation."""
    ms.load_new_mesh(str(path))
    ms.meshing_remove_unreferenced_vertices()
    return ms.current_mesh_id()


def hausdorff(ms, sampled: int, target: int, diag: float) -> dict:
    """One direction: samples on mesh `sampled`, distances to mesh `target`, relative to diag.

    max: the largest of MAX_REPEATS runs sampling vertices, edges and faces densely;
    mean, RMS: one run sampling the faces only, 10 per face (Metro's density)."""
    import pymeshlab as ml

    ms.set_current_mesh(sampled)
    faces = ms.current_mesh().face_number()
    common = dict(
        sampledmesh=sampled,
        targetmesh=target,
        savesample=False,
        samplefauxedge=False,
        maxdist=ml.PercentageValue(100.0),
    )
    r = ms.get_hausdorff_distance(
        samplevert=False,
        sampleedge=False,
        sampleface=True,
        samplenum=max(10 * faces, MEAN_MIN_SAMPLENUM),
        **common,
    )
    maxima = []
    for _ in range(MAX_REPEATS):
        ms.set_current_mesh(sampled)
        m = ms.get_hausdorff_distance(
            samplevert=True,
            sampleedge=True,
            sampleface=True,
            samplenum=max(10 * faces, MAX_SAMPLENUM),
            **common,
        )
        maxima.append(m["max"])
    return {
        "mean": r["mean"] / diag,
        "max": max(maxima) / diag,
        "rms": r["RMS"] / diag,
        "samples": int(r["n_samples"]),
        "max_runs": [x / diag for x in maxima],
        "face_only_max": r["max"] / diag,
    }


def two_sided(ms, original: int, simplified: int, diag: float) -> dict:
    ab = hausdorff(ms, original, simplified, diag)
    ba = hausdorff(ms, simplified, original, diag)
    return {
        "mean": (ab["mean"] + ba["mean"]) / 2,
        "max": max(ab["max"], ba["max"]),
        "rms": math.sqrt((ab["rms"] ** 2 + ba["rms"] ** 2) / 2),
        "original_to_simplified": ab,
        "simplified_to_original": ba,
    }


def compare(src: Path, ratios: list[float], args, workdir: Path) -> list[dict]:
    import pymeshlab as ml

    ms = ml.MeshSet()
    original = load(ms, src)
    m0 = ms.current_mesh()
    faces0 = m0.face_number()
    diag = m0.bounding_box().diagonal()
    stem = src.stem
    rows = []
    for ratio in ratios:
        row = {
            "mesh": src.name,
            "ratio": ratio,
            "input_faces": faces0,
            "diagonal": diag,
        }
        # MeshLab.
        load(ms, src)
        target = max(int(round(ratio * faces0)), 1)
        start = time.perf_counter()
        ms.meshing_decimation_quadric_edge_collapse(
            targetfacenum=target, preservetopology=True
        )
        row["meshlab_seconds"] = time.perf_counter() - start
        lab = ms.current_mesh_id()
        row["meshlab_faces"] = ms.current_mesh().face_number()
        row["meshlab"] = two_sided(ms, original, lab, diag)
        if args.keep:
            ms.set_current_mesh(lab)
            ms.save_current_mesh(str(workdir / f"{stem}-{ratio_name(ratio)}-meshlab.ply"))
        # Ours.
        try:
            if args.ours:
                out, secs, exact = ours_from_dir(Path(args.ours), stem, ratio)
            else:
                out = workdir / f"{stem}-{ratio_name(ratio)}.ply"
                secs, exact = run_ours(Path(args.binary), src, out, ratio)
            ours = load(ms, out)
            row["ours_faces"] = ms.current_mesh().face_number()
            row["ours_seconds"] = secs
            row["ours_seconds_is_wall_clock"] = not exact
            row["ours"] = two_sided(ms, original, ours, diag)
        except Exception as e:  # report and keep going with the other meshes
            row["ours_error"] = str(e)
            print(f"{src.name} @ {ratio}: ours failed: {e}", file=sys.stderr)
        rows.append(row)
        print(f"done {src.name} @ {ratio}", file=sys.stderr, flush=True)
    return rows


def agreement(src: Path, ratios: list[float], args, workdir: Path) -> list[dict]:
    """`meshslim compare ORIGINAL OURS` against MeshLab's filter on our simplified meshes."""
    import pymeshlab as ml

    stem = src.stem
    rows = []
    for ratio in ratios:
        if args.ours:
            out, _, _ = ours_from_dir(Path(args.ours), stem, ratio)
        else:
            out = workdir / f"{stem}-{ratio_name(ratio)}.ply"
            run_ours(Path(args.binary), src, out, ratio)
        cmd = [str(args.binary), "compare", str(src), str(out), "--json"]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr}")
        d = json.loads(proc.stdout)["distance"]
        ms = ml.MeshSet()
        original = load(ms, src)
        simplified = load(ms, out)
        # Absolute units (diag = 1): no dependence on how either tool computes the diagonal.
        lab = {
            "a_to_b": hausdorff(ms, original, simplified, 1.0),
            "b_to_a": hausdorff(ms, simplified, original, 1.0),
        }
        for direction in ("a_to_b", "b_to_a"):
            rows.append(
                {
                    "mesh": src.name,
                    "ratio": ratio,
                    "direction": direction,
                    "ours": {k: d[direction][k] for k in ("max", "mean", "rms")},
                    "meshlab": lab[direction],
                }
            )
        print(f"done {src.name} @ {ratio}", file=sys.stderr, flush=True)
    return rows


def print_agreement(rows: list[dict]) -> bool:
    """Prints the agreement table; True when every row is within 5%."""
    head = ("mesh", "ratio", "direction", "max ours / MeshLab (x)", "mean ours / MeshLab (x)", "5%")
    lines = []
    all_ok = True
    for r in rows:
        o, lab = r["ours"], r["meshlab"]
        qx = o["max"] / lab["max"] if lab["max"] > 0 else math.inf
        qm = o["mean"] / lab["mean"] if lab["mean"] > 0 else math.inf
        ok = abs(qx - 1) <= 0.05 and abs(qm - 1) <= 0.05
        all_ok = all_ok and ok
        lines.append(
            (
                r["mesh"],
                ratio_name(r["ratio"]),
                "orig->ours" if r["direction"] == "a_to_b" else "ours->orig",
                f"{o['max']:.4e} / {lab['max']:.4e} ({qx:.3f})",
                f"{o['mean']:.4e} / {lab['mean']:.4e} ({qm:.3f})",
                "yes" if ok else "NO",
            )
        )
    print_aligned(head, lines)
    print(
        "absolute distances; (x) = ours / MeshLab; MeshLab max = largest of "
        f"{MAX_REPEATS} vertex+edge+face runs, mean = face-only run"
    )
    return all_ok


def fmt_time(t: float | None, exact: bool = True) -> str:
    if t is None:
        return "-"
    return f"{t:.3f}{'' if exact else '*'}"


def print_table(rows: list[dict]) -> None:
    head = (
        "mesh",
        "ratio",
        "faces ours/MeshLab",
        "mean ours / MeshLab (x)",
        "max ours / MeshLab (x)",
        "time s ours / MeshLab",
    )
    lines = []
    for r in rows:
        lab = r["meshlab"]
        if "ours" in r:
            o = r["ours"]
            faces = f"{r['ours_faces']}/{r['meshlab_faces']}"
            mean = f"{o['mean']:.2e} / {lab['mean']:.2e} ({o['mean'] / lab['mean']:.2f})"
            mx = f"{o['max']:.2e} / {lab['max']:.2e} ({o['max'] / lab['max']:.2f})"
            tm = (
                f"{fmt_time(r['ours_seconds'], not r['ours_seconds_is_wall_clock'])} / "
                f"{r['meshlab_seconds']:.3f}"
            )
        else:
            faces = f"-/{r['meshlab_faces']}"
            mean = f"- / {lab['mean']:.2e}"
            mx = f"- / {lab['max']:.2e}"
            tm = f"- / {r['meshlab_seconds']:.3f}"
        lines.append((r["mesh"], ratio_name(r["ratio"]), faces, mean, mx, tm))
    print_aligned(head, lines)
    print(
        "distances relative to the original's bbox diagonal; mean = average of both directions, "
        "max = larger direction; (x) = ours / MeshLab; * = wall clock of the whole CLI run"
    )


def main() -> int:
    global MAX_REPEATS, MAX_SAMPLENUM
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--models-dir", help="folder of meshes (default: as meshslim::bench)")
    p.add_argument("--models", nargs="*", help="file names in the models folder (default: all)")
    p.add_argument("--ratios", nargs="*", type=float, default=[0.1, 0.01])
    p.add_argument("--ours", help="folder of our outputs named <stem>-<ratio>.ply")
    p.add_argument(
        "--binary",
        default=str(CRATE / "target" / "release" / "meshslim"),
        help="our CLI, run as BINARY simplify IN OUT --ratio R --json",
    )
    p.add_argument("--json", help="also write the rows to this file")
    p.add_argument(
        "--agreement",
        action="store_true",
        help="check `meshslim compare` against MeshLab's filter on our simplified meshes",
    )
    p.add_argument(
        "--repeats", type=int, default=MAX_REPEATS, help="MeshLab runs whose max is taken"
    )
    p.add_argument(
        "--samplenum",
        type=int,
        default=MAX_SAMPLENUM,
        help="least samplenum of the MeshLab runs for the max",
    )
    p.add_argument("--keep", help="keep the simplified meshes in this folder")
    args = p.parse_args()
    MAX_REPEATS = max(args.repeats, 1)
    MAX_SAMPLENUM = args.samplenum

    try:
        import pymeshlab  # noqa: F401
    except ImportError as e:
        print(f"pymeshlab is needed: pip install pymeshlab ({e})", file=sys.stderr)
        return 2
    folder = Path(args.models_dir) if args.models_dir else models_dir()
    if folder is None or not folder.is_dir():
        print("no models folder: set MESHSLIM_MODELS or pass --models-dir", file=sys.stderr)
        return 2
    if args.models:
        files = [folder / m for m in args.models]
    else:
        files = sorted(
            f for f in folder.rglob("*") if f.suffix.lower() in MESH_EXTENSIONS and f.is_file()
        )
    if not args.ours and not Path(args.binary).is_file():
        print(f"{args.binary} is missing: cargo build --release, or pass --ours DIR", file=sys.stderr)
        return 2

    rows = []
    with tempfile.TemporaryDirectory(prefix="meshslim-compare-") as tmp:
        workdir = Path(args.keep) if args.keep else Path(tmp)
        workdir.mkdir(parents=True, exist_ok=True)
        for f in files:
            if args.agreement:
                rows.extend(agreement(f, args.ratios, args, workdir))
            else:
                rows.extend(compare(f, args.ratios, args, workdir))
    if args.agreement:
        ok = print_agreement(rows)
        if args.json:
            Path(args.json).write_text(json.dumps(rows, indent=2) + "\n")
        return 0 if ok else 1
    print_table(rows)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2) + "\n")
    return 1 if any("ours_error" in r for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
