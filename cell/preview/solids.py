"""Triangle meshes of what the 3D view draws as solids, numpy only: the robot's shapes, the table, any part's body
(box or polyhedron), camera frusta.

Input in the robot frame R [m]; meshes come out in millimetres (vertices (n, 3), triangles (m, 3) of vertex
indices), ready for plotly's ``Mesh3d``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from cell.geometry import FloatArray
from cell.preview.views import MM
from cell.types import Box, CameraView, Part, RobotPose, Shape, ShapeKind

_SIDES = 16  # facets around a cylinder
# corners indexed by bits (x, y, z) as Box.corners: 0 = ---, 1 = --+, 2 = -+-, 3 = -++, 4 = +--, ...
_BOX_FACES = np.array(
    [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4],
     [1, 5, 7], [1, 7, 3]]
)  # fmt: skip


class Mesh(NamedTuple):
    """Triangles to draw: vertices (n, 3) [mm], triangles (m, 3) of vertex indices."""

    vertices: FloatArray
    triangles: np.ndarray


def _unit_box() -> FloatArray:
    return np.array([[sx, sy, sz] for sx in (-0.5, 0.5) for sy in (-0.5, 0.5) for sz in (-0.5, 0.5)])


def _unit_cylinder() -> tuple[FloatArray, np.ndarray]:
    """Diameter 1, length 1 along z: a ring of ``_SIDES`` at each end plus both end centres."""
    a = np.linspace(0.0, 2.0 * np.pi, _SIDES, endpoint=False)
    ring = np.column_stack([0.5 * np.cos(a), 0.5 * np.sin(a)])
    v = np.vstack([np.c_[ring, np.full(_SIDES, -0.5)], np.c_[ring, np.full(_SIDES, 0.5)], [[0, 0, -0.5], [0, 0, 0.5]]])
    i = np.arange(_SIDES)
    j = (i + 1) % _SIDES
    n = _SIDES
    sides = np.vstack([np.c_[i, j, j + n], np.c_[i, j + n, i + n]])
    caps = np.vstack([np.c_[np.full(n, 2 * n), j, i], np.c_[np.full(n, 2 * n + 1), i + n, j + n]])
    return v, np.vstack([sides, caps])


def _unit_sphere() -> tuple[FloatArray, np.ndarray]:
    """Diameter 1: a latitude-longitude mesh."""
    lat = np.linspace(-np.pi / 2, np.pi / 2, 7)[1:-1]
    lon = np.linspace(0.0, 2.0 * np.pi, _SIDES, endpoint=False)
    rings = [0.5 * np.c_[np.cos(b) * np.cos(lon), np.cos(b) * np.sin(lon), np.full(_SIDES, np.sin(b))] for b in lat]
    v = np.vstack([*rings, [[0, 0, -0.5], [0, 0, 0.5]]])
    n, k = _SIDES, len(lat)
    i = np.arange(n)
    j = (i + 1) % n
    tris = []
    for r in range(k - 1):
        a, b = r * n, (r + 1) * n
        tris += [np.c_[a + i, a + j, b + j], np.c_[a + i, b + j, b + i]]
    tris += [np.c_[np.full(n, k * n), j, i], np.c_[np.full(n, k * n + 1), (k - 1) * n + i, (k - 1) * n + j]]
    return v, np.vstack(tris)


def solid_mesh(kind: ShapeKind, size: FloatArray, X_RS: FloatArray) -> Mesh:
    """The mesh [mm] of a primitive solid of ``size`` (3,) [m] (see :class:`~cell.types.Shape`) at X_RS (4, 4)."""
    if kind is ShapeKind.BOX:
        v, f = _unit_box(), _BOX_FACES
    elif kind is ShapeKind.CYLINDER:
        v, f = _unit_cylinder()
    else:
        v, f = _unit_sphere()
    p = (v * np.asarray(size, dtype=float)) @ X_RS[:3, :3].T + X_RS[:3, 3]
    return Mesh(p * MM, f)


def merge(meshes: list[Mesh]) -> Mesh:
    """One mesh of several (indices offset)."""
    if not meshes:
        return Mesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=int))
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    return Mesh(
        np.vstack([m.vertices for m in meshes]),
        np.vstack([m.triangles + o for m, o in zip(meshes, offsets, strict=True)]),
    )


def link_meshes(shapes: tuple[Shape, ...], pose: RobotPose) -> dict[str, Mesh]:
    """One mesh [mm] per link of the robot at ``pose`` (links without a pose are left out)."""
    out: dict[str, list[Mesh]] = {}
    for s in shapes:
        X_RL = pose.X_RL.get(s.link)
        if X_RL is not None:
            out.setdefault(s.link, []).append(solid_mesh(s.kind, s.size, np.asarray(X_RL) @ s.X_LS))
    return {link: merge(ms) for link, ms in out.items()}


def link_colour(shapes: tuple[Shape, ...], link: str) -> str:
    """The colour (CSS rgb) of a link: its largest shape's."""
    mine = [s for s in shapes if s.link == link]
    if not mine:
        return "rgb(150,150,150)"
    big = max(mine, key=lambda s: float(np.prod(s.size)))
    r, g, b = (round(255 * c) for c in big.rgba[:3])
    return f"rgb({r},{g},{b})"


def box_mesh(box: Box) -> Mesh:
    """The mesh [mm] of a box given in R."""
    return solid_mesh(ShapeKind.BOX, box.size, box.X_AB)


def part_mesh(part: Part) -> Mesh:
    """The mesh [mm] of any part given in R: a box's twelve triangles, a polyhedron's own triangulation of its
    faces (outward winding)."""
    vertices, triangles = part.triangles()
    return Mesh(np.asarray(vertices, dtype=float) * MM, np.asarray(triangles, dtype=int))


def frustum_segments(cam: CameraView) -> FloatArray:
    """(8, 2, 3) [mm]: the four rays from the optical centre and the far rectangle of a camera's frustum."""
    p = cam.frustum() * MM
    rays = [(p[0], p[k]) for k in range(1, 5)]
    rim = [(p[k], p[k % 4 + 1]) for k in range(1, 5)]
    return np.array(rays + rim)
