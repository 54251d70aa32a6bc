"""Welding positions by ISO 6947 from a seam's geometry (docs/positioner.md, "ISO 6947"). Values in, values out.

slope S [deg]: the weld axis's angle above the horizontal, signed (+ when the weld runs uphill), in [-90, 90].
rotation R [deg]: in the plane across the weld axis, the angle from straight down to the weld's centreline (the
bisector of the two faces' outward normals: the way the bead's face looks), in [0, 180] (left and right folded):
180 the bead facing up (PA), 135 a fillet's bisector 45 deg above the horizontal (PB), 45 (PD), 0 overhead (PE).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from cell.types.positioner import WeldPosition

SLOPE_TOL_DEG = 5.0  # [deg] a weld in position when its slope is this close to the position's
ROTATION_TOL_DEG = 10.0  # [deg] and its rotation this close
VERTICAL_SLOPE_DEG = 60.0  # [deg] steeper than this a weld is vertical: PF up, PG down
NOMINAL_ROTATION_DEG = {"PA": 180.0, "PB": 135.0, "PD": 45.0, "PE": 0.0}  # at slope 0
NOMINAL_SLOPE_DEG = {"PF": 90.0, "PG": -90.0}


def _unit(v: npt.ArrayLike) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def slope_rotation(d: npt.ArrayLike, n_a: npt.ArrayLike, n_b: npt.ArrayLike, up: npt.ArrayLike) -> tuple[float, float]:
    """(S, R) [deg] of one waypoint: weld direction ``d`` (3,), the faces' outward normals ``n_a``, ``n_b`` (3,), the
    world's up ``up`` (3,), all in one frame. R is measured about the weld axis from the downward vertical's
    projection; for a vertical weld (no such projection) R is 0."""
    d_u, u = _unit(d), _unit(up)
    s = math.degrees(math.asin(float(np.clip(d_u @ u, -1.0, 1.0))))
    b = _unit(np.asarray(n_a, dtype=float) + np.asarray(n_b, dtype=float))
    b_p = b - (b @ d_u) * d_u
    down_p = -u + (u @ d_u) * d_u
    nb, nd = float(np.linalg.norm(b_p)), float(np.linalg.norm(down_p))
    if nb < 1e-9 or nd < 1e-9:
        return s, 0.0
    r = math.degrees(math.acos(float(np.clip((b_p / nb) @ (down_p / nd), -1.0, 1.0))))
    return s, r


def code(slope_deg: float, rotation_deg: float) -> str:
    """The position's code from (S, R) [deg] (the classes of cell/process/procedures.position: PF / PG steeper
    than ``VERTICAL_SLOPE_DEG``, else by the bisector's elevation R - 90: PA above 67.5, PB down to -22.5, PD down to
    -67.5, PE below)."""
    if abs(slope_deg) >= VERTICAL_SLOPE_DEG:
        return "PF" if slope_deg > 0.0 else "PG"
    elev = rotation_deg - 90.0
    if elev > 67.5:
        return "PA"
    if elev >= -22.5:
        return "PB"
    return "PD" if elev >= -67.5 else "PE"


def off_nominal(target: str, slope_deg: float, rotation_deg: float) -> tuple[float, float]:
    """(|dS|, |dR|) [deg]: how far a waypoint lies from ``target``'s nominal slope and rotation (a vertical
    position's rotation is free: 0)."""
    if target in NOMINAL_SLOPE_DEG:
        return abs(slope_deg - NOMINAL_SLOPE_DEG[target]), 0.0
    return abs(slope_deg), abs(rotation_deg - NOMINAL_ROTATION_DEG[target])


def weld_position(
    d: npt.ArrayLike, n_a: npt.ArrayLike, n_b: npt.ArrayLike, up: npt.ArrayLike, target: str = "PB"
) -> WeldPosition:
    """The worst waypoint's position of a weld against ``target`` (``PA``, ``PB``, ``PD``, ``PE``, ``PF``, ``PG``):
    ``d``, ``n_a``, ``n_b`` (n, 3) or (3,) per waypoint, ``up`` (3,), all in one frame. The slope is the worst
    slope's, the rotation the worst rotation's; the code the worst waypoint's."""
    D, A, B = (np.atleast_2d(np.asarray(v, dtype=float)) for v in (d, n_a, n_b))
    n = max(len(D), len(A), len(B))
    D, A, B = (np.broadcast_to(v, (n, 3)) for v in (D, A, B))
    sr = [slope_rotation(D[i], A[i], B[i], up) for i in range(n)]
    offs = [off_nominal(target, s, r) for s, r in sr]
    i_s = int(np.argmax([o[0] for o in offs]))
    i_r = int(np.argmax([o[1] for o in offs]))
    worst = int(np.argmax([max(o[0] / SLOPE_TOL_DEG, o[1] / ROTATION_TOL_DEG) for o in offs]))
    within = all(o[0] <= SLOPE_TOL_DEG and o[1] <= ROTATION_TOL_DEG for o in offs)
    return WeldPosition(code(*sr[worst]), sr[i_s][0], sr[i_r][1], target, within)
