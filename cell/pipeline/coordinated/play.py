"""A coordinated weld played in the simulator: at every record the arm at its joints and the positioner's axes
turned (the part, the clamping table and the faceplate carried, the clamping error riding on them; the bodies
moved each time an axis has turned ``BODY_STEP_RAD``, the part's pose at every record from the same motion), the
torch's tip recorded and the bead laid where the tip is on the part (it turns with it); then measured against the
true curve in the part's own frame (the tip carried back by the part's true motion from home). Frames: W the world,
R the robot base; [m], [s]."""

from __future__ import annotations

import math

import numpy as np

from cell.coordinated.record import CoordinatedWeld
from cell.geometry import FloatArray, invert
from cell.station.sim import SimStation
from cell.types.execution import Event, Execution, WeldQuality

RECORD_DT = 0.01  # [s] between records, as the arm's own playback
BODY_STEP_RAD = math.radians(0.25)  # the part's bodies moved when an axis has turned this far (0.5 mm at 0.11 m)


def play(station: SimStation, cw: CoordinatedWeld, record_dt: float = RECORD_DT) -> tuple[Execution, FloatArray]:
    """Drive the arm and the positioner together along ``cw``; returns the execution (TCP in W) and each record's
    tip carried back to where the part stood at the scan (n, 3) in R (the part's frame at home)."""
    assert station.positioner is not None
    sc = station.scenario
    X_RW = invert(sc.X_WR)
    t = np.asarray(cw.times)
    at = np.unique(np.concatenate([np.arange(0.0, t[-1], record_dt), t[np.flatnonzero(np.diff(cw.arc_on.astype(int)))
                                   + 1], [t[-1]]]))  # fmt: skip
    q = np.column_stack([np.interp(at, t, cw.q[:, j]) for j in range(cw.q.shape[1])])
    axes = np.column_stack([np.interp(at, t, cw.axes[:, j]) for j in range(2)])
    arc = np.asarray(cw.arc_on, dtype=bool)[np.clip(np.searchsorted(t, at, side="right") - 1, 0, len(t) - 1)]
    sim = station.sim
    sp = station.positioner
    tcp_W = np.empty((len(at), 3))
    back_R = np.empty((len(at), 3))
    moved = np.full(2, np.inf)  # the axes where the bodies were last moved to
    bead = _Bead(station)
    for i in range(len(at)):
        a = axes[i]
        if np.abs(a - moved).max() >= BODY_STEP_RAD or i == len(at) - 1:
            station.follow_positioner(float(a[0]), float(a[1]))
            moved = a
        sim.set_q(q[i])
        p_W = sim.link_pose("torch_tcp")[:3, 3]
        tcp_W[i] = p_W
        # The part's true motion from the scan at these axes: the bodies' last step carried on by the kinematics.
        X_step_R = sp.pos.move(float(a[0]), float(a[1])) @ np.linalg.inv(sp.pos.move(*sp.axes))
        X_R_true = X_step_R @ X_RW @ sp.X_W_true @ sc.X_WR
        back_R[i] = (invert(X_R_true) @ np.r_[X_RW[:3, :3] @ p_W + X_RW[:3, 3], 1.0])[:3]
        bead.lay(back_R[i], bool(arc[i - 1]) if i else False, bool(arc[i]), sp.X_W_true @ sc.X_WR)
    events = tuple(Event(float(t0), "move", f"{kind} {cw.seam_id}") for kind, t0, _ in cw.pieces)
    return Execution(at, q, tcp_W, arc, events), back_R


def play_arcs(station: SimStation, cw: CoordinatedWeld,
              R_R_F0: FloatArray) -> list[tuple[Execution, FloatArray, FloatArray | None]]:  # fmt: skip
    """Each arc of ``cw`` (:attr:`CoordinatedWeld.arcs`: each from home and back) played in turn from the
    positioner at home: its execution, its records' tips in the part's frame at the scan (:func:`play`) and the
    weave meant at them (:func:`weave_at_records`, R_R_F0 (3, 3) the faceplate's rotation at home; None without
    a weave)."""
    assert station.positioner is not None
    home = station.positioner.pos.home
    out = []
    for arc in cw.arcs:
        station.move_positioner(*home)
        ex, back = play(station, arc)
        out.append((ex, back, weave_at_records(arc, ex, R_R_F0) if arc.weave_F is not None else None))
    return out


def joined(played: list[tuple[Execution, FloatArray, FloatArray | None]]) -> tuple[Execution, FloatArray,
                                                                                   FloatArray | None]:  # fmt: skip
    """Arcs played one after the other (:func:`play_arcs`) as one execution (each arc's times after the last's end),
    their tips and weaves (None: no arc weaves)."""
    if len(played) == 1:
        return played[0]
    times, t0, events = [], 0.0, []
    for ex, _, _ in played:
        times.append(np.asarray(ex.times) + t0)
        events += [Event(e.t + t0, e.kind, e.detail) for e in ex.events]
        t0 = float(times[-1][-1]) + RECORD_DT
    cat = lambda f: np.concatenate([f(p) for p in played])  # noqa: E731
    ex = Execution(np.concatenate(times), cat(lambda p: p[0].q), cat(lambda p: p[0].tcp_W), cat(lambda p: p[0].arc_on),
                   tuple(events))  # fmt: skip
    weave = None if all(p[2] is None for p in played) else cat(lambda p: p[2] if p[2] is not None else 0.0 * p[1])
    return ex, cat(lambda p: p[1]), weave


class _Bead:
    """The bead of a coordinated weld, laid on the turning part: the tip's points in the part's frame at the scan
    (R at home) gathered while the arc burns, drawn as chords of the scenario's bead style once they span a step
    (or the arc goes off), each placed where the part's bodies stand at that moment (they carry it on)."""

    def __init__(self, station: SimStation) -> None:
        self.sim, self.style = station.sim, station.scenario.simulation.bead
        self.pending: list[FloatArray] = []

    def lay(self, p_R: FloatArray, was_on: bool, on: bool, X_W_part: FloatArray) -> None:
        """One record: the tip p_R (3,) in the part's frame; the arc on since the last record (``was_on``) and from
        this one on (``on``); X_W_part (4, 4): the part's bodies now, from its frame at the scan."""
        from cell.sim.robot import bead_chords

        if was_on or on:
            self.pending.append(np.asarray(p_R, dtype=float))
        path = np.asarray(self.pending)
        if len(path) > 1 and (not on or np.linalg.norm(np.diff(path, axis=0), axis=1).sum() >= self.style.step_m):
            p_W = path @ X_W_part[:3, :3].T + X_W_part[:3, 3]
            self.sim.add_beads(bead_chords(p_W, np.ones(len(p_W), bool), self.style.step_m), self.style)
            self.pending = [path[-1]] if on else []
        elif not on:
            self.pending = []


def weave_at_records(cw: CoordinatedWeld, ex: Execution, R_R_F0: FloatArray) -> FloatArray:
    """(n, 3) [m]: the weave the plan meant at each record, in the part's frame at the scan (R at home; R_R_F0
    (3, 3) the faceplate's rotation there): each record's place along the weld from its rotate axis (it turns one
    way along a loop; else the knot nearest the record's planned torch), the weave interpolated there."""
    w_F = np.zeros((len(cw.s), 3)) if cw.weave_F is None else np.asarray(cw.weave_F)
    r, s = np.asarray(cw.knot_axes)[:, 1], np.asarray(cw.s)
    rec = np.interp(np.asarray(ex.times), np.asarray(cw.times), np.asarray(cw.axes)[:, 1])
    if np.all(np.diff(r) > 0) or np.all(np.diff(r) < 0):
        order = np.argsort(r)
        at = np.interp(rec, r[order], s[order])
    else:
        at = s[np.abs(rec[:, None] - r[None, :]).argmin(axis=1)]
    w = np.column_stack([np.interp(at, s, w_F[:, j]) for j in range(3)])
    return np.asarray(w @ np.asarray(R_R_F0).T)


def quality(
    ex: Execution, back_R: FloatArray, truth_R: FloatArray, closed: bool, weave_R: FloatArray | None = None
) -> WeldQuality:
    """The weld's quality from the arc-on records carried back to the part at the scan against its true curve
    there (n, 3) in R: the TCP error and the travel speed are the torch's relative to the part; ``weave_R`` (n, 3)
    the weave meant at each record (:func:`weave_at_records`), taken off first: the torch against the curve
    without its weave."""
    from cell.process.curve_quality import curve_weld_quality

    on = np.asarray(ex.arc_on)
    p = back_R if weave_R is None else back_R - weave_R
    return curve_weld_quality(np.asarray(ex.times)[on], p[on], truth_R, closed)
