"""The welding program played seam by seam, as a cell controller runs it: each seam's motions (the move to it, its
passes, the depart) one after the other, its arc on and off written to the job's journal as they happen, a stop
signal held until the seam's weld ends (never a bead cut in the middle), and the pieces joined into one record."""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from cell.journal import deferred
from cell.journal.writer import SideLog
from cell.station import Station
from cell.types.execution import Event, Execution

if TYPE_CHECKING:
    from cell.pipeline.records import Detection
    from cell.scenario import Scenario
    from cell.types.execution import WeldQuality
    from cell.types.plan import WeldPlan
    from cell.types.trajectory import Trajectory

Measure = Callable[[str, Execution], "WeldQuality | None"]  # a seam's weld measured on the record so far


def play_by_seam(
    station: Station,
    times: np.ndarray,
    q: np.ndarray,
    arc_on: np.ndarray,
    marks: Sequence[tuple[float, str]],
    e1: np.ndarray | None,
    plan: WeldPlan,
    pre_s: float,
    log: SideLog,
    measure: Measure,
) -> Execution:
    """Play the side's program (times (n,) [s], q (n, dof) [rad], arc (n,), the plan's marks, the track's E1)
    one seam at a time, journaling ``arc_on`` before each seam's weld and ``arc_off`` after it (its times and the
    TCP error ``measure`` finds), and return the whole record, as one :meth:`Station.execute` of it would."""
    cuts = _cuts(times, arc_on, plan, pre_s)
    pieces: list[Execution] = []
    for i0, i1 in itertools.pairwise(cuts):
        t0, t1 = float(times[i0]), float(times[i1])
        last = i1 == len(times) - 1
        mine = [(t, m) for t, m in marks if t0 <= t < t1 or (last and t == t1)]
        welds = [s for s in plan.segments if s.arc_on and t0 <= pre_s + s.t0 < t1]
        seams = list(dict.fromkeys(s.seam_id for s in welds))
        sl = slice(i0, i1 + 1)
        with deferred():  # a stop signal waits for the end of this seam's weld
            for sid in seams:
                on = min(pre_s + s.t0 for s in welds if s.seam_id == sid)
                log.write("arc_on", seam=sid, t_s=round(on, 3))
            ex = station.execute(
                times[sl], q[sl], arc_on[sl], marks=mine, record_dt=0.01, e1=None if e1 is None else e1[sl]
            )
            pieces.append(ex)
            whole = _joined(pieces, float(times[-1] - times[0]))
            for sid in seams:
                log.write("arc_off", seam=sid, complete=True, **_arc_fields(ex, welds, sid, pre_s, whole, measure))
    return _joined(pieces, float(times[-1] - times[0]))


def _cuts(times: np.ndarray, arc_on: np.ndarray, plan: WeldPlan, pre_s: float) -> list[int]:
    """Sample indices where the program is cut: where each seam's motions begin (after the first seam), the arc
    off on both sides; the first and last sample."""
    cuts = [0]
    prev = None
    for s in plan.segments:
        if prev is not None and s.seam_id != prev:
            i = int(np.searchsorted(times, pre_s + s.t0))
            i = min(max(i, 1), len(times) - 2)
            if not arc_on[i - 1] and not arc_on[i] and i - cuts[-1] >= 2:
                cuts.append(i)
        prev = s.seam_id
    cuts.append(len(times) - 1)
    return cuts


def _arc_fields(
    ex: Execution, welds: Sequence[Any], sid: str, pre_s: float, whole: Execution, measure: Measure
) -> dict[str, Any]:
    """What ``arc_off`` says of one seam: the arc's first on and last off [s] in this piece, the bead's length,
    and the TCP error against the true seam (None where the truth is unknown)."""
    segs = [s for s in welds if s.seam_id == sid]
    lo, hi = pre_s + min(s.t0 for s in segs) - 1e-6, pre_s + max(s.t1 for s in segs) + 1e-6
    on = [e.t for e in ex.events if e.kind == "arc_on" and lo <= e.t <= hi]
    off = [e.t for e in ex.events if e.kind == "arc_off" and lo <= e.t <= hi]
    quality = measure(sid, whole)
    return {
        "t_on_s": round(min(on), 3) if on else None,
        "t_off_s": round(max(off), 3) if off else None,
        "tcp_rms_mm": round(quality.tcp_rms_mm, 4) if quality is not None else None,
        "tcp_max_mm": round(quality.tcp_max_mm, 4) if quality is not None else None,
        "length_mm": round(quality.length_mm, 2) if quality is not None else None,
    }


def _joined(pieces: Sequence[Execution], duration_s: float) -> Execution:
    """The pieces' records as one: each piece's first record (the previous one's last) and start mark dropped."""
    if len(pieces) == 1:
        return pieces[0]
    first = pieces[0]
    q_deg = np.round(np.degrees(first.q[0]), 2).tolist()
    start = Event(float(first.times[0]), "move", f"start at q = {q_deg} deg, {duration_s:.3f} s of motion")
    events = [start, *first.events[1:]]
    for p in pieces[1:]:
        events += list(p.events[1:])
    poses = [p.X_W_tcp for p in pieces if p.X_W_tcp is not None]
    return Execution(
        times=np.concatenate([first.times] + [p.times[1:] for p in pieces[1:]]),
        q=np.concatenate([first.q] + [p.q[1:] for p in pieces[1:]]),
        tcp_W=np.concatenate([first.tcp_W] + [p.tcp_W[1:] for p in pieces[1:]]),
        arc_on=np.concatenate([first.arc_on] + [p.arc_on[1:] for p in pieces[1:]]),
        events=tuple(sorted(events, key=lambda e: e.t)),
        X_W_tcp=np.concatenate([poses[0]] + [x[1:] for x in poses[1:]]) if len(poses) == len(pieces) else None,
    )


def log_detection(log: SideLog, det: Detection) -> None:
    """Journal what a side captured and located: the cameras lost, the alignment's fitness, each seam's status."""
    scene = det.scene
    log.write(
        "located",
        lost_cameras=list(det.lost_cameras),
        fitness=round(scene.alignment.fitness, 4) if scene is not None else None,
        X_RM=np.round(scene.X_RM, 6) if scene is not None else None,
        error=det.error.message if det.error is not None else None,
        seams=[
            {
                "id": e.id,
                "status": e.status.value,
                "reason_code": e.code.value if e.code is not None else None,
                "ends_mm": [np.round(e.p_start * 1000.0, 2), np.round(e.p_end * 1000.0, 2)] if e.p_start.size else None,
                "confidence": round(float(e.confidence), 4),
                "sigma_mm": round(float(e.sigma_m) * 1000.0, 4) if np.isfinite(e.sigma_m) else None,
            }
            for e in det.estimates
        ],
    )


def log_plan(log: SideLog, plan: WeldPlan) -> None:
    """Journal a side's checked plan: the seams in welding order, those the planner refused (with its code)."""
    log.write(
        "planned",
        order=list(dict.fromkeys(s.seam_id for s in plan.segments if s.arc_on)),
        refused={o.seam_id: str(o.code or o.reason) for o in plan.seams if not o.feasible},
        cycle_time_s=round(plan.cycle_time, 3),
    )


def measurer(det: Detection, plan: WeldPlan, pre: Trajectory, sc: Scenario) -> Measure:
    """How one seam's weld is measured on the record so far (as the run's own outcome measures it)."""
    from dataclasses import replace

    from cell.pipeline.outcomes import seam_welds

    by_id = {e.id: e for e in det.estimates}

    def measure(seam_id: str, ex: Execution) -> WeldQuality | None:
        est = by_id.get(seam_id)
        if est is None:  # a tack
            return None
        one = replace(det, estimates=(est,))
        return seam_welds(one, plan, ex, pre.duration, "", sc, False)[0].quality

    return measure
