"""A run's motion as a timeline, numpy only: what the arm did (or would do), subsampled, with its marks; and the
quaternions of rotation matrices that the Rerun recording (:mod:`cell.preview.rerun`) logs.

Values of the run only (its execution, else its plan and the move home before it). Time [s] is the execution's:
0 where the move home starts.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray

if TYPE_CHECKING:
    from cell.pipeline.records import WeldRun

Motion = tuple[FloatArray, FloatArray, npt.NDArray[np.bool_], tuple[tuple[float, str], ...]]


def quaternions_xyzw(R: npt.ArrayLike) -> FloatArray:
    """(n, 4) unit quaternions (x, y, z, w) of rotation matrices (n, 3, 3) (Shepperd's method)."""
    m = np.asarray(R, dtype=float).reshape(-1, 3, 3)
    tr = np.trace(m, axis1=1, axis2=2)
    d = np.stack([m[:, 0, 0], m[:, 1, 1], m[:, 2, 2], tr], axis=1)
    k = np.argmax(d, axis=1)
    q = np.empty((len(m), 4))
    for i in range(len(m)):
        a = m[i]
        if k[i] == 3:
            s = 2.0 * np.sqrt(1.0 + tr[i])
            q[i] = [(a[2, 1] - a[1, 2]) / s, (a[0, 2] - a[2, 0]) / s, (a[1, 0] - a[0, 1]) / s, 0.25 * s]
        else:
            j, n = (k[i] + 1) % 3, (k[i] + 2) % 3
            s = 2.0 * np.sqrt(max(1.0 + a[k[i], k[i]] - a[j, j] - a[n, n], 1e-12))
            v = np.empty(4)
            v[k[i]] = 0.25 * s
            v[j] = (a[j, k[i]] + a[k[i], j]) / s
            v[n] = (a[n, k[i]] + a[k[i], n]) / s
            v[3] = (a[n, j] - a[j, n]) / s
            q[i] = v
    q *= np.where(q[:, 3:4] < 0.0, -1.0, 1.0)
    return np.asarray(q / np.linalg.norm(q, axis=1, keepdims=True))


def motion(run: WeldRun) -> Motion | None:
    """The arm's motion on the recording's time axis: times (n,) [s], q (n, dof) [rad], arc (n,) and the marks
    (time, text); what the arm did when it moved, else the plan's (move from the scan pose home, then the
    program); None without a plan."""
    ex, plan, pre = run.execution, run.plan, run.pre_move
    if ex is not None:
        done = tuple((float(e.t), event_text(run, e.t, e.kind, e.detail)) for e in ex.events)
        return np.asarray(ex.times, dtype=float), np.asarray(ex.q, dtype=float), np.asarray(ex.arc_on), done
    if plan is None or not plan.segments:
        return None
    traj, arc = plan.joint_trajectory()
    t0 = pre.duration if pre is not None else 0.0
    times, q = traj.times + t0, np.asarray(traj.q)
    on = np.asarray(arc)
    if pre is not None:
        times = np.concatenate([pre.times, times[1:]])
        q = np.concatenate([pre.q, q[1:]])
        on = np.concatenate([np.zeros(len(pre.times), bool), on[1:]])
    marks: list[tuple[float, str]] = [(0.0, "move scan -> home")] if pre is not None else []
    for s in plan.segments:
        marks.append((t0 + s.t0, f"{s.kind} {s.seam_id}".strip()))
        if s.arc_on:
            marks += [(t0 + s.t0, f"arc_on {s.seam_id}"), (t0 + s.t1, f"arc_off {s.seam_id}")]
    return times, q, on, tuple(sorted(marks))


def event_text(run: WeldRun, t: float, kind: str, detail: str) -> str:
    """An execution event as a line of the log: a move mark as it is, an arc switch with its seam's id."""
    if kind == "move":
        return detail
    off = run.pre_move.duration if run.pre_move is not None else 0.0
    welds = [s for s in run.plan.segments if s.arc_on] if run.plan is not None else []
    seam = next((s.seam_id for s in welds if min(abs(off + s.t0 - t), abs(off + s.t1 - t)) < 0.02), "")
    return f"{kind} {seam} ({detail})" if seam else f"{kind} ({detail})"


def subsample(times: FloatArray, arc: npt.NDArray[np.bool_], rate_hz: float) -> npt.NDArray[np.intp]:
    """Indices of the samples kept: the first at or after every 1/rate_hz, every arc switch (both sides), the last."""
    grid = np.arange(times[0], times[-1], 1.0 / rate_hz)
    idx = np.searchsorted(times, grid - 1e-9)
    switch = np.flatnonzero(np.diff(arc.astype(np.int8)) != 0)
    return np.unique(np.clip(np.r_[idx, switch, switch + 1, len(times) - 1], 0, len(times) - 1))
