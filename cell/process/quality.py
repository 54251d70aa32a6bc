"""How well a seam was welded: the executed tool path against the true seam (how far it strays from the joint, and
how much of the joint it leaves unwelded or overruns at each end), and the travel speed along it."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.types.execution import WeldQuality

_MM = 1000.0


def distance_to_segment(p: npt.ArrayLike, a: npt.ArrayLike, b: npt.ArrayLike) -> FloatArray:
    """Distance [m] of points p (n, 3) from the segment a-b (3,)."""
    p = np.asarray(p, dtype=float)
    a = np.asarray(a, dtype=float)
    ab = np.asarray(b, dtype=float) - a
    t = np.clip(((p - a) @ ab) / float(ab @ ab), 0.0, 1.0)
    return np.asarray(np.linalg.norm(p - (a + t[:, None] * ab), axis=1))


def end_coverage(p: npt.ArrayLike, a: npt.ArrayLike, b: npt.ArrayLike) -> tuple[float, float, float, float]:
    """How a bead along points p (n, 3) covers the joint a-b (3,) [m]: (short_start, short_end, past_start,
    past_end) [m], each >= 0.

    The points are projected on the joint's line (whatever way the bead ran): short is how much of the joint at
    that end the bead leaves unwelded, past how far it runs beyond that end (one of the two is 0 at each end).
    """
    p = np.asarray(p, dtype=float).reshape(-1, 3)
    a = np.asarray(a, dtype=float)
    ab = np.asarray(b, dtype=float) - a
    length = float(np.linalg.norm(ab))
    s = (p - a) @ (ab / length)
    lo, hi = float(s.min()), float(s.max())
    return max(lo, 0.0), max(length - hi, 0.0), max(-lo, 0.0), max(hi - length, 0.0)


def weld_quality(
    times: npt.ArrayLike,
    tcp_R: npt.ArrayLike,
    truth_start: npt.ArrayLike,
    truth_end: npt.ArrayLike,
    offsets_R: npt.ArrayLike | None = None,
) -> WeldQuality:
    """Quality of one weld (one pass) from the records taken while its arc burned.

    times : (n,) record times [s]; tcp_R : (n, 3) tool positions in R [m] (n >= 2); truth : the true seam in R [m].
    offsets_R : (n, 3) [m] where the plan meant each record to lie off the seam (the pass's offset and the weave,
        :func:`cell.process.weave.intended_offsets`); the TCP error and the travel speed are measured on the
        records minus these (against the seam plus the intended weave and offset), the length on the path as
        driven. None: on the seam line.

    The TCP error is each record's distance to the true segment (a record beyond an end counts its distance to
    that end); the ends' coverage (:func:`end_coverage`) is of the records minus the offsets too.
    """
    t = np.asarray(times, dtype=float)
    raw = np.asarray(tcp_R, dtype=float)
    p = raw if offsets_R is None else raw - np.asarray(offsets_R, dtype=float)
    if len(t) < 2:
        raise ValueError("a weld needs at least two tool records")
    d = distance_to_segment(p, truth_start, truth_end) * _MM
    short_start, short_end, past_start, past_end = end_coverage(p, truth_start, truth_end)
    driven = float(np.linalg.norm(np.diff(raw, axis=0), axis=1).sum())
    return quality_figures(t, p, d, (short_start, short_end, past_start, past_end), driven)


def continuous(t: FloatArray) -> npt.NDArray[np.bool_]:
    """Which steps between records at times t (n,) [s] are of one weld (n - 1,): all but those that last more than
    ten times the median step (the air between two arcs of a seam welded in pieces)."""
    dt = np.diff(np.asarray(t, dtype=float))
    return dt <= 10.0 * float(np.median(dt)) if dt.size else np.zeros(0, dtype=bool)


def quality_figures(
    t: FloatArray, p: FloatArray, d_mm: FloatArray, ends_m: tuple[float, float, float, float], length_m: float
) -> WeldQuality:
    """The figures of one weld from its records at times t (n,) [s]: the TCP error d_mm (n,) [mm] (RMS and max),
    the travel speed along p (n, 3) [m] (the median over the records above half the top speed, between records
    that follow each other: :func:`continuous`), the length driven [m] and the ends' (short start, short end, past
    start, past end) [m]."""
    step = np.linalg.norm(np.diff(p, axis=0), axis=1)
    dt = np.diff(t)
    keep = continuous(t)  # not the air between two arcs of one seam: its jump is no travel speed
    step, dt = step[keep], dt[keep]
    speed = np.divide(step, dt, out=np.zeros_like(step), where=dt > 0) * _MM
    cruise = speed[speed > 0.5 * speed.max()] if speed.size and speed.max() > 0 else speed
    short_start, short_end, past_start, past_end = ends_m
    return WeldQuality(
        tcp_rms_mm=float(np.sqrt(np.mean(d_mm**2))),
        tcp_max_mm=float(d_mm.max()),
        weld_time_s=float(t[-1] - t[0]),
        length_mm=length_m * _MM,
        speed_mm_s=float(np.median(cruise)) if cruise.size else 0.0,
        samples=len(t),
        short_start_mm=short_start * _MM,
        short_end_mm=short_end * _MM,
        past_start_mm=past_start * _MM,
        past_end_mm=past_end * _MM,
    )


def combined(passes: Sequence[WeldQuality]) -> WeldQuality:
    """All passes of one seam as one figure: the TCP error over every record (RMS weighted by samples, the
    largest), the arc time and driven length summed, the first pass's travel speed, and at each end the worst
    pass's shortfall and overrun."""
    if not passes:
        raise ValueError("a weld needs at least one pass")
    n = sum(q.samples for q in passes)
    return WeldQuality(
        tcp_rms_mm=float(np.sqrt(sum(q.tcp_rms_mm**2 * q.samples for q in passes) / n)),
        tcp_max_mm=max(q.tcp_max_mm for q in passes),
        weld_time_s=sum(q.weld_time_s for q in passes),
        length_mm=sum(q.length_mm for q in passes),
        speed_mm_s=passes[0].speed_mm_s,
        samples=n,
        short_start_mm=max(q.short_start_mm for q in passes),
        short_end_mm=max(q.short_end_mm for q in passes),
        past_start_mm=max(q.past_start_mm for q in passes),
        past_end_mm=max(q.past_end_mm for q in passes),
    )
