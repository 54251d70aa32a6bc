"""A curved weld's planned path as a controller's moves: circular moves (KRL ``CIRC``, RAPID ``ArcC``) where the
path is a circle or an arc of one, each at most :data:`MAX_SWEEP_RAD` (a full circle and its overlap in several),
else straight chords (``LIN``, ``ArcL``) each within :data:`CHORD_TOL_M` of the path (docs/curves-welding.md
section 4). Values only: poses in R [m]."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.types.plan import Segment, WeldPlan
from cell.types.robot import Kinematics

CHORD_TOL_M = 0.0001  # [m] a chord's largest distance from the path it stands for
CIRCLE_TOL_M = 0.00005  # [m] a path is a circle when every knot lies this close to the fitted one
MAX_SWEEP_RAD = math.radians(90.0)  # one circular move's angle at most: the orientation follows closely


@dataclass(frozen=True)
class Move:
    """One motion of a curved weld: ``CIRC`` through X_aux (4, 4) to X_end, turning ``angle`` [rad] about the circle
    of ``centre`` (3,) and ``radius`` [m] (R); or ``LIN`` to X_end, within ``chord`` [m] of the path. q_end (dof,)
    [rad]: the planned joints at its end (for the controller's status and turn)."""

    kind: str
    X_end: FloatArray
    q_end: FloatArray
    X_aux: FloatArray | None = None
    angle: float = 0.0
    centre: FloatArray | None = None
    radius: float = 0.0
    chord: float = 0.0


def fit_circle(p: FloatArray) -> tuple[FloatArray, FloatArray, float, float]:
    """(centre (3,), unit normal (3,), radius [m], largest distance [m] of a point from the circle) of the circle
    best through points p (n, 3): their plane by SVD, then the algebraic (Kasa) circle in it."""
    c0 = p.mean(axis=0)
    _, _, Vt = np.linalg.svd(p - c0)
    e1, e2, n = Vt[0], Vt[1], Vt[2]
    u, v = (p - c0) @ e1, (p - c0) @ e2
    A = np.column_stack([u, v, np.ones(len(p))])
    (a, b, c), *_ = np.linalg.lstsq(A, u**2 + v**2, rcond=None)
    uc, vc = a / 2.0, b / 2.0
    r = math.sqrt(max(c + uc**2 + vc**2, 0.0))
    centre = c0 + uc * e1 + vc * e2
    d = p - centre
    h = d @ n
    radial = np.linalg.norm(d - np.outer(h, n), axis=1) - r
    return centre, n, r, float(np.max(np.hypot(radial, h)))


def swept(p: FloatArray, centre: FloatArray, normal: FloatArray) -> FloatArray:
    """(n,) the angle [rad] turned about the normal from p[0] to each point, unwrapped (signed)."""
    d = p - centre
    x = d[0] / np.linalg.norm(d[0])
    y = np.cross(normal, x)
    return np.asarray(np.unwrap(np.arctan2(d @ y, d @ x)))


def _q_at(seg: Segment, robot: Kinematics, p: FloatArray) -> FloatArray:
    """(dof,) the weld trajectory's joints where its TCP passes nearest p (3,) (every 10 ms, then refined; p in the
    arm's own base frame)."""
    tr = seg.trajectory
    step = max(1, len(tr.times) // max(1, int(tr.duration / 0.01)))
    idx = np.arange(0, len(tr.times), step)
    d = [float(np.linalg.norm(robot.fk(tr.q[i])[:3, 3] - p)) for i in idx]
    k = int(idx[int(np.argmin(d))])
    lo, hi = max(0, k - step), min(len(tr.times), k + step + 1)
    near = min(range(lo, hi), key=lambda i: float(np.linalg.norm(robot.fk(tr.q[i])[:3, 3] - p)))
    return np.asarray(tr.q[near])


def base_at(plan: WeldPlan, seg: Segment) -> FloatArray:
    """(3,) [m] in R: where the plan's linear track has the arm's base at the end of ``seg`` (zero without one)."""
    return np.zeros(3) if plan.track is None else np.asarray(plan.track.offset_R(seg.e1_end), dtype=float)


def curve_moves(seg: Segment, robot: Kinematics, base_R: npt.ArrayLike = (0.0, 0.0, 0.0)) -> list[Move]:
    """The moves of a curved weld segment (``seg.X_path``): circular moves when its path is a circle or an arc of
    one (within :data:`CIRCLE_TOL_M`), each through the path's middle knot between its ends; else the fewest
    chords each within :data:`CHORD_TOL_M` of every knot it passes. ``base_R`` (3,) [m]: where a linear track has
    the arm's base during the weld (its E1 times the axis), each move's joints found with it."""
    X = np.asarray(seg.X_path)
    p = X[:, :3, 3]
    p_arm = p - np.asarray(base_R, dtype=float)
    centre, n, r, err = fit_circle(p)
    out: list[Move] = []
    if err <= CIRCLE_TOL_M and r > 0.0:
        ang = swept(p, centre, n)
        total = float(abs(ang[-1]))
        k = max(1, math.ceil(total / MAX_SWEEP_RAD - 1e-9))
        cuts = [int(np.argmin(np.abs(np.abs(ang) - total * i / k))) for i in range(k + 1)]
        cuts[0], cuts[-1] = 0, len(X) - 1
        for a, b in itertools.pairwise(cuts):
            m = int(np.argmin(np.abs(np.abs(ang) - 0.5 * (abs(ang[a]) + abs(ang[b])))))
            q = seg.q_end if b == len(X) - 1 else _q_at(seg, robot, p_arm[b])
            out.append(Move("CIRC", X[b], q, X[m], float(abs(ang[b] - ang[a])), centre, r))
        return out
    i = 0
    while i < len(X) - 1:
        j = i + 1
        while j + 1 < len(X) and _chord_error(p, i, j + 1) <= CHORD_TOL_M:
            j += 1
        q = seg.q_end if j == len(X) - 1 else _q_at(seg, robot, p_arm[j])
        out.append(Move("LIN", X[j], q, chord=_chord_error(p, i, j)))
        i = j
    return out


def _chord_error(p: FloatArray, i: int, j: int) -> float:
    """The largest distance [m] of the knots p[i..j] from the chord p[i]-p[j]."""
    a, b = p[i], p[j]
    ab = b - a
    ll = float(ab @ ab)
    if j - i < 2 or ll <= 0.0:
        return 0.0
    t = np.clip((p[i + 1 : j] - a) @ ab / ll, 0.0, 1.0)
    return float(np.max(np.linalg.norm(p[i + 1 : j] - (a + t[:, None] * ab), axis=1)))


def circle_through(a: FloatArray, b: FloatArray, c: FloatArray) -> tuple[FloatArray, float, float] | None:
    """(centre (3,), radius, angle [rad] from a through b to c) of the circle through three points (any unit),
    or None when they are (nearly) on one line."""
    ab, ac = b - a, c - a
    n = np.cross(ab, ac)
    nn = float(n @ n)
    if nn < 1e-12 * float(ab @ ab) * float(ac @ ac) or nn == 0.0:
        return None
    centre = a + (np.cross(n, ab) * float(ac @ ac) + np.cross(ac, n) * float(ab @ ab)) / (2.0 * nn)
    r = float(np.linalg.norm(a - centre))
    axis = n / math.sqrt(nn)
    ang = swept(np.vstack([a, b, c]), centre, axis)  # about the normal of a -> b -> c: both turns positive
    return centre, r, float(ang[2] % (2.0 * math.pi))
