"""Close-up views of a seam for the eye-in-hand camera: where to put the camera, and the arm's move there; candidate
views ranked, then checked cheapest first (geometry, IK, collisions); :class:`NoViewError` when none passes
(docs/planning.md section 7). Everything in the robot frame R [m]."""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from dataclasses import replace
from enum import StrEnum
from itertools import chain

import numpy as np
import numpy.typing as npt

from cell.errors import IKError, PlanError, TimingError
from cell.geometry import FloatArray
from cell.motion.collision import CollisionChecker
from cell.motion.ik import IKOptions, solve_ik
from cell.motion.robot import RobotModel
from cell.motion.timing import Trajectory, ptp
from cell.rescan.view_grid import (
    ViewCandidate,
    ViewOptions,
    ViewTarget,
    ranked_views,
    segments_hit_box,
    torch_axis_in_camera,
    view_candidates,
)
from cell.types import CameraIntrinsics, Part
from cell.types.rescan import Viewpoint

_segments_hit_box = segments_hit_box  # the name tests/unit/test_rescan.py imports from here


class ViewRejection(StrEnum):
    """Why a geometrically acceptable candidate view was rejected (the value is the message's words)."""

    UNREACHABLE = "unreachable"
    COLLIDES_AT_VIEW = "collides at the view"
    NO_TIMED_MOVE = "no timed move"
    MOVE_COLLIDES = "move collides"
    MOVE_COLLIDES_VIA = "move collides (also through the scan pose)"


class NoViewError(PlanError):
    """No close-up view of ``seam_id`` works: ``tried`` candidates got IK and collision checks, ``rejected``
    counts why each failed (``tried == 0``: none passed the geometric tests, see :func:`view_candidates`)."""

    def __init__(
        self, message: str, *, seam_id: str, tried: int = 0, rejected: Mapping[ViewRejection, int] | None = None
    ) -> None:
        super().__init__(message)
        self.seam_id = seam_id
        self.tried = tried
        self.rejected = dict(rejected or {})


def plan_view(
    model: RobotModel,
    checker: CollisionChecker,
    target: ViewTarget,
    q_from: npt.ArrayLike,
    intrinsics: CameraIntrinsics,
    parts: Sequence[Part],
    table_z: float,
    *,
    rng: np.random.Generator,
    q_via: npt.ArrayLike | None = None,
    options: ViewOptions | None = None,
    max_candidates: int = 60,
    restart_candidates: int = 8,
) -> Viewpoint:
    """The first candidate view of ``target`` (see the module docstring) that the arm reaches without collision
    from q_from (dof,) [rad], directly or through q_via; PlanError naming the seam and why when there is none.

    The ``max_candidates`` best-scored geometric candidates get warm-started IK (from q_from, then q_via) and
    collision checks; if none passes, the ``restart_candidates`` best get IK with random restarts from ``rng``.
    """
    o = options or ViewOptions()
    q0 = np.asarray(q_from, dtype=float)
    torch_C = torch_axis_in_camera(model, o)
    ranked = ranked_views(target, intrinsics, torch_C, parts, table_z, o)  # lazily: the first that works ends it
    best = next(ranked, None)
    grid, tried_fallback = o, best is None and bool(o.fallback_tilts_deg)
    if tried_fallback:  # between tall parts only a narrow, grazing cone sees it: the fallback grid (ViewOptions)
        o = replace(
            grid,
            tilts_deg=o.fallback_tilts_deg,
            max_incidence_deg=o.fallback_max_incidence_deg,
            face_strip_m=o.fallback_face_strip_m,
        )
        ranked = ranked_views(target, intrinsics, torch_C, parts, table_z, o)
        best = next(ranked, None)
    if best is None:
        grazing = f", nor a grazing one (<= {o.max_incidence_deg:g} deg, {o.face_strip_m * 1000:g} mm strips)"
        raise NoViewError(
            f"seam {target.id}: no close-up view sees the seam and both faces (in the image, clear of the "
            f"torch, incidence <= {grid.max_incidence_deg:g} deg, unoccluded) at {list(o.distances_m)} m"
            f"{grazing if tried_fallback else ''}",
            seam_id=target.id,
        )
    why: dict[ViewRejection, int] = {}
    seeds = [q0] if q_via is None else [q0, np.asarray(q_via, dtype=float)]
    tried = 0
    first = _Prefix(chain([best], ranked))
    # Pass 1: warm-started IK only (cheap), on the best max_candidates; pass 2: random restarts on the best few.
    for pass_, top in ((1, max_candidates), (2, restart_candidates)):
        for c in first.upto(top):
            tried += 1
            q = _ik(model, c.X_RC, seeds, o.camera_frame, rng if pass_ == 2 else None, o.ik)
            if q is None:
                why[ViewRejection.UNREACHABLE] = why.get(ViewRejection.UNREACHABLE, 0) + 1
                continue
            if checker.check(q) is not None:
                why[ViewRejection.COLLIDES_AT_VIEW] = why.get(ViewRejection.COLLIDES_AT_VIEW, 0) + 1
                continue
            moved = _move(model, checker, q0, q, q_via, o.dt)
            if isinstance(moved, ViewRejection):
                why[moved] = why.get(moved, 0) + 1
                continue
            move, via = moved
            X_RC = model.fk(q, o.camera_frame)
            dist = float(np.linalg.norm(X_RC[:3, 3] - target.mid))
            return Viewpoint(target.id, X_RC, q, move, dist, c.incidence, c.tilt, c.slant, c.roll, tried, via)
    summary = ", ".join(f"{n} {r}" for r, n in why.items())
    raise NoViewError(
        f"seam {target.id}: none of {tried} close-up views works ({summary})",
        seam_id=target.id,
        tried=tried,
        rejected=why,
    )


class _Prefix:
    """The candidates of an iterator read as far as asked and kept, so a second pass reads the same ones again."""

    def __init__(self, source: Iterator[ViewCandidate]) -> None:
        self._source, self._seen = source, list[ViewCandidate]()

    def upto(self, n: int) -> Iterator[ViewCandidate]:
        """The first ``n`` candidates (fewer when the source ends), read lazily."""
        k = 0
        while k < n:
            if k == len(self._seen):
                nxt = next(self._source, None)
                if nxt is None:
                    return
                self._seen.append(nxt)
            yield self._seen[k]
            k += 1


def _ik(
    model: RobotModel,
    X_RC: FloatArray,
    seeds: Sequence[FloatArray],
    frame: str,
    rng: np.random.Generator | None,
    ik: IKOptions,
) -> FloatArray | None:
    """Joint values for the camera pose from the first seed that converges (with restarts when ``rng`` is
    given), or None: an unreachable candidate is an expected outcome here, not an error."""
    for seed in seeds:
        try:
            return np.asarray(solve_ik(model, X_RC, seed, frame=frame, rng=rng, options=ik), dtype=float)
        except IKError:
            if rng is not None:
                return None  # the restarts do not depend on the seed: one round is enough
    return None


def _move(
    model: RobotModel,
    checker: CollisionChecker,
    q0: FloatArray,
    q1: FloatArray,
    q_via: npt.ArrayLike | None,
    dt: float,
) -> tuple[Trajectory, bool] | ViewRejection:
    """A collision-free ptp move q0 -> q1, else q0 -> q_via -> q1, and whether it goes through q_via; why not when
    neither is free."""
    try:
        direct = ptp(q0, q1, model.limits, dt=dt)
    except TimingError:
        return ViewRejection.NO_TIMED_MOVE
    if checker.check_path(direct.q, direct.times) is None:
        return direct, False
    if q_via is None:
        return ViewRejection.MOVE_COLLIDES
    qv = np.asarray(q_via, dtype=float)
    try:
        legs = [ptp(q0, qv, model.limits, dt=dt), ptp(qv, q1, model.limits, dt=dt)]
    except TimingError:
        return ViewRejection.NO_TIMED_MOVE
    if any(checker.check_path(leg.q, leg.times) is not None for leg in legs):
        return ViewRejection.MOVE_COLLIDES_VIA
    return concatenate(legs), True


def way_back(
    model: RobotModel, checker: CollisionChecker, stops: Sequence[FloatArray], q_home: FloatArray, dt: float
) -> Trajectory | None:
    """A collision-free move from the last of ``stops`` to ``q_home``: straight there (a ptp) from the latest stop
    that way is free from, after going back stop by stop along the straight joint lines the arm came by; None when
    no stop has a free way home (or a leg back is not free: the arm did not come that way).

    stops : (dof,) [rad] configurations the arm reached one after the other by rest-to-rest ptp moves, the first
    where it started."""
    legs: list[Trajectory] = []
    for k in range(len(stops) - 1, -1, -1):
        try:
            home = ptp(stops[k], q_home, model.limits, dt=dt)
        except TimingError:
            return None
        if checker.check_path(home.q, home.times) is None:
            return concatenate([*legs, home])
        if k == 0:
            return None
        try:
            leg = ptp(stops[k], stops[k - 1], model.limits, dt=dt)
        except TimingError:
            return None
        if checker.check_path(leg.q, leg.times) is not None:
            return None
        legs.append(leg)
    return None


def concatenate(moves: Sequence[Trajectory]) -> Trajectory:
    """Rest-to-rest moves played one after the other, as one trajectory (each starts where the last ended)."""
    times, q, qd, qdd = [moves[0].times], [moves[0].q], [moves[0].qd], [moves[0].qdd]
    t0 = moves[0].duration
    for m in moves[1:]:
        times.append(m.times[1:] + t0)
        q.append(m.q[1:])
        qd.append(m.qd[1:])
        qdd.append(m.qdd[1:])
        t0 += m.duration
    return Trajectory(np.concatenate(times), np.concatenate(q), np.concatenate(qd), np.concatenate(qdd))


__all__ = [
    "NoViewError",
    "ViewCandidate",
    "ViewOptions",
    "ViewRejection",
    "ViewTarget",
    "Viewpoint",
    "concatenate",
    "plan_view",
    "segments_hit_box",
    "torch_axis_in_camera",
    "view_candidates",
    "way_back",
]
