"""The timed motions a transfer is made of, put back to back, and why a transfer found no free way
(:mod:`cell.planning.transfers`). Frames: the robot base frame R [m]; joints [rad]; time [s]."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from cell.geometry import FloatArray
from cell.motion.timing import Trajectory
from cell.types.plan import SegmentKind


class Piece(NamedTuple):
    """One timed motion before it gets its place in the plan: kind, trajectory, TCP speed [m/s] (0: PTP) and
    the TCP pose X_end (4, 4) in R at its end."""

    kind: SegmentKind
    trajectory: Trajectory
    speed: float
    X_end: FloatArray


@dataclass(frozen=True)
class TransferFail:
    """No free way: why (the last strategy's contact or error) and the contact point p_R (3,) [m] in R."""

    reason: str
    p_R: FloatArray


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
