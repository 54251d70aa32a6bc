"""What the arm did: the record of a played joint trajectory, and how well a seam was welded by it.

Frames: ``W`` world. Units: metres, radians, seconds (millimetres where a name says ``_mm``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, readonly


class Event(NamedTuple):
    """One entry of an execution log: time [s], kind ``"move"`` | ``"arc_on"`` | ``"arc_off"``, free text."""

    t: float
    kind: str
    detail: str


@dataclass(frozen=True)
class Execution:
    """What the simulated arm did while playing back a joint trajectory.

    times : (n,) record times [s] (the trajectory's time axis: a grid of ``record_dt`` from its first time, every
        arc switch time, and its last time).
    q : (n, dof) joint values played at those times [rad], in the robot's joint order.
    tcp_W : (n, 3) position of the tool frame in W [m], from PyBullet's forward kinematics.
    arc_on : (n,) bool, the arc state holding from each record time to the next.
    events : time-ordered log of :class:`Event` (move marks, arc_on, arc_off).
    X_W_tcp : (n, 4, 4) full tool poses in W, or None when not recorded.
    """

    times: FloatArray
    q: FloatArray
    tcp_W: FloatArray
    arc_on: npt.NDArray[np.bool_]
    events: tuple[Event, ...]
    X_W_tcp: FloatArray | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "times", readonly(self.times))
        object.__setattr__(self, "q", readonly(self.q))
        object.__setattr__(self, "tcp_W", readonly(self.tcp_W))
        object.__setattr__(self, "arc_on", readonly(self.arc_on, np.bool_))
        if self.X_W_tcp is not None:
            object.__setattr__(self, "X_W_tcp", readonly(self.X_W_tcp))
        n = len(self.times)
        if self.tcp_W.shape != (n, 3) or self.arc_on.shape != (n,) or self.q.shape[0] != n:
            raise ValueError(f"Execution arrays must have one row per record time ({n})")

    @property
    def duration(self) -> float:
        """Robot time from the first to the last record [s]."""
        return float(self.times[-1] - self.times[0])

    @property
    def arc_time(self) -> float:
        """Time with the arc on [s]."""
        return float(np.sum(np.diff(self.times)[self.arc_on[:-1]]))

    @property
    def weld_length(self) -> float:
        """Length of the tool path travelled with the arc on [m]."""
        steps = np.linalg.norm(np.diff(self.tcp_W, axis=0), axis=1)
        return float(np.sum(steps[self.arc_on[:-1]]))


@dataclass(frozen=True)
class WeldQuality:
    """One seam's weld as executed.

    tcp_rms_mm, tcp_max_mm : distance of the tool centre point from the true seam segment while the arc burned (a
        point beyond an end counts its distance to that end).
    weld_time_s : arc time [s]; length_mm : length of the executed arc-on path.
    speed_mm_s : median TCP speed while the arc burned, ramps excluded (the constant-speed part).
    samples : number of recorded tool positions behind the figures.
    short_start_mm, short_end_mm : how much of the true joint the bead leaves unwelded at its start and its end
        (the true seam's ``p_start``, ``p_end``; >= 0), the arc-on records projected on the joint's line.
    past_start_mm, past_end_mm : how far the bead runs beyond the joint's start and end (>= 0).
    """

    tcp_rms_mm: float
    tcp_max_mm: float
    weld_time_s: float
    length_mm: float
    speed_mm_s: float
    samples: int
    short_start_mm: float = 0.0
    short_end_mm: float = 0.0
    past_start_mm: float = 0.0
    past_end_mm: float = 0.0

    @property
    def ends_mm(self) -> float:
        """The worst of the four end figures [mm]: how far the bead misses either end of the joint, either way."""
        return max(self.short_start_mm, self.short_end_mm, self.past_start_mm, self.past_end_mm)
