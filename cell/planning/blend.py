"""Approximate positioning of the arc-off motions (KRL ``C_DIS``, RAPID zones): between two welds the depart, the
transfer's moves and the approach run without stopping at the points between them. As a controller blends, the arm
leaves a motion before its end (where the TCP is the zone's distance from the programmed point) and joins the next
one after its start, by the time-optimal jerk-limited move between the two moving states (Ruckig); the rest of
each motion is as planned, the arc stays at exact stops (docs/cycle.md). Joints [rad]; time [s]; TCP [m] in R."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from cell.errors import TimingError
from cell.geometry import FloatArray, readonly
from cell.motion.limits import JointLimits
from cell.motion.timing import connect
from cell.types.plan import Segment
from cell.types.trajectory import Trajectory

# The cuts tried at a point, longest first, as fractions of the longest cut of each motion (before, after), down to a
# sixteenth, three quarters and three eighths between the halvings: where a link collides, the cut into one motion is
# shortened before the other's (the collision is usually near one of them)
_CUTS = tuple(
    sorted(
        (
            (x, y)
            for x in (1.0, 0.75, 0.5, 0.375, 0.25, 0.125, 0.0625)
            for y in (1.0, 0.75, 0.5, 0.375, 0.25, 0.125, 0.0625)
        ),
        key=lambda c: (-(c[0] + c[1]), -min(c)),
    )
)
_MIN_CUT = 0.02  # [s] a motion cut shorter than this at a point: an exact stop there


class _Blend(NamedTuple):
    """At one point: motion k - 1 left ``exit_s`` [s] into it, motion k joined ``entry_s`` [s] into it, by
    ``link`` (the move between the two states)."""

    exit_s: float
    entry_s: float
    link: Trajectory


def blend_plan(
    segments: Sequence[Segment],
    limits: JointLimits,
    tcp: Callable[[FloatArray], FloatArray],
    clear: Callable[[Trajectory], bool],
    *,
    fraction: float = 0.5,
    dt: float = 0.001,
) -> list[Segment]:
    """The plan's segments with every run of arc-off motions blended (welds, their starts and ends untouched).

    fraction [0, 0.5]: at most this fraction of each of two neighbouring motions is cut at their point, and no more
    of a motion than its previous blend left (so half of an approach at least stays the straight line it was, and a
    motion blended at both ends keeps at least its middle). At each point the cuts are shortened (each to a half,
    a quarter ... of its longest, one motion's before both, the longest pair first) until the link is faster than
    the two cut pieces and ``clear`` (the collision and body tests) passes for it, else the point is an exact stop.
    tcp : q (dof,) -> the TCP (3,) in R, for the zones. Segments come back to back, times renumbered from the first
    one's start.
    """
    if not 0.0 <= fraction <= 0.5:
        raise ValueError(f"blend fraction must be within [0, 0.5], got {fraction}")
    return _each_run(
        segments,
        lambda seg: not seg.arc_on and seg.trajectory.e1 is None,
        lambda run: _blend_run(run, limits, tcp, clear, fraction, dt),
    )


def _each_run(
    segments: Sequence[Segment], joins: Callable[[Segment], bool], blend: Callable[[list[Segment]], list[Segment]]
) -> list[Segment]:
    """``segments`` with every run of two or more consecutive ones that ``joins`` takes put through ``blend``,
    back to back, times renumbered from the first one's start."""
    out: list[Segment] = []
    run: list[Segment] = []
    for seg in [*segments, None]:
        if seg is not None and joins(seg):
            run.append(seg)
            continue
        out += blend(run) if len(run) > 1 else run
        run = []
        if seg is not None:
            out.append(seg)
    t = segments[0].t0 if segments else 0.0
    timed = []
    for seg in out:
        timed.append(replace(seg, t0=t))
        t += seg.trajectory.duration
    return timed


def _blend_at(
    a: Trajectory,
    b: Trajectory,
    entry_min: float,
    exit_max: float,
    lim: JointLimits,
    clear: Callable[[Trajectory], bool],
    fraction: float,
    dt: float,
) -> _Blend | None:
    """The blend between motions a and b (None: an exact stop): a left no earlier than ``entry_min`` [s] into it
    (where the previous blend joined it), b joined no later than ``exit_max`` [s] (where the next may leave)."""
    # a's cut ends where the previous blend joined it (a motion blended at both ends keeps at least its middle)
    max_a, max_b = min(fraction * a.duration, a.duration - entry_min - 2.0 * dt), fraction * b.duration
    for scale_a, scale_b in _CUTS:
        cut_a, cut_b = scale_a * max_a, scale_b * max_b
        if min(cut_a, cut_b) < _MIN_CUT:
            continue
        exit_s = float(np.floor((a.duration - cut_a) / dt + 1e-9) * dt)  # on a's sample grid
        entry_s = float(np.ceil(cut_b / dt - 1e-9) * dt)  # on b's
        if exit_s > entry_min + dt and entry_s < exit_max - dt:
            try:
                link = connect(a.sample(exit_s), b.sample(entry_s), lim, dt=dt)
            except TimingError:
                link = None
            if link is not None and link.duration < (a.duration - exit_s) + entry_s - dt and clear(link):
                return _Blend(exit_s, entry_s, link)
    return None


def _piece(tr: Trajectory, t_from: float, t_to: float) -> tuple[FloatArray, ...]:
    """tr's own samples from t_from to t_to [s] (both on its grid, or its ends)."""
    keep = (tr.times >= t_from - 1e-9) & (tr.times <= t_to + 1e-9)
    return tr.times[keep] - t_from, tr.q[keep], tr.qd[keep], tr.qdd[keep]


def _joined(parts: Sequence[tuple[FloatArray, ...]]) -> Trajectory:
    """Sampled pieces back to back (each starts at the last one's final state: its first sample dropped)."""
    t0 = 0.0
    cols: list[list[FloatArray]] = [[], [], [], []]
    for k, (t, q, qd, qdd) in enumerate(parts):
        skip = int(k > 0)
        for col, arr in zip(cols, (t + t0, q, qd, qdd), strict=True):
            col.append(arr[skip:])
        t0 += float(t[-1])
    return Trajectory(*(np.concatenate(c) for c in cols))


def _blend_run(
    segs: list[Segment],
    lim: JointLimits,
    tcp: Callable[[FloatArray], FloatArray],
    clear: Callable[[Trajectory], bool],
    fraction: float,
    dt: float,
) -> list[Segment]:
    """One run of arc-off motions blended at each point between them, each motion's segment from where it is
    joined to where it is left."""
    blends: list[_Blend | None] = [None]
    for k in range(1, len(segs)):
        a, b = segs[k - 1].trajectory, segs[k].trajectory
        prev = blends[k - 1]
        entry_min = prev.entry_s if prev is not None else 0.0
        blends.append(_blend_at(a, b, entry_min, b.duration, lim, clear, fraction, dt))
    blends.append(None)
    if not any(blends):
        return segs
    out = []
    for k, seg in enumerate(segs):
        tr = seg.trajectory
        into, out_of = blends[k], blends[k + 1]
        start = into.entry_s if into is not None else 0.0
        end = out_of.exit_s if out_of is not None else tr.duration
        parts = [_piece(into.link, 0.0, into.link.duration)] if into is not None else []
        parts.append(_piece(tr, start, end))
        new = replace(seg, trajectory=_joined(parts), link_s=into.link.duration if into is not None else 0.0)
        if out_of is not None:
            target = np.asarray(tr.q[-1], dtype=float)
            zone = float(np.linalg.norm(tcp(new.trajectory.q[-1]) - tcp(target)))
            new = replace(new, zone_m=zone, q_target=readonly(target))
        out.append(new)
    return out


def blend_track(
    segments: Sequence[Segment],
    limits: JointLimits,
    tcp: Callable[[FloatArray], FloatArray],
    clear: Callable[[Trajectory], bool],
    *,
    fraction: float = 0.5,
    dt: float = 0.001,
) -> list[Segment]:
    """The plan's segments (each with E1) with every run of arc-off motions in which the track moves blended, the
    arm's axes and E1 together, at the points between them not blended yet (the rules of :func:`blend_plan`).

    limits : the arm's and E1's (dof + 1 axes); tcp : (dof + 1,) -> the TCP (3,) in R; clear : a motion with E1 ->
    whether it is free. Segments come back to back, times renumbered from the first one's start."""

    def blend(run: list[Segment]) -> list[Segment]:
        moves = any(float(np.ptp(s.trajectory.e1)) > 0.0 for s in run if s.trajectory.e1 is not None)
        return _track_run(run, limits, tcp, clear, fraction, dt) if moves else run

    return _each_run(segments, lambda seg: not seg.arc_on, blend)


def _with_e1(tr: Trajectory) -> Trajectory:
    """A motion with E1 as one trajectory over the arm's axes and E1 (E1's rates from its samples)."""
    e1 = np.zeros(len(tr.times)) if tr.e1 is None else np.asarray(tr.e1, dtype=float)
    if len(tr.times) > 2 and float(np.ptp(e1)) > 0.0:
        e1d = np.gradient(e1, tr.times)
        e1d[[0, -1]] = 0.0
        e1dd = np.gradient(e1d, tr.times)
    else:
        e1d = e1dd = np.zeros_like(e1)
    return Trajectory(tr.times, np.c_[tr.q, e1], np.c_[tr.qd, e1d], np.c_[tr.qdd, e1dd])


def _split_e1(tr: Trajectory) -> Trajectory:
    return Trajectory(tr.times, tr.q[:, :-1], tr.qd[:, :-1], tr.qdd[:, :-1], tr.q[:, -1])


def _track_run(
    segs: list[Segment],
    lim: JointLimits,
    tcp: Callable[[FloatArray], FloatArray],
    clear: Callable[[Trajectory], bool],
    fraction: float,
    dt: float,
) -> list[Segment]:
    """One run blended over the arm's axes and E1 at each point not blended yet (a motion joined or left there
    already keeps its blend)."""
    views = [_with_e1(s.trajectory) for s in segs]
    blends: list[_Blend | None] = [None]
    for k in range(1, len(segs)):
        if segs[k].link_s > 0.0 or segs[k - 1].zone_m > 0.0:
            blends.append(None)
            continue
        prev = blends[k - 1]
        entry_min = prev.entry_s if prev is not None else segs[k - 1].link_s
        blends.append(
            _blend_at(
                views[k - 1], views[k], entry_min, views[k].duration, lim, lambda x: clear(_split_e1(x)), fraction, dt
            )
        )
    blends.append(None)
    if not any(blends):
        return segs
    out = []
    for k, seg in enumerate(segs):
        tr, into, out_of = views[k], blends[k], blends[k + 1]
        if into is None and out_of is None:
            out.append(seg)
            continue
        start = into.entry_s if into is not None else 0.0
        end = out_of.exit_s if out_of is not None else tr.duration
        parts = [_piece(into.link, 0.0, into.link.duration)] if into is not None else []
        parts.append(_piece(tr, start, end))
        joined = _joined(parts)
        new = replace(seg, trajectory=_split_e1(joined), link_s=into.link.duration if into is not None else seg.link_s)
        if out_of is not None:
            target = np.asarray(tr.q[-1], dtype=float)
            zone = float(np.linalg.norm(tcp(joined.q[-1]) - tcp(target)))
            new = replace(new, zone_m=zone, q_target=readonly(target[:-1]), e1_target=float(target[-1]))
        out.append(new)
    return out
