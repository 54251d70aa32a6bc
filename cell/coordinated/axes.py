"""The positioner's axes along a curved seam that keep each point of it in PA (its fillet's bisector straight up)
where the torch stands: the rotate axis turning with the weld, the tilt held where the seam's bisector keeps its
angle to the faceplate's axis and following it where it does not (docs/positioner.md, "Coordinated
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


TILT_HELD_DEG = 1.0  # the knots' tilts spread at most this much: one tilt held, their median (a pipe on its plate)
TILT_SMOOTH_M = 0.005  # [m] the following tilt smoothed along the seam (a local line, Gaussian weights of this sigma)


def knot_tilt_rotate(b_F: npt.ArrayLike, branch: int = 1) -> FloatArray:
    """(n, 2) (tilt, rotate) [rad] that put each unit bisector b (n, 3) in F straight up: t = acos(b_z),
    r = atan2(b_x, b_y) (``branch`` -1 at the first knot: -t, r + pi), each later knot on the branch nearer its
    predecessor's axes (a bisector passing the faceplate's axis changes branch rather than jump half a turn),
    the rotation unwrapped along the seam."""
    b = np.asarray(b_F, dtype=float)
    t = np.arccos(np.clip(b[:, 2], -1.0, 1.0))
    r = np.arctan2(b[:, 0], b[:, 1])
    out = np.empty((len(b), 2))
    out[0] = (t[0], r[0]) if branch > 0 else (-t[0], r[0] + math.pi)
    for i in range(1, len(b)):
        prev = out[i - 1]
        best = None
        for cand in ((t[i], r[i]), (-t[i], r[i] + math.pi)):
            rr = cand[1] + 2.0 * math.pi * round((prev[1] - cand[1]) / (2.0 * math.pi))
            d = abs(cand[0] - prev[0]) + abs(math.sin(prev[0])) * abs(rr - prev[1])
            if best is None or d < best[0]:
                best = (d, cand[0], rr)
        assert best is not None
        out[i] = best[1:]
    return out


def _smooth(v: FloatArray, s: FloatArray, sigma: float) -> FloatArray:
    """v (n,) along s (n,) [m] (increasing): at each knot the value of the line fitted to its neighbours within
    4 ``sigma`` with Gaussian weights of ``sigma`` [m] (a linear trend kept, also at the ends)."""
    lo, hi = np.searchsorted(s, s - 4.0 * sigma), np.searchsorted(s, s + 4.0 * sigma, side="right")
    out = np.empty(len(v))
    for i in range(len(v)):
        d = s[lo[i] : hi[i]] - s[i]
        w = np.exp(-0.5 * (d / sigma) ** 2)
        s0, s1, s2 = w.sum(), w @ d, w @ (d * d)
        t0, t1 = w @ v[lo[i] : hi[i]], (w * d) @ v[lo[i] : hi[i]]
        out[i] = (s2 * t0 - s1 * t1) / max(s0 * s2 - s1 * s1, 1e-300)
    return out


def pa_axes(pos: TiltRotatePositioner, curve: CurveInF, branch: int = 1) -> FloatArray | None:
    """(n, 2) (tilt, rotate) [rad] putting each knot's bisector straight up (:func:`knot_tilt_rotate`).

    Where the knots' tilts spread less than ``TILT_HELD_DEG`` the tilt is held at their median (a pipe square
    on its plate: only the rotate axis moves); else it follows the seam, smoothed (``TILT_SMOOTH_M``): an
    ellipse of a leaning tube, a saddle. The rotation follows each knot, shifted by whole turns to the middle of
    the rotate axis's range. None when a tilt or the rotation's sweep does not fit the limits."""
    tr = knot_tilt_rotate(curve.bisector_F, branch)
    t, r = tr[:, 0], tr[:, 1]
    if np.ptp(t) <= math.radians(TILT_HELD_DEG):
        t = np.full(len(t), float(np.median(t)))
    elif len(t) > 2:
        t = _smooth(t, np.asarray(curve.s), TILT_SMOOTH_M)
    lo, hi = pos.rotate.q_min, pos.rotate.q_max
    r = r + 2.0 * math.pi * round((0.5 * (lo + hi) - 0.5 * (r.min() + r.max())) / (2.0 * math.pi))
    tilt = pos.tilt
    if t.min() < tilt.q_min - 1e-9 or t.max() > tilt.q_max + 1e-9 or r.min() < lo or r.max() > hi:
        return None
    return readonly(np.column_stack([t, r]))


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
