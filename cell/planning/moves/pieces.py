"""The timed motions a transfer is made of, put back to back, and why a transfer found no free way
(:mod:`cell.planning.transfers`). Frames: the robot base frame R [m]; joints [rad]; time [s]."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import NamedTuple

import numpy as np

from cell.geometry import FloatArray
from cell.motion.robot import RobotModel
from cell.motion.timing import Trajectory
from cell.motion.wrist import HoseWindow
from cell.types.plan import SegmentKind


class Piece(NamedTuple):
    """One timed motion before it gets its place in the plan: kind, trajectory, TCP speed [m/s] (0: PTP) and
    the TCP pose X_end (4, 4) in R at its end."""

    kind: SegmentKind
    trajectory: Trajectory
    speed: float
    X_end: FloatArray


class TransferFail:
    """No free way: why (the last strategy's contact or error) and the contact point p_R (3,) [m] in R. A failure
    made by :meth:`deferred` finds both when first asked: placing it takes full collision checks, and the order
    search reads few of the failures it meets (docs/positioner.md, "Planning time")."""

    __slots__ = ("_place", "_placed")

    def __init__(self, reason: str, p_R: FloatArray) -> None:
        self._placed: tuple[str, FloatArray] | None = (reason, p_R)
        self._place: Callable[[], TransferFail] | None = None

    @classmethod
    def deferred(cls, place: Callable[[], TransferFail]) -> TransferFail:
        """The failure ``place()`` gives, asked once, when its reason or place is first read."""
        fail = cls.__new__(cls)
        fail._placed, fail._place = None, place
        return fail

    @property
    def reason(self) -> str:
        return self._found()[0]

    @property
    def p_R(self) -> FloatArray:
        return self._found()[1]

    def _found(self) -> tuple[str, FloatArray]:
        if self._placed is None:
            assert self._place is not None
            got = self._place()
            self._placed, self._place = (got.reason, got.p_R), None
        return self._placed

    def __repr__(self) -> str:
        return f"TransferFail({self.reason!r}, {self.p_R!r})"


def joined(pieces: Sequence[Piece]) -> Trajectory:
    """One trajectory of timed motions put back to back (each starts where the last ended, at rest)."""
    times, q, qd, qdd, t0 = [], [], [], [], 0.0
    for k, pc in enumerate(pieces):
        tr, skip = pc.trajectory, int(k > 0)  # a piece's first sample is the last one's final sample
        times.append(tr.times[skip:] + t0)
        q.append(tr.q[skip:])
        qd.append(tr.qd[skip:])
        qdd.append(tr.qdd[skip:])
        t0 += tr.duration
    return Trajectory(np.concatenate(times), np.concatenate(q), np.concatenate(qd), np.concatenate(qdd))


def out_of_window(
    robot: RobotModel, window: HoseWindow, pieces: Sequence[Piece], q_a: FloatArray, q_b: FloatArray
) -> TransferFail | None:
    """Why a transfer's motions take A6 further out of the hose ``window`` than their ends q_a, q_b (dof,) [rad] are
    (None: they do not), with the TCP p_R (3,) [m] where it is furthest out."""
    allowed = max(window.excess(q_a), window.excess(q_b)) + 1e-9
    q = np.concatenate([pc.trajectory.q for pc in pieces])
    over = np.abs(q[:, -1] - window.center) - window.half_width
    k = int(np.argmax(over))
    if over[k] <= allowed:
        return None
    why = (
        f"A6 leaves the hose package window ({np.degrees(window.center):.0f} +- {np.degrees(window.half_width):.0f}"
        f" deg) by {np.degrees(over[k]):.1f} deg"
    )
    return TransferFail(why, robot.fk(q[k])[:3, 3].copy())
