"""Timed motions as values (numpy only): a joint :class:`Trajectory` and a path :class:`PathProfile`, sampled
between their stored samples by quintic Hermite interpolation. Made by :mod:`cell.motion.timing` (Ruckig).

Units: joints [rad], [rad/s], [rad/s^2]; path length [m], [m/s], [m/s^2]; time [s].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, readonly


def hermite5(
    times: FloatArray, x: FloatArray, xd: FloatArray, xdd: FloatArray, t: npt.ArrayLike
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Quintic Hermite interpolation of samples (n, d) at times t (m,): values, rates, second rates (m, d).

    It matches position, velocity and acceleration at every sample, so it is exact on any interval where the
    motion is a polynomial of degree <= 5 (a jerk-limited profile between its switching times).
    t is clamped to [times[0], times[-1]].
    """
    ts: FloatArray = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), times[0], times[-1])
    if len(times) == 1:
        m = len(ts)
        return np.repeat(x[:1], m, 0), np.repeat(xd[:1], m, 0), np.repeat(xdd[:1], m, 0)
    k = np.clip(np.searchsorted(times, ts, side="right") - 1, 0, len(times) - 2)
    h = (times[k + 1] - times[k])[:, None]
    tau = (ts - times[k])[:, None] / h
    p0, p1, v0, v1, a0, a1 = x[k], x[k + 1], xd[k] * h, xd[k + 1] * h, xdd[k] * h * h, xdd[k + 1] * h * h
    dp = p1 - p0
    c3 = 10.0 * dp - 6.0 * v0 - 4.0 * v1 - (3.0 * a0 - a1) / 2.0
    c4 = -15.0 * dp + 8.0 * v0 + 7.0 * v1 + (3.0 * a0 - 2.0 * a1) / 2.0
    c5 = 6.0 * dp - 3.0 * (v0 + v1) - (a0 - a1) / 2.0
    c2 = a0 / 2.0
    pos = p0 + tau * (v0 + tau * (c2 + tau * (c3 + tau * (c4 + tau * c5))))
    vel = (v0 + tau * (2.0 * c2 + tau * (3.0 * c3 + tau * (4.0 * c4 + tau * 5.0 * c5)))) / h
    acc = (2.0 * c2 + tau * (6.0 * c3 + tau * (12.0 * c4 + tau * 20.0 * c5))) / (h * h)
    return pos, vel, acc


def check_samples(times: FloatArray, *arrays: FloatArray) -> None:
    """ValueError unless times (n,) start at 0 and increase strictly and every array is finite with n rows."""
    if times.ndim != 1 or len(times) == 0 or times[0] != 0.0 or np.any(np.diff(times) <= 0.0):
        raise ValueError("trajectory times must be (n,) with n >= 1, start at 0 and increase strictly")
    shape = arrays[0].shape
    if any(a.shape != shape or a.shape[0] != len(times) or not np.all(np.isfinite(a)) for a in arrays):
        raise ValueError(f"trajectory samples must be finite, one row per time ({len(times)}), all of one shape")


@dataclass(frozen=True)
class Trajectory:
    """A timed joint trajectory sampled at a fixed period (the last interval may be shorter).

    times : (n,) [s], from 0 to ``duration``; q : (n, dof) [rad]; qd : (n, dof) [rad/s]; qdd : (n, dof)
    [rad/s^2]. e1 : (n,) [m] the linear track's external axis E1 at each sample (:mod:`cell.types.track`), None
    for an arm without a track (E1 = 0 throughout).
    """

    times: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    e1: FloatArray | None = None

    def __post_init__(self) -> None:
        for key in ("times", "q", "qd", "qdd"):
            object.__setattr__(self, key, readonly(getattr(self, key)))
        check_samples(self.times, self.q, self.qd, self.qdd)
        if self.q.ndim != 2:
            raise ValueError(f"Trajectory q must be (n, dof), got {self.q.shape}")
        if self.e1 is not None:
            e1 = readonly(self.e1)
            if e1.shape != self.times.shape or not np.all(np.isfinite(e1)):
                raise ValueError(f"Trajectory e1 must be ({len(self.times)},) finite values [m], got {e1.shape}")
            object.__setattr__(self, "e1", e1)

    @property
    def duration(self) -> float:
        return float(self.times[-1])

    @property
    def dof(self) -> int:
        return int(self.q.shape[1])

    def sample(self, t: float | npt.ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """(q, qd, qdd) at t [s], clamped to [0, duration]: (dof,) each for a scalar t, (m, dof) for t (m,).

        Between samples this is a quintic Hermite interpolation: exact where no profile switch falls inside
        the sample interval, within O(j_max dt^3) elsewhere (tests/test_timing.py bounds it).
        """
        q, qd, qdd = hermite5(self.times, self.q, self.qd, self.qdd, t)
        if np.ndim(t) == 0:
            return q[0], qd[0], qdd[0]
        return q, qd, qdd

    def e1_at(self, t: npt.ArrayLike) -> FloatArray:
        """E1 [m] at times t [s] (clamped), shaped like t: linear between samples (a track move is sampled every
        few ms), 0 without a track."""
        ts = np.asarray(t, dtype=float)
        if self.e1 is None:
            return np.zeros(ts.shape)
        return np.asarray(np.interp(ts, self.times, self.e1), dtype=float)

    def with_e1(self, e1: float | npt.ArrayLike) -> Trajectory:
        """The same motion with E1 [m] at every sample: a constant, or (n,) values."""
        arr = np.broadcast_to(np.asarray(e1, dtype=float), self.times.shape).copy()
        return Trajectory(self.times, self.q, self.qd, self.qdd, arr)


@dataclass(frozen=True)
class PathProfile:
    """Timing of a path parameter s(t): the arc length travelled along a seam.

    times : (n,) [s]; s : (n,) [m] from 0 to ``length``; sd : (n,) [m/s]; sdd : (n,) [m/s^2].
    """

    times: FloatArray
    s: FloatArray
    sd: FloatArray
    sdd: FloatArray

    def __post_init__(self) -> None:
        for key in ("times", "s", "sd", "sdd"):
            object.__setattr__(self, key, readonly(getattr(self, key)))
        check_samples(self.times, self.s, self.sd, self.sdd)

    @property
    def duration(self) -> float:
        return float(self.times[-1])

    @property
    def length(self) -> float:
        return float(self.s[-1])

    def at(self, t: float | npt.ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """(s, sd, sdd) at times t [s] (clamped to [0, duration]), each shaped like t."""
        s, sd, sdd = hermite5(self.times, self.s[:, None], self.sd[:, None], self.sdd[:, None], t)
        shape = np.shape(t)
        return s.reshape(shape), sd.reshape(shape), sdd.reshape(shape)

    def __call__(self, t: float | npt.ArrayLike) -> FloatArray:
        """s(t) [m]."""
        return self.at(t)[0]
