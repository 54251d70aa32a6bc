"""What the simulated arm did while playing back a joint trajectory, as a record (numpy only): the trajectory checked,
sampled at the record times, the tool pose read there and the arc switches logged. Frame W; metres, radians, seconds."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.types.execution import Event


def _check_trajectory(
    times: npt.ArrayLike, q: npt.ArrayLike, arc_on: npt.ArrayLike, dof: int
) -> tuple[FloatArray, FloatArray, npt.NDArray[np.bool_]]:
    t = np.asarray(times, dtype=float)
    qa = np.asarray(q, dtype=float)
    arc = np.asarray(arc_on)
    if t.ndim != 1 or len(t) == 0 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0.0):
        raise ValueError("execute: times must be (n,) finite, n >= 1, strictly increasing [s]")
    if qa.shape != (len(t), dof) or not np.all(np.isfinite(qa)):
        raise ValueError(f"execute: q must be ({len(t)}, {dof}) finite joint values [rad], got {qa.shape}")
    if arc.shape != (len(t),) or arc.dtype != np.bool_:
        raise ValueError(f"execute: arc_on must be ({len(t)},) bool, got {arc.shape} {arc.dtype}")
    return t, qa, arc


def _record_times(times: FloatArray, arc_on: npt.NDArray[np.bool_], record_dt: float) -> FloatArray:
    """A grid of ``record_dt`` over [times[0], times[-1]], plus the arc switch times and the end, sorted."""
    if not record_dt > 0.0:
        raise ValueError(f"execute: record_dt must be positive [s], got {record_dt}")
    t0, t1 = float(times[0]), float(times[-1])
    grid = t0 + np.arange(int(np.floor((t1 - t0) / record_dt + 1e-9)) + 1) * record_dt
    switches = times[1:][arc_on[1:] != arc_on[:-1]]
    out = np.unique(np.concatenate([grid[grid < t1], switches, [t1]]))
    # drop grid points closer than a microsecond to a switch time (keep the exact switch)
    keep = np.ones(len(out), bool)
    keep[1:] = np.diff(out) > 1e-6
    keep[np.isin(out, switches)] = True
    return out[keep]


def _interp_rows(t: FloatArray, times: FloatArray, values: FloatArray) -> FloatArray:
    """Piecewise-linear interpolation of samples (n, d) at times t (m,): (m, d)."""
    return np.column_stack([np.interp(t, times, values[:, j]) for j in range(values.shape[1])])


def _events(
    t: FloatArray,
    q: FloatArray,
    tcp_W: FloatArray,
    arc_on: npt.NDArray[np.bool_],
    marks: Sequence[tuple[float, str]],
) -> tuple[Event, ...]:
    """The log: a move mark at the start (and the caller's marks), arc_on/arc_off at every switch."""
    q_deg = np.round(np.degrees(q[0]), 2).tolist()
    log = [Event(float(t[0]), "move", f"start at q = {q_deg} deg, {t[-1] - t[0]:.3f} s of motion")]
    log += [Event(float(tm), "move", str(text)) for tm, text in marks]
    for k in range(len(t)):
        was = bool(arc_on[k - 1]) if k > 0 else False
        if bool(arc_on[k]) != was:
            kind = "arc_on" if arc_on[k] else "arc_off"
            log.append(Event(float(t[k]), kind, f"tcp at {np.round(tcp_W[k] * 1000.0, 1).tolist()} mm in W"))
    if arc_on[-1]:  # the arc is never left burning past the end of a trajectory
        log.append(Event(float(t[-1]), "arc_off", "end of trajectory"))
    log.sort(key=lambda e: e.t)  # stable: the start mark stays first
    return tuple(log)
