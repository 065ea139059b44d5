"""meshslim for trimesh: simplify a ``trimesh.Trimesh`` and keep what it looks like.

>>> import trimesh
>>> from meshslim import trimesh as mt
>>> small = mt.simplify(trimesh.load("spot.obj"), ratio=0.1)   # UVs and material kept

Vertex colours and UVs go into meshslim's cost (``color_weight``, ``uv_weight``) and come back
solved on the result's vertices; a textured mesh keeps its material (the same image), a coloured
one its vertex colours. trimesh splits vertices at UV seams; meshslim joins them for the
topology and keeps each side's UVs, so the seams stay where they were.
"""

from __future__ import annotations

from typing import Any

import numpy as np

import meshslim


def simplify(mesh: Any, *, ratio: float | None = None, target_faces: int | None = None,
             **options: Any) -> Any:
    """``mesh`` (a ``trimesh.Trimesh``) simplified to ``ratio`` of its faces (default 0.1) or to
    ``target_faces``; ``options`` as :func:`meshslim.simplify` takes them (``method``,
    ``backend``, ``max_error``, the weights, ``progress``). Returns a new ``trimesh.Trimesh``."""
    import trimesh

    visual = getattr(mesh, "visual", None)
    kind = getattr(visual, "kind", None)
    colors = uvs = None
    if kind == "vertex":
        colors = np.asarray(visual.vertex_colors, dtype=np.float32)[:, :4] / 255.0
    elif kind == "texture" and getattr(visual, "uv", None) is not None:
        uvs = np.asarray(visual.uv, dtype=np.float32)
    res = meshslim.simplify(np.asarray(mesh.vertices), np.asarray(mesh.faces), ratio=ratio,
                            target_faces=target_faces, colors=colors, uvs=uvs, **options)
    out = trimesh.Trimesh(res.vertices, res.faces, process=False)
    if res.uvs is not None and uvs is not None:
        out.visual = trimesh.visual.TextureVisuals(uv=res.uvs, material=visual.material)
    elif res.colors is not None and colors is not None:
        rgba = np.clip(np.round(res.colors * 255.0), 0, 255).astype(np.uint8)
        out.visual = trimesh.visual.ColorVisuals(out, vertex_colors=rgba)
    return out
