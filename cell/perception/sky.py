"""Which points of the map's surfaces are open to the sky: nothing of the map's parts lies straight above them
(frame R, z up, metres). The parts-seen check (:func:`cell.perception.align.checks.part_coverage`) judges a
part only by the samples of its top a camera above the table can see: an open tube's inner bottom wall faces up
but lies under the tube's own top wall."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.perception import _open3d
from cell.types import Part

BoolArray = npt.NDArray[np.bool_]
CLEAR_M = 1e-4  # a surface this little above a point is the point's own face (its triangles), not a cover [m]


def open_to_sky(p: FloatArray, parts: Sequence[Part], clear_m: float = CLEAR_M) -> BoolArray:
    """(n,) whether the vertical ray up from each point p (n, 3) meets no triangle of ``parts`` more than
    ``clear_m`` [m] above it: a ray cast (open3d's, :func:`cell.perception._open3d.rays_hit`) from ``clear_m``
    above each point against every part's triangles at once. Walls seen edge-on from above cover nothing."""
    p = np.asarray(p, dtype=float).reshape(-1, 3)
    if not len(p) or not parts:
        return np.ones(len(p), dtype=bool)
    meshes = [part.triangles() for part in parts]
    starts = np.cumsum([0] + [len(V) for V, _ in meshes[:-1]])
    vertices = np.concatenate([V for V, _ in meshes])
    triangles = np.concatenate([T + s for (_, T), s in zip(meshes, starts, strict=True)])
    up = np.broadcast_to([0.0, 0.0, 1.0], p.shape)
    return ~_open3d.rays_hit(vertices, triangles, p + np.array([0.0, 0.0, clear_m]), up)
