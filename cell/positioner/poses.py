"""The positioner's angles that bring a seam to the position asked, in closed form, and the seams grouped so the
positioner moves between groups, not per seam (docs/positioner.md, "Choosing the part's pose").

A seam's position depends only on where the world's up points in the faceplate frame F. For the tilt-rotate
kinematics (:class:`~cell.types.positioner.TiltRotatePositioner`) that is u_F = (sin t sin r, sin t cos r, cos t):
any u_F whose angle from the faceplate's axis is a reachable tilt is one pose, twice over ((t, r) and (-t, r + pi),
the second the first turned half a turn about the vertical). For a weld of direction d and centreline b (made
across d), the up-vectors that put it at slope 0 with its centreline at elevation e are
u = sin(e) b + cos(e) (+-(d x b)): PA (e = 90 deg) one, PB (e = 45 deg) two. Frames: F at home is where the
located seams are carried from; angles [rad].
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray
from cell.positioner.iso6947 import weld_position
from cell.types.positioner import TiltRotatePositioner, WeldPosition, wrap_near

ELEVATION_DEG = {"PA": 90.0, "PB": 45.0}  # the centreline's elevation each downhand position asks


@dataclass(frozen=True)
class SeamFrame:
    """One seam's geometry in the faceplate frame F at home: waypoints' directions ``d_F`` and faces' outward
    normals ``n_a_F``, ``n_b_F`` (n, 3), its points ``p_F`` (n, 3) [m], and the position asked (``PA``/``PB``)."""

    id: str
    d_F: FloatArray
    n_a_F: FloatArray
    n_b_F: FloatArray
    p_F: FloatArray
    target: str = "PB"


@dataclass(frozen=True)
class PositionerPose:
    """One group: the axes (tilt, rotate) [rad], the seams welded there in order, and each one's position."""

    tilt: float
    rotate: float
    seams: tuple[str, ...]
    positions: Mapping[str, WeldPosition]


Reach = Callable[[TiltRotatePositioner, float, float, SeamFrame], bool]  # (positioner, t, r, seam) -> reachable


def up_candidates(seam: SeamFrame) -> list[FloatArray]:
    """The up-vectors in F (unit, (3,)) that put the seam's mean waypoint in its position asked (slope 0; PA one,
    PB two)."""
    d = np.mean(seam.d_F, axis=0)
    d = d / np.linalg.norm(d)
    b = np.mean(seam.n_a_F + seam.n_b_F, axis=0)
    b = b - (b @ d) * d
    b = b / np.linalg.norm(b)
    w = np.cross(d, b)
    e = math.radians(ELEVATION_DEG[seam.target])
    if seam.target == "PA":
        return [b]
    return [math.sin(e) * b + math.cos(e) * w, math.sin(e) * b - math.cos(e) * w]


def axes_for_up(pos: TiltRotatePositioner, u_F: FloatArray, rotate_ref: float = 0.0) -> list[tuple[float, float]]:
    """Every (tilt, rotate) [rad] within the axes' limits that points the world's up along ``u_F`` (3,) in F:
    t = +-acos(u_z), r = atan2(u_x, u_y) (+ pi for the negative tilt), the rotate axis's whole turns nearest
    ``rotate_ref``. At t = 0 the rotation is free: ``rotate_ref`` kept."""
    u = np.asarray(u_F, dtype=float) / np.linalg.norm(u_F)
    t = math.acos(float(np.clip(u[2], -1.0, 1.0)))
    if math.sin(t) < 1e-9:
        options = [(t, rotate_ref)]
    else:
        r = math.atan2(float(u[0]), float(u[1]))
        options = [(t, r), (-t, r + math.pi)]
    out = []
    for ti, ri in options:
        ri = wrap_near(ri, rotate_ref)
        for k in (0, -1, 1):  # a whole turn the other way when the nearest is beyond a limit
            rk = ri + 2.0 * math.pi * k
            if pos.within(ti, rk):
                out.append((ti, rk))
                break
    return out


def tilt_reachable(pos: TiltRotatePositioner, u_F: FloatArray, margin_rad: float = 1e-3) -> FloatArray:
    """The up-vector ``u_F`` (3,) turned towards the faceplate's axis until its tilt is within the tilt axis's
    limits (``margin_rad`` inside them); itself when it already is. A position just beyond the limits (PA on a
    face against the faceplate asks 135 deg) is then reached as nearly as the axis allows: whether that is within
    ISO 6947's tolerance is :func:`position_at`'s to say."""
    u = np.asarray(u_F, dtype=float) / np.linalg.norm(u_F)
    limit = max(abs(pos.tilt.q_min), abs(pos.tilt.q_max)) - margin_rad
    t = math.acos(float(np.clip(u[2], -1.0, 1.0)))
    if t <= limit or math.hypot(u[0], u[1]) < 1e-9:
        return u
    side = np.array([u[0], u[1], 0.0]) / math.hypot(u[0], u[1])
    return np.asarray(math.cos(limit) * np.array([0.0, 0.0, 1.0]) + math.sin(limit) * side, dtype=float)


def position_at(pos: TiltRotatePositioner, tilt: float, rotate: float, seam: SeamFrame) -> WeldPosition:
    """The seam's worst waypoint's position with the positioner at (tilt, rotate) [rad]."""
    return weld_position(seam.d_F, seam.n_a_F, seam.n_b_F, pos.up_F(tilt, rotate), seam.target)


def plan_poses(
    pos: TiltRotatePositioner,
    seams: Sequence[SeamFrame],
    reach: Reach,
    excluded: Collection[tuple[str, tuple[float, float]]] = (),
    start: tuple[float, float] | None = None,
) -> tuple[tuple[PositionerPose, ...], dict[str, str]]:
    """The groups: greedy cover of the seams by candidate poses (each seam's closed-form poses, both tilt branches),
    each pose taking every seam it holds within ISO 6947's tolerance and ``reach`` accepts; the pose covering most
    seams first (ties: the home pose, then the smaller tilt, then the smaller rotation move from the last pose).
    Returns the poses in welding order and, per seam no pose holds, why (``unreachable`` or
    ``beyond tilt``). excluded : (seam id, pose) pairs the planner refused (a collision, IK): left out. start : where
    the axes stand (default home); the poses are then ordered from there, nearest move first."""
    home = pos.home
    cands: list[tuple[float, float]] = [home]
    why: dict[str, str] = {}
    for s in seams:
        found = [a for u in up_candidates(s) for a in axes_for_up(pos, u, home[1])]
        if not found:  # just beyond the tilt: as near as the axis reaches, when that is within the tolerance
            near = [a for u in up_candidates(s) for a in axes_for_up(pos, tilt_reachable(pos, u), home[1])]
            found = [a for a in near if position_at(pos, a[0], a[1], s).within]
        if not found:
            why[s.id] = "beyond tilt: the position asks a tilt outside the tilt axis's limits"
        cands.extend(found)
    holds: dict[tuple[float, float], dict[str, WeldPosition]] = {}
    for c in cands:
        if c in holds:
            continue
        at = {s.id: position_at(pos, c[0], c[1], s) for s in seams}
        holds[c] = {
            i: p
            for i, p in at.items()
            if p.within and (i, c) not in excluded and reach(pos, c[0], c[1], _by_id(seams, i))
        }
    left = {s.id for s in seams}
    order: list[PositionerPose] = []
    last = home
    while left:
        best = max(
            holds,
            key=lambda c: (len(left & set(holds[c])), c == home, -abs(c[0]), -abs(c[1] - last[1])),
        )
        got = [s.id for s in seams if s.id in left and s.id in holds[best]]
        if not got:
            break
        order.append(PositionerPose(best[0], best[1], tuple(got), {i: holds[best][i] for i in got}))
        left -= set(got)
        last = best
    for i in sorted(left):
        why.setdefault(i, "unreachable: no pose that holds it in position is within the arm's reach")
    return _nearest_first(order, start or home), why


def _nearest_first(poses: list[PositionerPose], start: tuple[float, float]) -> tuple[PositionerPose, ...]:
    """The poses ordered by the nearest next move from ``start`` (the larger of the two axes' travels)."""
    out, here, left = [], start, list(poses)
    while left:
        nxt = min(left, key=lambda p: max(abs(p.tilt - here[0]), abs(p.rotate - here[1])))
        out.append(nxt)
        left.remove(nxt)
        here = (nxt.tilt, nxt.rotate)
    return tuple(out)


def _by_id(seams: Sequence[SeamFrame], sid: str) -> SeamFrame:
    return next(s for s in seams if s.id == sid)


def shoulder_reach(centre_R: FloatArray, radius_m: float, min_facing: float = -0.2) -> Reach:
    """A reach test without IK: every waypoint of the seam, carried to (tilt, rotate), within ``radius_m`` of the
    arm's shoulder ``centre_R`` (3,) (:meth:`cell.motion.robot.RobotModel.reach_bound`), and the weld's centreline
    facing the arm (its cosine to the shoulder's direction at least ``min_facing``: a seam on the far side of the
    part, its bead looking away, is left for the other tilt branch)."""
    c = np.asarray(centre_R, dtype=float)

    def reach(pos: TiltRotatePositioner, tilt: float, rotate: float, seam: SeamFrame) -> bool:
        X = pos.X_R_F(tilt, rotate)
        p_R = seam.p_F @ X[:3, :3].T + X[:3, 3]
        if not np.all(np.linalg.norm(p_R - c, axis=1) <= radius_m):
            return False
        b_R = (seam.n_a_F + seam.n_b_F) @ X[:3, :3].T
        to_arm = c - p_R
        cos = np.sum(b_R * to_arm, axis=1) / (np.linalg.norm(b_R, axis=1) * np.linalg.norm(to_arm, axis=1))
        return bool(np.all(cos >= min_facing))

    return reach
