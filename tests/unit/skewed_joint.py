"""A mitred flat-bar brace meeting a rail at an angle, ray-cast with numpy, for the ends' tests (test_seam_ends.py).

The rail B (400 x 60 x 60 mm, along x) lies on the table (z = 0); the brace A, a flat bar 30 mm wide and 12 mm thick
lying on the table, runs away from B's -y face at ``angle_deg`` to the rail, its end mitred parallel to that face
across a ``gap_m`` gap. The seam (A's top face on B's -y face) runs along x, ``width / sin(angle)`` long. A third
body may stand where the seam ends (``third``: a box the acute end of the brace runs against). Convex bodies only,
each given by its outward face planes; cameras above and in front of the joint, depth noise along the ray and a few
% of flying pixels. Frame R = the joint's frame, metres.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray, invert, look_at, make_pose, transform_points
from cell.types import Box, Cloud, MapSeam, Part, Polyhedron, SeamScene, WeldMap

WIDTH_M = 0.030  # the brace across its axis [m]
THICK_M = 0.012  # the brace's height above the table [m]
LENGTH_M = 0.20  # the brace along its axis, from its mitred end [m]
CAMERAS = (((0.25, -0.55, 0.75), (0.0, -0.03, 0.0)), ((-0.3, -0.6, 0.7), (0.0, -0.03, 0.0)))  # (eye, target) [m]


def rail(dx: float = 0.0) -> Box:
    """The rail B, shifted ``dx`` [m] along x."""
    return Box(make_pose(p=(dx, 0.03, 0.03)), np.array([0.4, 0.06, 0.06]))


def brace(angle_deg: float, gap_m: float, x0: float = 0.0) -> Polyhedron:
    """The brace A: its mitred end on y = -gap from x = x0 to x0 + WIDTH / sin(angle); its axis at ``angle_deg`` to
    x, running to -y (its acute corner at x0 + WIDTH / sin(angle))."""
    a = np.radians(angle_deg)
    axis = np.array([-np.cos(a), -np.sin(a), 0.0])  # from the end into the brace
    span = WIDTH_M / np.sin(a)
    p0, p1 = np.array([x0, -gap_m, 0.0]), np.array([x0 + span, -gap_m, 0.0])
    q0, q1 = p0 + LENGTH_M * axis, p1 + LENGTH_M * axis
    base = [p0, p1, q1, q0]  # counter-clockwise seen from above? checked below
    if float(np.cross(base[1] - base[0], base[2] - base[1])[2]) < 0.0:
        base = base[::-1]
    up = np.array([0.0, 0.0, THICK_M])
    v = np.array([*base, *(p + up for p in base)])
    faces = ((3, 2, 1, 0), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))
    return Polyhedron(v, faces)


def seam_of(angle_deg: float, gap_m: float, x0: float = 0.0) -> tuple[FloatArray, FloatArray]:
    """The true seam: A's top edge of its mitred end, on B's face (y = 0 less the gap: the line lies on B's face
    plane y = 0 at A's top z)."""
    span = WIDTH_M / np.sin(np.radians(angle_deg))
    return np.array([x0, 0.0, THICK_M]), np.array([x0 + span, 0.0, THICK_M])


def _planes(body: Box | Polyhedron) -> FloatArray:
    poly = body.to_polyhedron() if isinstance(body, Box) else body
    return np.array([[*poly.face_plane(n)[0], poly.face_plane(n)[1]] for n in poly.face_names()])


def _ray_convex(eye: FloatArray, D: FloatArray, bodies: Sequence[FloatArray]) -> tuple[FloatArray, FloatArray]:
    """Nearest hit distance (m,) of unit rays D (m, 3) from ``eye`` on convex bodies (each (F, 4) outward planes n,
    d), and the normal there (m, 3)."""
    best = np.full(len(D), np.inf)
    normal = np.zeros((len(D), 3))
    for planes in bodies:
        n, d = planes[:, :3], planes[:, 3]
        den = D @ n.T  # (m, F)
        num = d - n @ eye  # (F,)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = num[None, :] / den
        enter = np.where(den < 0, t, -np.inf)
        leave = np.where(den > 0, t, np.inf)
        near, face = enter.max(axis=1), enter.argmax(axis=1)
        miss = np.any((den == 0) & (num[None, :] < 0), axis=1)
        hit = (near <= leave.min(axis=1)) & (near > 0.0) & (near < best) & ~miss
        best[hit] = near[hit]
        normal[hit] = n[face[hit]]
    return best, normal


@dataclass(frozen=True)
class Render:
    sigma_m: float = 0.0008  # depth noise along the ray
    pixel_rad: float = 0.0012  # angular pixel pitch
    flying: float = 0.01  # share of pixels returned up to 20 mm behind the surface


def render(bodies: Sequence[Box | Polyhedron], opts: Render, rng: np.random.Generator) -> Cloud:
    """Ray-cast ``bodies`` and the table z = 0 from CAMERAS; frame R."""
    planes = [_planes(b) for b in bodies]
    pts, cams = [], []
    for c, (eye, target) in enumerate(CAMERAS):
        X_RC = look_at(eye, target, up=(0.0, 0.0, 1.0))
        span = np.radians(14.0)
        u = np.arange(-span, span, opts.pixel_rad)
        U, V = np.meshgrid(u, u)
        D = np.column_stack([U.ravel(), V.ravel(), np.ones(U.size)]) @ X_RC[:3, :3].T
        D /= np.linalg.norm(D, axis=1, keepdims=True)
        e = np.asarray(eye, float)
        dist, normal = _ray_convex(e, D, planes)
        tz = -e[2] / np.where(D[:, 2] < -1e-9, D[:, 2], -1e-9)
        on_table = tz < dist
        dist = np.where(on_table, tz, dist)
        normal[on_table] = (0.0, 0.0, 1.0)
        ok = np.isfinite(dist) & (np.abs(np.einsum("ij,ij->i", D, normal)) > np.cos(np.radians(80.0)))
        dist, D = dist[ok], D[ok]
        dist = dist + opts.sigma_m * rng.standard_normal(len(dist))
        fly = rng.random(len(dist)) < opts.flying
        dist[fly] += rng.uniform(0.0, 0.02, int(fly.sum()))
        p = e + D * dist[:, None]
        keep = np.abs(p[:, 0]) < 0.25  # the region about the joint
        pts.append(p[keep])
        cams.append(np.full(int(keep.sum()), c, np.int16))
    return Cloud(np.vstack(pts), "R", np.concatenate(cams), tuple(f"cam{i}" for i in range(len(CAMERAS))))


def scene(
    angle_deg: float,
    gap_m: float = 0.001,
    built_dx: float = 0.0015,
    third: Box | None = None,
    seed: int = 0,
    opts: Render = Render(),
) -> tuple[SeamScene, tuple[FloatArray, FloatArray]]:
    """The brace at ``angle_deg`` on the rail (the map drawn at x0 = 0; built ``built_dx`` [m] further along x), and
    ``third`` (a box of the map and the build) where it stands: the scene (its joints found from the map) and the
    true seam."""
    from cell.seams.joint import find_joints

    built = [brace(angle_deg, gap_m, built_dx), rail()]
    drawn = [Part("BRACE", brace(angle_deg, gap_m)), Part("RAIL", rail())]
    if third is not None:
        built.append(third)
        drawn.append(Part("THIRD", third))
    dense = render(built, opts, np.random.default_rng(seed))
    seam = MapSeam("BRACE>RAIL", *seam_of(angle_deg, gap_m))
    weldmap = WeldMap(tuple(drawn), (seam,), "mm", "synthetic", frame="R")
    return SeamScene(dense, dense, weldmap, find_joints(weldmap), 0.0), seam_of(angle_deg, gap_m, built_dx)


def moved(p: FloatArray, X: FloatArray) -> FloatArray:
    """p (3,) moved by X (4, 4) (for a test that turns the scene)."""
    return transform_points(X, p)


__all__ = ["Render", "brace", "invert", "rail", "render", "scene", "seam_of"]
