#!/usr/bin/env python3
"""meshslim's isotropic remeshing beside MeshLab's and gpytoolbox's, in one run.

For each model: the target edge length is twice the input's mean edge length (meshslim's
`--edge-factor 2`; the same absolute length is given to the peers), 5 iterations each. Every
result is measured by the same tools: faces, mean smallest angle, share of faces with an angle
under 30 degrees, Euler characteristic and manifoldness by `meshslim info --json`, and the mean
two-sided Metro distance relative to the diagonal by `meshslim compare --json`.

Times are the remeshing call alone (reading and writing apart): meshslim's from its own report
(`report.seconds.total`, which includes building its half-edges and BVHs), MeshLab's
`meshing_isotropic_explicit_remeshing` (every other parameter at its default: feature angle 30,
surface-distance check on, no adaptivity) and gpytoolbox's `remesh_botsch` (project=True, no
feature edges, its defaults) timed around the call.

Install (outside the repository):
    python3 -m venv /tmp/remeshvenv && /tmp/remeshvenv/bin/pip install pymeshlab gpytoolbox
    (pymeshlab needs the system libGL.so.1 / libOpenGL.so.0: Debian's libgl1, libopengl0)
Run (after `cargo build --release`):
    /tmp/remeshvenv/bin/python benches/remesh_peers.py target/release/meshslim \\
        ../shared/models/horse.ply ../shared/models/stanford-bunny.obj ../shared/models/igea.ply
"""

import json
import os
import subprocess
import sys
import tempfile
import time

import gpytoolbox
import numpy as np
import pymeshlab

ITERATIONS = 5
FACTOR = 2.0


def run_json(*cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def measure(binary, original, result):
    info = run_json(binary, "info", result, "--json")
    cmp = run_json(binary, "compare", original, result, "--json")
    q = info["quality"]
    return {
        "faces": info["faces"],
        "mean_min_angle": q["mean_min_angle_deg"],
        "under_30": q["share_under_30_deg"],
        "euler": info["euler_characteristic"],
        "manifold": info["manifold"],
        "distance": cmp["distance"]["two_sided"]["mean_rel"],
    }


def mean_edge(v, f):
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    e = np.unique(np.sort(e, axis=1), axis=0)
    return float(np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1).mean())


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    binary, models = sys.argv[1], sys.argv[2:]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for model in models:
            name = os.path.splitext(os.path.basename(model))[0]
            ms = pymeshlab.MeshSet()
            ms.load_new_mesh(model)
            m = ms.current_mesh()
            v, f = m.vertex_matrix(), m.face_matrix()
            length = FACTOR * mean_edge(v, f)
            rows.append({"model": name, "tool": "input", "seconds": 0.0, "length": length,
                         **measure(binary, model, model)})

            ours = os.path.join(tmp, f"{name}-meshslim.ply")
            rep = run_json(binary, "remesh", model, ours, "--edge-length", repr(length),
                           "--iterations", str(ITERATIONS), "--json")
            rows.append({"model": name, "tool": "meshslim", "length": length,
                         "seconds": rep["report"]["seconds"]["total"],
                         **measure(binary, model, ours)})

            t = time.perf_counter()
            ms.meshing_isotropic_explicit_remeshing(
                iterations=ITERATIONS, targetlen=pymeshlab.PureValue(length))
            secs = time.perf_counter() - t
            lab = os.path.join(tmp, f"{name}-meshlab.ply")
            ms.save_current_mesh(lab, save_vertex_normal=False, save_vertex_color=False)
            rows.append({"model": name, "tool": "MeshLab", "length": length, "seconds": secs,
                         **measure(binary, model, lab)})

            t = time.perf_counter()
            gv, gf = gpytoolbox.remesh_botsch(v.astype(np.float64), f.astype(np.int32),
                                              i=ITERATIONS, h=length)
            secs = time.perf_counter() - t
            gpy = os.path.join(tmp, f"{name}-gpytoolbox.ply")
            gpytoolbox.write_mesh(gpy, gv, gf)
            rows.append({"model": name, "tool": "gpytoolbox", "length": length, "seconds": secs,
                         **measure(binary, model, gpy)})

    print("| model | tool | faces | seconds | mean min angle | < 30 deg | mean distance "
          "| Euler | manifold |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['model']} | {r['tool']} | {r['faces']:,} | {r['seconds']:.3f} "
              f"| {r['mean_min_angle']:.2f} | {100 * r['under_30']:.2f}% "
              f"| {r['distance']:.3e} | {r['euler']} | {r['manifold']} |")
    if os.environ.get("REMESH_JSON"):
        with open(os.environ["REMESH_JSON"], "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
