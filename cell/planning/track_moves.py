"""The moves between the groups of a plan on a linear track: the arm and the carriage together, one jerk-limited PTP
over A1..A6 and E1 (straight in the seven axes, Ruckig with the arm's and the track's limits, all axes arriving
together, as a KRC drives a PTP with a coupled external axis), from the last depart of one group to the first
approach of the next; checked with the base where E1 puts it at every sample. Where that collides the arm goes home
while the carriage moves (or comes from home while it moves), and only where both collide does the arm wait at home
for the carriage, as before (docs/track.md, "Planning"). Joints [rad]; E1 [m]; time [s]; frames: R."""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from cell.config.motion import GateOptions, PlanOptions
from cell.errors import IKError, TimingError
from cell.geometry import FloatArray, readonly
from cell.motion.collision import CollisionChecker
from cell.motion.collision.wire import body_entry
from cell.motion.ik import solve_ik
from cell.motion.limits import JointLimits
from cell.motion.robot import RobotModel
from cell.motion.timing import ptp
from cell.types import Part
from cell.types.plan import Segment
from cell.types.track import LinearTrack
from cell.types.trajectory import Trajectory

_BODY_STEP = 0.001  # [m] TCP travel between the body tests of a move (the gate tests it again, finer)


def arm_and_track(limits: JointLimits, track: LinearTrack) -> JointLimits:
    """The arm's limits with the track's E1 as a seventh axis."""
    return JointLimits(
        (*limits.names, "E1"),
        np.append(limits.q_min, track.e1_min),
        np.append(limits.q_max, track.e1_max),
        np.append(limits.v_max, track.v_max),
        np.append(limits.a_max, track.a_max),
        np.append(limits.j_max, track.j_max),
    )


@dataclass(frozen=True)
class GroupLegs:
    """One group's motions planned with its base at E1 ``e1`` [m] (no E1 in them yet): from home to its first
    approach (``head``), its welds and the moves between them (``inner``), from its last depart home (``tail``)."""

    e1: float
    head: tuple[Segment, ...]
    inner: tuple[Segment, ...]
    tail: tuple[Segment, ...]

    @classmethod
    def split(cls, e1: float, segments: Sequence[Segment]) -> GroupLegs:
        """A group plan's segments (home to home) cut before its first approach and after its last depart."""
        lines = [k for k, s in enumerate(segments) if s.kind != "move"]
        a, b = lines[0], lines[-1] + 1
        return cls(e1, tuple(segments[:a]), tuple(segments[a:b]), tuple(segments[b:]))

    @property
    def q_in(self) -> FloatArray:
        return self.inner[0].trajectory.q[0]

    @property
    def q_out(self) -> FloatArray:
        return self.inner[-1].q_end


class TrackMoves:
    """The moves between groups for one arm (its base at R), track, scene and wire (see the module docstring)."""

    def __init__(
        self,
        robot: RobotModel,
        track: LinearTrack,
        checker: CollisionChecker,
        obstacles: Sequence[Part],
        wire_m: float,
        q_home: FloatArray,
        options: PlanOptions,
        rises: Sequence[float] = (0.05, 0.15),
    ) -> None:
        self.robot, self.track, self.checker, self.obstacles = robot, track, checker, tuple(obstacles)
        self.wire_m, self.q_home, self.dt, self.ik = wire_m, np.asarray(q_home, dtype=float), options.dt, options.ik
        self.rises = tuple(rises)  # [m] via points this far above the highest obstacle, lowest first
        self.top = max((float(np.max(o.vertices()[:, 2])) for o in self.obstacles), default=0.0)
        self.limits = arm_and_track(robot.limits, track)
        self._depth = GateOptions().body_depth

    def move(self, q_a: FloatArray, e_a: float, q_b: FloatArray, e_b: float) -> Trajectory:
        """The arm and the carriage from (q_a, e_a) to (q_b, e_b) together, rest to rest; TimingError when it
        cannot be timed."""
        tr = ptp(np.append(q_a, e_a), np.append(q_b, e_b), self.limits, dt=self.dt)
        dof = self.robot.dof
        e1 = tr.q[:, dof].copy()
        e1[-1] = e_b
        return Trajectory(tr.times, tr.q[:, :dof], tr.qd[:, :dof], tr.qdd[:, :dof], e1)

    def free(self, tr: Trajectory) -> bool:
        """Whether a move (E1 in it) touches nothing and takes the wire into no obstacle's body, with the base
        where E1 puts it at every sample."""
        if self.checker.check_trajectory(tr, self.track) is not None:
            return False
        track = self.track

        def offset(t: FloatArray) -> FloatArray:
            return np.stack([track.offset_R(float(e)) for e in tr.e1_at(t)])

        hit = body_entry(
            self.robot, tr, self.obstacles, wire_m=self.wire_m, depth=self._depth, step=_BODY_STEP, offset=offset
        )
        return hit is None

    def tcp(self, q: FloatArray) -> FloatArray:
        """The TCP (3,) [m] in R of a configuration over the arm's axes and E1 (dof + 1,)."""
        return np.asarray((self.track.X_R_Re(float(q[-1])) @ self.robot.fk(q[:-1]))[:3, 3])

    def segment(self, tr: Trajectory, seam_id: str, t0: float) -> Segment:
        """A move (E1 in it) as a plan segment of kind ``move`` for ``seam_id`` ("" for the way home)."""
        e = float(np.asarray(tr.e1)[-1])
        X_end = self.track.X_R_Re(e) @ self.robot.fk(tr.q[-1])
        return Segment("move", seam_id, tr, t0, readonly(X_end))

    def between(self, a: GroupLegs | None, b: GroupLegs | None) -> tuple[bool, bool, list[Trajectory]]:
        """From group a's last depart (None: home at E1 = 0) to group b's first approach (None: home at E1 = 0):
        (whether a's way home is taken, whether b's way from home is, the moves with E1 between them): the arm
        and the carriage together straight there; else the arm home while the carriage moves, or from home while
        it moves; else the carriage alone with the arm at home."""
        home, e_a, e_b = self.q_home, a.e1 if a else 0.0, b.e1 if b else 0.0
        q_a, q_b = (a.q_out if a else home), (b.q_in if b else home)
        if np.array_equal(q_a, q_b) and e_a == e_b:
            return False, False, []
        lifted = self.lifted(q_a, e_a, q_b, e_b)
        if lifted is not None:
            return False, False, lifted
        tries = [(False, True, q_a, home), (True, False, home, q_b), (True, True, home, home)]
        for tail, head, q_from, q_to in tries:
            if (tail and a is None) or (head and b is None):
                continue  # home is where that end already is: another try covers it
            try:
                tr = self.move(q_from, e_a, q_to, e_b)
            except TimingError:
                continue
            if (tail and head) or self.free(tr):  # the arm at home while the carriage moves: as it always was
                return tail, head, [tr]
        raise TimingError(f"no move of the track from E1 = {e_a * 1000:.0f} mm to {e_b * 1000:.0f} mm")

    def lifted(self, q_a: FloatArray, e_a: float, q_b: FloatArray, e_b: float) -> list[Trajectory] | None:
        """The arm and the carriage together straight from (q_a, e_a) to (q_b, e_b); else the arm up to a via
        point above its TCP at each of ``rises`` over the highest obstacle, together to the one above q_b's
        TCP, down: the first whose moves are all free (None: none is)."""
        try:
            direct = self.move(q_a, e_a, q_b, e_b)
        except TimingError:
            direct = None
        if direct is not None and self.free(direct):
            return [direct]
        for rise in self.rises:
            try:
                up_a, up_b = self._above(q_a, e_a, self.top + rise), self._above(q_b, e_b, self.top + rise)
                moves = [
                    ptp(q_a, up_a, self.robot.limits, dt=self.dt).with_e1(e_a),
                    self.move(up_a, e_a, up_b, e_b),
                    ptp(up_b, q_b, self.robot.limits, dt=self.dt).with_e1(e_b),
                ]
            except (IKError, TimingError):
                continue
            if all(self.free(tr) for tr in moves):
                return moves
        return None

    def _above(self, q: FloatArray, e1: float, height: float) -> FloatArray:
        """q (dof,) [rad] with its TCP (the base at E1 = e1 [m]) raised to ``height`` [m] in R; IKError when it
        cannot be reached."""
        arm = self.robot.shifted(self.track.offset_R(e1)) if e1 else self.robot
        X = arm.fk(q)
        X[2, 3] = max(height, float(X[2, 3]))
        return np.asarray(solve_ik(arm, X, q, options=self.ik))


def stitched(
    moves: TrackMoves, groups: Sequence[GroupLegs], blend: Callable[[GroupLegs, list[Segment]], list[Segment]]
) -> list[Segment]:
    """Every group's motions with its E1, the moves between them (:meth:`TrackMoves.between`, from home at E1 = 0
    to the first group, on to the next, back home at E1 = 0), back to back from t = 0. ``blend`` approximates a
    group's own segments (its way from or to home among them where taken) with its base where it stands."""
    ends: list[GroupLegs | None] = [None, *groups, None]
    ways = [moves.between(a, b) for a, b in itertools.pairwise(ends)]
    out: list[Segment] = []
    t = 0.0

    def add(seg: Segment) -> None:
        nonlocal t
        out.append(replace(seg, t0=t))
        t += seg.trajectory.duration

    for k, (_, _, trs) in enumerate(ways):
        to = groups[k].inner[0].seam_id if k < len(groups) else ""
        for tr in trs:
            add(moves.segment(tr, to, t))
        if k == len(groups):
            break
        g = groups[k]
        own = [*(g.head if ways[k][1] else ()), *g.inner, *(g.tail if ways[k + 1][0] else ())]
        for seg in blend(g, own):
            add(replace(seg, trajectory=seg.trajectory.with_e1(g.e1)))
    return out
