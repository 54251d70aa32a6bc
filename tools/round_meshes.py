"""Meshes and seam curves of round parts for the generated maps (``tools/make_round.py``), in millimetres.

A tube (or a solid bar) is drawn as CAD exporters tessellate it: ``facets`` flat sides whose corners lie on the round
(the facets' middles at the angles k 360 / facets, so a gusset can stand square on one), its ends cut by any surface
(a plane square or at a slant, or a run pipe's round for a coped branch). Curved seams are drawn as CIRCLE and
ELLIPSE entities in their own plane (an OCS whatever its normal) or as a SPLINE through points of the true curve.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from ezdxf.layouts import BaseLayout
from ezdxf.math import Vec3
from ezdxf.render import MeshTransformer

APPID = "WELDCELL"
Cut = Callable[[float, float], float]  # (x, y) in the tube's frame -> z of its end there [mm]


def plane_cut(X_MT: np.ndarray, n_M: Sequence[float], d_M: float) -> Cut:
    """The end of a tube (frame T, axis z, pose X_MT in the map) cut by the map's plane n . p = d."""
    n_T = X_MT[:3, :3].T @ np.asarray(n_M, dtype=float)
    d_T = d_M - float(np.asarray(n_M) @ X_MT[:3, 3])
    return lambda x, y: (d_T - n_T[0] * x - n_T[1] * y) / n_T[2]


def tube_mesh(r_out: float, r_in: float, facets: int, bottom: Cut, top: Cut, X_MT: np.ndarray) -> MeshTransformer:
    """A closed tube (``r_in`` > 0) or bar (``r_in`` 0) about the z axis of frame T, between its ``bottom`` and
    ``top`` cuts, moved into the map by ``X_MT`` (4, 4); outward faces."""
    th = (np.arange(facets) + 0.5) * 2.0 * math.pi / facets
    rings = []
    for r in (r_out, r_in) if r_in > 0 else (r_out,):
        x, y = r * np.cos(th), r * np.sin(th)
        rings.append([(xi, yi, bottom(xi, yi)) for xi, yi in zip(x, y, strict=True)])
        rings.append([(xi, yi, top(xi, yi)) for xi, yi in zip(x, y, strict=True)])
    v = [p for ring in rings for p in ring]
    f: list[tuple[int, ...]] = []
    ob, ot = 0, facets
    for i in range(facets):
        j = (i + 1) % facets
        f.append((ob + i, ob + j, ot + j, ot + i))
    if r_in > 0:
        ib, it = 2 * facets, 3 * facets
        for i in range(facets):
            j = (i + 1) % facets
            f += [(ib + i, it + i, it + j, ib + j), (ot + i, ot + j, it + j, it + i), (ob + i, ib + i, ib + j, ob + j)]
    else:
        cb, ct = len(v), len(v) + 1
        v += [(0.0, 0.0, bottom(0.0, 0.0)), (0.0, 0.0, top(0.0, 0.0))]
        for i in range(facets):
            j = (i + 1) % facets
            f += [(ct, ot + i, ot + j), (cb, ob + j, ob + i)]
    P = np.asarray(v) @ X_MT[:3, :3].T + X_MT[:3, 3]
    mesh = MeshTransformer()
    mesh.vertices = [Vec3(*p) for p in P]
    mesh.faces = f
    return mesh


def prism_mesh(profile: Sequence[tuple[float, float]], thickness: float, X_MP: np.ndarray) -> MeshTransformer:
    """A plate: the convex polygon ``profile`` ((x, z) corners in order, in the plate's frame P) extruded from
    y = -thickness / 2 to +thickness / 2, moved by ``X_MP`` (the reader orients the faces outward)."""
    k = len(profile)
    h = thickness / 2.0
    v = [(u, y, w) for y in (-h, h) for u, w in profile]
    f: list[tuple[int, ...]] = [tuple(range(k)), tuple(range(2 * k - 1, k - 1, -1))]
    f += [(i, k + i, k + (i + 1) % k, (i + 1) % k) for i in range(k)]
    P = np.asarray(v) @ X_MP[:3, :3].T + X_MP[:3, 3]
    mesh = MeshTransformer()
    mesh.vertices = [Vec3(*p) for p in P]
    mesh.faces = f
    return mesh


def pose(R: np.ndarray, t: Sequence[float]) -> np.ndarray:
    X = np.eye(4)
    X[:3, :3], X[:3, 3] = R, t
    return X


def rot_y(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _tag(e: object, seam_id: str) -> None:
    e.set_xdata(APPID, [(1000, seam_id)])  # type: ignore[attr-defined]


def add_circle_seam(
    msp: BaseLayout, seam_id: str, centre: Sequence[float], radius: float, normal: Sequence[float], layer: str
) -> None:
    """A red CIRCLE in the plane through ``centre`` with ``normal`` (its OCS: centre given in OCS coordinates)."""
    from ezdxf.math import OCS

    ocs = OCS(Vec3(*normal))
    e = msp.add_circle(
        ocs.from_wcs(Vec3(*centre)), radius, dxfattribs={"layer": layer, "color": 256, "extrusion": Vec3(*normal)}
    )
    _tag(e, seam_id)


def add_tube_on_plane_seam(
    msp: BaseLayout,
    seam_id: str,
    q: Sequence[float],
    axis: Sequence[float],
    radius: float,
    normal: Sequence[float],
    layer: str,
) -> None:
    """The seam of a tube (``axis``, ``radius``) meeting the plane through ``q`` (on the axis) with ``normal``: a
    CIRCLE when square, else an ELLIPSE (minor semi-axis the radius, major the radius / cos of the lean)."""
    a, n = np.asarray(axis, float) / np.linalg.norm(axis), np.asarray(normal, float) / np.linalg.norm(normal)
    cos = abs(float(a @ n))
    if cos > 1.0 - 1e-12:
        add_circle_seam(msp, seam_id, q, radius, n, layer)
        return
    m = a - (a @ n) * n
    major = m / np.linalg.norm(m) * radius / cos
    e = msp.add_ellipse(Vec3(*q), Vec3(*major), cos, dxfattribs={"layer": layer, "color": 256, "extrusion": Vec3(*n)})
    _tag(e, seam_id)


def saddle_points(x0: float, r_branch: float, z_axis: float, r_run: float, n: int = 72) -> np.ndarray:
    """(n, 3) points of the outer saddle of a branch (axis vertical at x = x0, y = 0) set on a run pipe (axis along
    x at height ``z_axis``): (x0 + r cos t, r sin t, z_axis + sqrt(R^2 - r^2 sin^2 t))."""
    t = np.arange(n) * 2.0 * math.pi / n
    y = r_branch * np.sin(t)
    return np.column_stack([x0 + r_branch * np.cos(t), y, z_axis + np.sqrt(r_run**2 - y**2)])


def add_spline_seam(msp: BaseLayout, seam_id: str, points: np.ndarray, layer: str) -> None:
    """A red closed SPLINE through ``points`` (n, 3) (the first repeated at the end)."""
    pts = [Vec3(*p) for p in np.vstack([points, points[:1]])]
    e = msp.add_spline(fit_points=pts, dxfattribs={"layer": layer, "color": 256})
    _tag(e, seam_id)
