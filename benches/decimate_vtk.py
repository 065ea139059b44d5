#!/usr/bin/env python3
"""meshslim's vertex decimation beside VTK's vtkDecimatePro and meshslim's greedy QEM, in one run.

For each model and ratio: faces reached, seconds, mean two-sided distance (Metro, relative to
the diagonal, by `meshslim compare`), Euler characteristic and non-manifold edges of the result,
and whether its vertices are a subset of the input's.

VTK runs as the issue measured it: PreserveTopology on, FeatureAngle 15, Splitting off,
BoundaryVertexDeletion on; time is vtkDecimatePro's Update() alone (reading and writing apart),
meshslim's is the `simplify` time its report gives (load and save apart).

Install (outside the repository):
    python3 -m venv /tmp/vtkvenv && /tmp/vtkvenv/bin/pip install vtk
Run (after `cargo build --release`):
    /tmp/vtkvenv/bin/python benches/decimate_vtk.py target/release/meshslim ../shared/models/horse.ply ...
"""

import json
import os
import subprocess
import sys
import tempfile
import time

import vtk


def read(path):
    ext = os.path.splitext(path)[1].lower()
    r = {".ply": vtk.vtkPLYReader, ".obj": vtk.vtkOBJReader, ".stl": vtk.vtkSTLReader}[ext]()
    r.SetFileName(path)
    r.Update()
    tri = vtk.vtkTriangleFilter()
    tri.SetInputData(r.GetOutput())
    tri.Update()
    # vtkOBJReader splits vertices at normals/UVs: weld by position so that topology is kept
    # across them, as meshslim welds.
    clean = vtk.vtkCleanPolyData()
    clean.SetInputData(tri.GetOutput())
    clean.PointMergingOn()
    clean.SetTolerance(0.0)
    clean.Update()
    return clean.GetOutput()


def vtk_decimate(poly, ratio, out):
    d = vtk.vtkDecimatePro()
    d.SetInputData(poly)
    d.SetTargetReduction(1.0 - ratio)
    d.PreserveTopologyOn()
    d.SetFeatureAngle(15.0)
    d.SplittingOff()
    d.BoundaryVertexDeletionOn()
    t = time.perf_counter()
    d.Update()
    seconds = time.perf_counter() - t
    w = vtk.vtkPLYWriter()
    w.SetFileName(out)
    w.SetInputData(d.GetOutput())
    w.Write()
    return seconds


def meshslim_simplify(exe, model, out, ratio, method):
    o = subprocess.run(
        [exe, "simplify", model, out, "--ratio", str(ratio), "--method", method, "--json"],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(o.stdout)["seconds"]["simplify"]


def compare(exe, a, b):
    o = subprocess.run([exe, "compare", a, b, "--json"], check=True, capture_output=True, text=True)
    return json.loads(o.stdout)


def positions(path):
    poly = read(path)
    pts = poly.GetPoints()
    return {tuple(round(c, 7) for c in pts.GetPoint(i)) for i in range(pts.GetNumberOfPoints())}


def main():
    if len(sys.argv) < 3:
        print(__doc__)
        sys.exit(2)
    exe, models = sys.argv[1], sys.argv[2:]
    tmp = tempfile.mkdtemp(prefix="decimate-vtk-")
    print("| model | ratio | tool | faces (target) | seconds | mean two-sided | euler | non-manifold edges | subset |")
    print("|---|---|---|---|---|---|---|---|---|")
    for model in models:
        name = os.path.splitext(os.path.basename(model))[0]
        src = positions(model)
        poly = read(model)
        for ratio in (0.1, 0.01):
            target = round(poly.GetNumberOfPolys() * ratio)
            runs = []
            if poly.GetNumberOfPolys() > 0:
                out = os.path.join(tmp, f"{name}-{ratio}-vtk.ply")
                runs.append(("vtkDecimatePro", out, vtk_decimate(poly, ratio, out)))
            else:
                print(f"| {name} | {ratio} | vtkDecimatePro | VTK's reader found no faces in the file | | | | | |")
            for method in ("decimate", "qem"):
                out = os.path.join(tmp, f"{name}-{ratio}-{method}.ply")
                runs.append((f"meshslim {method}", out, meshslim_simplify(exe, model, out, ratio, method)))
            for tool, out, seconds in runs:
                c = compare(exe, model, out)
                topo = c["topology"]
                target = round(c["faces_a"] * ratio)
                subset = ("yes" if positions(out) <= src else "no") if src else "n/a (VTK cannot read it)"
                print(
                    f"| {name} | {ratio} | {tool} | {c['faces_b']} ({target}) | {seconds:.3f} | "
                    f"{c['distance']['two_sided']['mean_rel']:.3e} | "
                    f"{topo['a']['euler_characteristic']} -> {topo['b']['euler_characteristic']} | "
                    f"{topo['a']['non_manifold_edges']} -> {topo['b']['non_manifold_edges']} | "
                    f"{subset} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
