#!/usr/bin/env python3
"""Writes the fuzzers' seed corpora: the hostile cases of tests/io.rs, and every shared model
(../shared/models) simplified to a few hundred faces and written in every format by meshslim
itself, so that each seed carries the model's attributes (normals, UVs, quads, seams) in a size
the fuzzer mutates quickly. The models are never committed; the corpora live in fuzz/corpus
(ignored by git).

usage: seeds.py MESHSLIM_BINARY MODELS_DIR CORPUS_DIR
"""

import pathlib
import struct
import subprocess
import sys
import tempfile

# The simplify target reads its first byte as an index into this list (fuzz_targets/simplify.rs).
FORMATS = ["obj", "ply", "stl", "gltf", "glb"]
# Seeds larger than this slow every mutation down; run.sh passes the same -max_len.
MAX_SEED = 128 * 1024


def ply_head(nv, nf, fmt="binary_little_endian"):
    return (
        f"ply\nformat {fmt} 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\n"
        f"property float z\nelement face {nf}\nproperty list uchar int vertex_indices\nend_header\n"
    ).encode()


def hostile():
    """The hostile inputs of tests/io.rs (hostile_* tests), as (format, bytes)."""
    out = [(ext, b"") for ext in FORMATS]
    tri = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + b"\x03" + struct.pack("<3i", 0, 1, 2)
    good = ply_head(3, 1) + tri
    out += [
        ("ply", good),
        ("ply", good[:-3]),
        ("ply", ply_head(1000, 1) + tri),
        ("ply", ply_head(3, 4_000_000_000) + tri),
        ("ply", ply_head(5_000_000_000, 0) + bytes(64)),
        ("ply", good[:-4] + struct.pack("<i", 7)),
        ("ply", ply_head(3, 1)[: -len(b"end_header\n")] + b"end_header\n" + tri[:12]
         + struct.pack("<f", float("nan")) + tri[16:]),
        ("ply", ply_head(3, 4_000_000_000, "ascii") + b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
        ("ply", ply_head(3, 1, "ascii") + b"0 0 0\n1 0 0\n0 1 0\n3 0 1 -3\n"),
        ("ply", ply_head(3, 1, "ascii").replace(b"uchar int", b"uchar uint")
         + b"0 0 0\n1 0 0\n0 1 0\n4 0 1 2 0\n"),
        ("ply", b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n"),
        ("ply", b"ply\nformat ascii 1.0\nelement vertex 1\n"),
        ("ply", b"ply\n" + b"x" * 4096),
        ("ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
         b"property float y\nproperty float z\nelement face 1\nproperty list int int vertex_indices\n"
         b"end_header\n" + struct.pack("<12f", *range(12)) + struct.pack("<5i", 4, 0, 1, 2, 3)),
    ]
    v = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n"
    out += [("obj", t) for t in [
        v + b"f 1 2 4\n", v + b"f -1 -2 -4\n", v + b"f 0 1 2\n", v + b"vt 0 0\nf 1/1 2/2 3/1\n",
        v + b"v nan 0 0\nf 1 2 4\n", b"v 0 0 0\nv 1 -inf 0\n", b"v 0 0 0\nv 1 x 0\n",
        v + b"f 1 2 three\n", v + b"f 1 2\n", b"# nothing here\n",
        b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n",
        v + b"v 1 1 0\nvn 0 0 1\nvt 0 0\nusemtl a\ng one\nf 1/1/1 2/1/1 4/1/1 3/1/1\nmtllib none.mtl\n",
    ]]
    stl_bin = lambda n, recs: bytes(80) + struct.pack("<I", n) + recs
    rec = bytearray(50)
    rec[24:28] = struct.pack("<f", float("nan"))
    ok = bytearray(50)
    ok[24:48] = struct.pack("<6f", 1, 0, 0, 0, 1, 0)
    out += [
        ("stl", stl_bin(4_000_000_000, bytes(50))),
        ("stl", b"\x01" * 20),
        ("stl", stl_bin(1, bytes(rec))),
        ("stl", b"solid but binary".ljust(80) + struct.pack("<I", 1) + bytes(ok)),
    ]
    facet = b"facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
    out += [("stl", b"solid x\n" + facet + t) for t in [
        b"vertex 0 1 nan\nendloop\nendfacet\nendsolid x\n", b"vertex 1 0\n", b"endloop\n",
        b"vertex 0 1 0\nendloop\nendfacet\nendsolid x\n",
    ]]
    out += [
        ("gltf", b'{"asset": {"version": "2.0"},\n "meshes": [ nope ]}'),
        ("glb", b"glTF\x02\0\0\0\xff\xff\0\0"),
    ]
    return out


def convert(binary, model, ext, tmp):
    """The model simplified to about 300 faces and written as `ext` by meshslim."""
    out = pathlib.Path(tmp) / f"seed.{ext}"
    r = subprocess.run([binary, "simplify", str(model), str(out), "--faces", "300",
                        "--backend", "cpu", "--quiet"], capture_output=True)
    if r.returncode != 0:
        sys.stderr.write(f"skipped {model.name} as {ext}: {r.stderr.decode().strip()}\n")
        return None
    data = out.read_bytes()
    return data if len(data) <= MAX_SEED else None


def ascii_stl(data):
    """A binary STL's triangles as ascii STL (the writer's default is binary)."""
    (n,) = struct.unpack_from("<I", data, 80)
    lines = ["solid seed"]
    for i in range(n):
        f = struct.unpack_from("<12f", data, 84 + 50 * i)
        lines.append("facet normal %g %g %g\nouter loop" % f[:3])
        lines += ["vertex %g %g %g" % f[3 + 3 * k: 6 + 3 * k] for k in range(3)]
        lines.append("endloop\nendfacet")
    lines.append("endsolid seed\n")
    return "\n".join(lines).encode()


def main():
    binary, models, corpus = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
    seeds = hostile()
    found = sorted(p for p in models.rglob("*") if p.suffix.lower() in (".obj", ".ply"))
    with tempfile.TemporaryDirectory() as tmp:
        for model in found:
            if model.stat().st_size <= MAX_SEED:
                seeds.append((model.suffix[1:].lower(), model.read_bytes()))
            for ext in FORMATS:
                data = convert(binary, model, ext, tmp)
                if data is not None:
                    seeds.append((ext, data))
                    if ext == "stl":
                        seeds.append(("stl", ascii_stl(data)))
    counts = {}
    with tempfile.TemporaryDirectory() as tmp:
        # Cluster DAGs of small built-in meshes, one with colours.
        for k, mesh in enumerate(["builtin:sphere:300", "builtin:torus:800", "builtin:grid:500"]):
            out = pathlib.Path(tmp) / f"dag{k}.mslod"
            subprocess.run([binary, "dag", "build", mesh, str(out)], check=True, capture_output=True)
            d = corpus / "read_mslod"
            d.mkdir(parents=True, exist_ok=True)
            (d / f"seed-{k:03}.mslod").write_bytes(out.read_bytes())
            counts["read_mslod"] = counts.get("read_mslod", 0) + 1
    for k, (ext, data) in enumerate(seeds):
        target = "read_gltf" if ext in ("gltf", "glb") else f"read_{ext}"
        for name, body in [(target, data),
                           ("simplify", bytes([FORMATS.index(ext), 26 + 77 * (k % 3), k % 8]) + data)]:
            d = corpus / name
            d.mkdir(parents=True, exist_ok=True)
            (d / f"seed-{k:03}.{ext}").write_bytes(body)
            counts[name] = counts.get(name, 0) + 1
    print(f"{len(found)} models, {len(seeds)} seeds: {counts}")


if __name__ == "__main__":
    main()
