"""The positioner's axes along a curved seam that keep each point of it in PA (its fillet's bisector straight up)
where the torch stands: the tilt fixed, the rotate axis turning with the weld (docs/positioner.md, "Coordinated
motion"). Frames: F the faceplate at home (the part's frame while it turns), R the robot base; angles [rad]."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, readonly
from cell.positioner.iso6947 import off_nominal, slope_rotation
from cell.types.positioner import TiltRotatePositioner


@dataclass(frozen=True)
class CurveInF:
    """A curve to weld in the faceplate frame F: knots p_F, unit weld tangents t_F, the faces' outward normals
    n_a_F, n_b_F (n, 3) and the length welded at each s (n,) [m]."""

    p_F: FloatArray
    t_F: FloatArray
    n_a_F: FloatArray
    n_b_F: FloatArray
    s: FloatArray

    def __post_init__(self) -> None:
        for name in ("p_F", "t_F", "n_a_F", "n_b_F", "s"):
            object.__setattr__(self, name, readonly(np.asarray(getattr(self, name), dtype=float)))

    @property
    def bisector_F(self) -> FloatArray:
        b = np.asarray(self.n_a_F) + np.asarray(self.n_b_F)
        return np.asarray(b / np.linalg.norm(b, axis=1, keepdims=True))


def pa_axes(pos: TiltRotatePositioner, curve: CurveInF, branch: int = 1) -> FloatArray | None:
    """(n, 2) (tilt, rotate) [rad] putting each knot's bisector as near straight up as one fixed tilt allows.

    With P upright the world's up in F is u_F = (sin t sin r, sin t cos r, cos t): the bisector b = u_F needs
    t = acos(b_z) and r = atan2(b_x, b_y). The tilt is held at the knots' median (``branch`` -1: the other branch,
    -t with r + pi), the rotation follows each knot, unwrapped along the weld and shifted by whole turns to the
    middle of the rotate axis's range. None when the tilt or the rotation's sweep does not fit the limits."""
    b = curve.bisector_F
    t = float(np.median(np.arccos(np.clip(b[:, 2], -1.0, 1.0)))) * (1.0 if branch > 0 else -1.0)
    r = np.unwrap(np.arctan2(b[:, 0], b[:, 1]) + (0.0 if branch > 0 else math.pi))
    lo, hi = pos.rotate.q_min, pos.rotate.q_max
    r = r + 2.0 * math.pi * round((0.5 * (lo + hi) - 0.5 * (r.min() + r.max())) / (2.0 * math.pi))
    if not pos.tilt.contains(t) or r.min() < lo or r.max() > hi:
        return None
    return readonly(np.column_stack([np.full(len(r), t), r]))


def knots_in_R(pos: TiltRotatePositioner, curve: CurveInF, axes: npt.ArrayLike) -> tuple[FloatArray, ...]:
    """(p_R, t_R, n_a_R, n_b_R) (n, 3): each knot where the positioner puts it at its own axes ``axes`` (n, 2)."""
    A = np.asarray(axes, dtype=float)
    X = np.array([pos.X_R_F(t, r) for t, r in A])
    R, o = X[:, :3, :3], X[:, :3, 3]
    rot = lambda v: np.einsum("nij,nj->ni", R, np.asarray(v))  # noqa: E731
    return o + rot(curve.p_F), rot(curve.t_F), rot(curve.n_a_F), rot(curve.n_b_F)


def positions(
    pos: TiltRotatePositioner, curve: CurveInF, axes: npt.ArrayLike, target: str = "PA"
) -> tuple[FloatArray, FloatArray, bool]:
    """ISO 6947 slope and rotation [deg] (n,) of every knot at its axes, and whether every one is within the
    standard's tolerance of ``target`` (slope within 5 deg, rotation within 10 deg)."""
    from cell.positioner.iso6947 import ROTATION_TOL_DEG, SLOPE_TOL_DEG

    _, t_R, na_R, nb_R = knots_in_R(pos, curve, axes)
    up = pos.up_R
    sr = np.array([slope_rotation(t_R[i], na_R[i], nb_R[i], up) for i in range(len(t_R))])
    offs = np.array([off_nominal(target, s, r) for s, r in sr])
    within = bool(np.all(offs[:, 0] <= SLOPE_TOL_DEG) and np.all(offs[:, 1] <= ROTATION_TOL_DEG))
    return readonly(sr[:, 0]), readonly(sr[:, 1]), within
