"""Which points of the map's surfaces are open to the sky (nothing of the map's parts lies straight above them) or
in sight of a sensor (nothing of them between the point and the sensor's centre); frame R, z up, metres. The
parts-seen check (:func:`cell.perception.align.checks.part_coverage`) judges a part only by the samples of its top
a camera can see: an open tube's inner bottom wall faces up but lies under the tube's own top wall, and a plate's
top behind a standing pipe is in its shadow."""

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
    vertices, triangles = _meshes(parts)
    up = np.broadcast_to([0.0, 0.0, 1.0], p.shape)
    return ~_open3d.rays_hit(vertices, triangles, p + np.array([0.0, 0.0, clear_m]), up)


def _meshes(parts: Sequence[Part]) -> tuple[FloatArray, npt.NDArray[np.int64]]:
    """Every part's triangles as one mesh: vertices (v, 3), triangles (t, 3)."""
    meshes = [part.triangles() for part in parts]
    starts = np.cumsum([0] + [len(V) for V, _ in meshes[:-1]])
    vertices = np.concatenate([V for V, _ in meshes])
    return vertices, np.concatenate([T + s for (_, T), s in zip(meshes, starts, strict=True)])


def in_sight(p: FloatArray, eyes: FloatArray, parts: Sequence[Part], clear_m: float = CLEAR_M) -> BoolArray:
    """(n,) whether each point p (n, 3) sees at least one of ``eyes`` (k, 3) (sensor centres) with no triangle of
    ``parts`` on the way: a ray from ``clear_m`` towards the eye to the eye (open3d's, as :func:`open_to_sky`)."""
    p = np.asarray(p, dtype=float).reshape(-1, 3)
    eyes = np.asarray(eyes, dtype=float).reshape(-1, 3)
    if not len(p) or not parts or not len(eyes):
        return np.ones(len(p), dtype=bool)
    vertices, triangles = _meshes(parts)
    seen = np.zeros(len(p), dtype=bool)
    for eye in eyes:
        d = eye - p
        dist = np.linalg.norm(d, axis=1)
        u = d / np.maximum(dist, 1e-12)[:, None]
        seen |= ~_open3d.rays_hit(vertices, triangles, p + clear_m * u, u, dist - clear_m)
    return seen
