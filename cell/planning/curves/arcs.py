"""A curved seam planned from its reach map: the fewest arcs that cover it whole with their overlaps (one, when a
torch setting holds all round), each solved along its whole length with its approach and depart; or the share of
it the arm can reach (docs/curves-welding.md section 10).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import replace

import numpy as np

from cell.errors import IKError, TimingError
from cell.geometry import FloatArray, readonly
from cell.motion.ik import solve_ik
from cell.planning.curves.gapseed import seeded
from cell.planning.curves.gapwalk import walked
from cell.planning.curves.graph import gaps, graph_map, refined, settings_along
from cell.planning.curves.path import CurvePath, curve_path, curve_poses
from cell.planning.curves.reach import Miss, Run, balanced, cover, pinch, settings, share, station_spacing
from cell.planning.curves.search import (
    CurveTask,
    _flange_axes,
    _Preview,
    _preview,
    _solved,
    _turns,
    curve_task,
    knot_spacing,
)
from cell.planning.curves.split import MAX_ARCS, Split, sub_arc
from cell.planning.curves.timing import curve_lines
from cell.planning.curves.weave import woven
from cell.planning.failures import SeamFailure, better, unreachable
from cell.planning.seam_search import SeamSearch, SeamSolution
from cell.planning.transfers import Piece
from cell.process.torch_orientations import Candidate
from cell.process.weave import knot_spacing as weave_spacing
from cell.process.weave import pass_speed
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason
from cell.types.procedure import WeldProcedure

TRIES = 10  # covers tried per map (an arc that fails its full solve is trimmed or dropped, the cover found again)
SPARE_TRIES = 4  # covers tried more once the map's spare paths are added (each a full solve of its arcs)
TRIM_M = 0.015  # [m] an arc whose approach or depart fails is shortened by this much at that end
MIN_ARC_M = 0.02  # [m] no shorter arc is kept
GAP_MARGIN_M = 0.015  # [m] a gap in the map is walked again with finer settings this far either side of it


def plan_arcs(
    search: SeamSearch,
    est: CurveEstimate,
    q_seed: FloatArray,
    procedure: WeldProcedure | None = None,
    gap_walk: bool = False,
) -> Split:
    """The arcs that weld ``est`` whole (a closed curve all round and over its overlap; an open one end to end),
    fewest first, at most :data:`MAX_ARCS`, each solved (a :class:`SeamSolution` per pass of ``procedure``, its
    task an open arc of the curve, id ``<seam>#arcK``); else the share of the curve some torch setting reaches
    and the failure of the arc that got furthest. The map's graph (:mod:`.graph`) holds the nominal angles first,
    then the tolerance's ends too, then finer settings in its gaps; ``gap_walk``: then the gaps walked at finer
    stations (:mod:`.gapwalk`, :mod:`.gapseed`: no round scenario's curve welded by it yet, 10-60 s more per curve
    with a gap, so not in ``cell weld``; docs/curves-welding.md section 10)."""
    pr, opt = search.process, search.opt
    knot = knot_spacing(est, opt.spacing)
    if procedure is not None:
        knot = weave_spacing(procedure, 0, knot)
    overlap = pr.closed_overlap if est.closed else 0.0
    probe = curve_path(est, station_spacing(est))
    flange = _flange_axes(search, q_seed, curve_poses(probe, pr)[:, :3, 2])
    runs: list[Run] = []
    misses: list[Miss] = []
    failure: SeamFailure | None = None
    stiff = pr.work_angle_tol <= 0.0 and pr.travel_angle_tol <= 0.0  # no angle to widen
    memo: dict[Candidate, list[FloatArray | None]] = {}  # each setting's joints at the stations, walked once
    for stage in range(1 if stiff else 4 if gap_walk else 3):  # nominal; tolerance's ends; finer settings, stations
        cands = settings(search, False) + (settings(search, True) if stage else [])
        windows = _windows(runs, est, overlap) if stage > 1 else []
        if stage > 1 and not windows:
            break
        cands += refined(search) if stage > 1 else []
        if stage == 3:
            got_runs = walked(search, est, runs, windows, flange, knot, overlap)
            got_runs += seeded(search, est, windows, flange, q_seed, knot, overlap)
            got_misses: list[Miss] = []
        else:
            got_runs, got_misses = graph_map(search, est, cands, flange, q_seed, knot, overlap, memo, windows)
        runs, misses = runs + [r for r in got_runs if not r.spare], misses + got_misses
        spare = sorted((r for r in got_runs if r.spare), key=_setting_changes)  # the fewest turns of the torch first
        for pool in range(2):  # the map's paths; then, once no cover of them welds, the spare paths too
            if pool and not spare:
                break
            runs = runs + spare if pool else runs
            for _ in range(SPARE_TRIES if pool else TRIES):
                chosen = cover(runs, est.length_m, est.closed, overlap, MAX_ARCS)
                if chosen is None:
                    break
                solved: list[tuple[CurveEstimate, tuple[SeamSolution, ...]]] = []
                arcs = balanced(chosen, est.length_m, est.closed, overlap)
                for k, (run, part) in enumerate(zip(chosen, arcs, strict=True), 1):
                    arc = sub_arc(est, part.a_m, part.b_m, k)
                    got = _arc_solution(search, arc, part, flange, knot, procedure)
                    if isinstance(got, SeamFailure):
                        failure = better(failure, got)
                        runs = [r for r in runs if not _same(r, run, est.length_m)] + _trimmed(part, got, arc)
                        break
                    solved.append((arc, got))
                else:
                    return Split(tuple(solved), 1.0, None)
    reached = share(runs, est.length_m, est.closed)
    if failure is None:
        failure = _gap(runs, misses, est, overlap)
    return Split((), reached, failure)


def _windows(runs: list[Run], est: CurveEstimate, overlap: float) -> list[tuple[float, float]]:
    """Where the map is walked again with finer settings (from, to) [m] along the located curve: its gaps, or with
    none, where every stretch through a point of a closed curve gives out short of the restart ``overlap`` [m]
    (:func:`.reach.pinch`), the overlap either side; each widened by :data:`GAP_MARGIN_M`."""
    out = gaps(runs, est.length_m, est.closed, GAP_MARGIN_M)
    at = pinch(runs, est.length_m, overlap) if est.closed and not out else None
    if at is not None:
        out.append((at[0] - overlap - GAP_MARGIN_M, at[0] + overlap + GAP_MARGIN_M))
    return out


def _setting_changes(run: Run) -> int:
    """How many times the torch's setting changes along ``run``."""
    if run.track is None:
        return 0
    return int(np.count_nonzero(np.any(np.abs(np.diff(run.track[:, 1:], axis=0)) > 1e-9, axis=1)))


def _same(a: Run, b: Run, total: float) -> bool:
    """Whether two stretches are one (the cover's copy a lap on): the same place, the same settings along it."""
    ta, tb = a.track, b.track
    same_track = (ta is None and tb is None) or (
        ta is not None and tb is not None and ta.shape == tb.shape and bool(np.allclose(ta[:, 1:], tb[:, 1:]))
    )
    return (
        a.cand == b.cand
        and abs(a.length - b.length) < 1e-9
        and abs(math.remainder(a.a_m - b.a_m, total)) < 1e-9
        and same_track
    )


def _trimmed(run: Run, failure: SeamFailure, arc: CurveEstimate) -> list[Run]:
    """What is left of a stretch whose arc failed its full solve: cut short of where the weld itself failed
    (``failure.progress`` along it; before 0: on the approach), else (its approach or depart) without
    :data:`TRIM_M` at the end nearer the failure; nothing when less than :data:`MIN_ARC_M` would be left. Lengths
    along the located curve."""
    length = arc.length_m
    if 0.0 <= failure.progress < length:  # the curve itself: keep the weld up to short of there
        cut_start, cut_end = 0.0, length - (failure.progress - TRIM_M)
    elif failure.progress < 0.0:  # the approach's checks (a body, the hose window, a singularity) before the start
        cut_start, cut_end = TRIM_M, 0.0
    else:
        ends = np.asarray(arc.p_RS)[[-1, 0] if run.cand.reversed else [0, -1]]  # the weld's start and end
        near_start = np.linalg.norm(ends[0] - failure.p_R) < np.linalg.norm(ends[1] - failure.p_R)
        cut_start, cut_end = (TRIM_M, 0.0) if near_start else (0.0, TRIM_M)
    if run.length - cut_start - cut_end < MIN_ARC_M:
        return []
    if run.cand.reversed:
        cut_start, cut_end = cut_end, cut_start
    return [replace(run, a_m=run.a_m + cut_start, b_m=run.b_m - cut_end)]


def _gap(runs: list[Run], misses: list[Miss], est: CurveEstimate, overlap: float) -> SeamFailure:
    """The failure for a curve no cover of stretches welds: where its widest stretch no setting holds starts, how
    long it is (and how many such stretches, how much in all) and what stops the settings there (the commonest
    reason of the stations in it: its code); with every point held, where every stretch gives out short of the
    restart ``overlap`` [m] (:func:`.reach.pinch`, and what stops the settings there), else that no
    :data:`MAX_ARCS` arcs overlap by it all round."""
    total = est.length_m
    free = gaps(runs, total, est.closed, 0.0)
    at = pinch(runs, total, overlap) if est.closed and not free else None
    if at is not None:
        code, why = _why(misses, at[0] - overlap, at[0] + overlap, total, est.closed)
        where = (f"every point is held, but every stretch through {at[0] * 1000:.0f} mm along it gives out within "
                 f"{at[1] * 1000:.1f} mm of it: no arc passes there to restart {overlap * 1000:.0f} mm back over the "
                 f"last ({why})")  # fmt: skip
        return SeamFailure(code, where, _point(est, at[0]), 0.0)
    if not free:
        where = (f"every point is held, but no {MAX_ARCS} arcs overlap by {overlap * 1000:.0f} mm at every restart "
                 "(the torch cannot turn through where the stretches give out fast enough)")  # fmt: skip
        return SeamFailure(PlanReason.COLLISION if misses else PlanReason.IK_FAILED, where, est.p_RS[0], 0.0)
    lo, hi = max(free, key=lambda g: g[1] - g[0])
    lo, hi = lo % total if est.closed else lo, (lo % total if est.closed else lo) + (hi - lo)
    code, why = _why(misses, lo - 0.01, hi + 0.01, total, est.closed)
    unheld = sum(b - a for a, b in free)
    more = f"; {len(free)} such stretches, {unheld * 1000:.0f} mm in all" if len(free) > 1 else ""
    where = f"no torch setting holds it from {lo * 1000:.0f} mm along it ({(hi - lo) * 1000:.0f} mm{more}; {why})"
    return SeamFailure(code, where, _point(est, lo), 0.0)


def _why(misses: list[Miss], lo: float, hi: float, total: float, closed: bool) -> tuple[PlanReason, str]:
    """What stops the torch settings from lo to hi [m] along a curve ``total`` long: the commonest reason of the
    stations there (every station's where none lies there) as the code, and the two commonest in words."""
    there = [m for m in misses if _within(m.at_m, lo, hi, total, closed)] or misses
    counts = Counter((m.code, m.what) for m in there).most_common(2)
    why = ", ".join(f"{k} of {len(there)} tries {w or c.value}" for (c, w), k in counts) or "no setting tried"
    return (counts[0][0][0] if counts else PlanReason.IK_FAILED), why


def _point(est: CurveEstimate, at_m: float) -> FloatArray:
    """The located curve's sample nearest ``at_m`` [m] along it (3,)."""
    k = int(np.searchsorted(np.linspace(0, est.length_m, len(est.p_RS)), at_m % est.length_m))
    return np.asarray(est.p_RS[min(k, len(est.p_RS) - 1)])


def _within(x: float, lo: float, hi: float, total: float, closed: bool) -> bool:
    """Whether x [m] along a curve ``total`` long lies in [lo, hi] (round a closed one's start)."""
    return 0.0 <= ((x - lo) % total if closed else x - lo) <= hi - lo


def _arc_solution(
    search: SeamSearch,
    arc: CurveEstimate,
    run: Run,
    flange: tuple[FloatArray, FloatArray],
    knot: float,
    procedure: WeldProcedure | None,
) -> tuple[SeamSolution, ...] | SeamFailure:
    """One arc (an open piece of the curve) solved with the torch setting ``run`` held along it (its spin first left
    to the arm where the process leaves it free, as the one-go search does), one solution per
    pass of ``procedure`` (each at its offset and weave in the local cross-section, seeded by the pass before): IK
    at its weld start from the map's, A4 and A6 turned whole turns to centre their travel, then the straight
    search's full solve with its approach and depart (shortened where they fail) and the weld timed at its travel
    speed (a TIMING failure, at progress 0, drops the stretch)."""
    c, pr = run.cand, search.process
    path = curve_path(arc, knot, reverse=c.reversed)
    spin, work, travel = settings_along(run, run.b_m - path.s if c.reversed else run.a_m + path.s)
    X0 = curve_poses(path, pr, spin=spin, work_offset=work, travel_offset=travel, flange=flange)
    task = curve_task(arc.id, path)
    if pr.spin_tol >= math.pi - 1e-9:  # the spin free: first as the arm takes it (the least joint motion)
        free = _preview(search, task, c, X0, run.q_start, search._reference(run.q_start), True)
        if not isinstance(free, SeamFailure):
            got = _passes(search, task, free.X, path, run, procedure)
            if not isinstance(got, SeamFailure):
                return got
    return _passes(search, task, X0, path, run, procedure)


def _passes(
    search: SeamSearch,
    task: CurveTask,
    X0: FloatArray,
    path: CurvePath,
    run: Run,
    procedure: WeldProcedure | None,
) -> tuple[SeamSolution, ...] | SeamFailure:
    """Every pass of ``procedure`` along the root poses X0 (n, 4, 4), solved and timed (:func:`_arc_solution`)."""
    c, pr = run.cand, search.process
    out: list[SeamSolution] = []
    for k in range(len(procedure.passes) if procedure is not None else 1):
        X = woven(X0, path, procedure, k)
        seed = out[-1].q_weld[0] if out else run.q_start
        try:
            q0 = np.asarray(solve_ik(search.robot, X[0], seed, options=search.opt.ik))
        except IKError as exc:
            return _pass(unreachable(exc, X[0], 0.0, 0.0), k)
        if not out:
            q0 = q0 + _turns(_travel(search, X, q0), search.window.center, search.robot.limits)
        got = _solved(search, _Preview(c, task, X, readonly(q0), 0.0, 1.0))
        if isinstance(got, SeamFailure):
            return _pass(got, k)
        speed = pass_speed(procedure, k) if procedure is not None else pr.travel_speed
        try:  # a joint over its velocity limit at the travel speed (a wrist near its singularity): not this arc
            pieces = curve_lines(search.robot, replace(pr, travel_speed=speed), search.opt, got)
        except TimingError as exc:
            return _pass(SeamFailure(PlanReason.TIMING, exc.message, X[0][:3, 3].copy(), 0.0), k)
        singular = _singular(search, pieces, task.length)
        if singular is not None:
            return _pass(singular, k)
        out.append(got)
    return tuple(out)


def _singular(search: SeamSearch, pieces: list[Piece], length: float) -> SeamFailure | None:
    """The first place the timed approach, weld or depart passes nearer a singularity than the safety gate allows
    (every 10th sample of the timed motion, as the gate samples it; between the IK knots too), or None; its
    progress beyond the curve for the approach or depart (their end trimmed), 0 for the weld (dropped)."""
    for piece in pieces:
        for q in piece.trajectory.q[::10]:
            m = search.robot.manipulability(q)
            if m < search.opt.min_manipulability:
                where = f"manipulability {m:.4f} below {search.opt.min_manipulability:g} on the {piece.kind}"
                p_R = search.robot.fk(q)[:3, 3].copy()
                return SeamFailure(PlanReason.SINGULAR, where, p_R, 0.0 if piece.kind == "weld" else length)
    return None


def _pass(failure: SeamFailure, k: int) -> SeamFailure:
    """A failure named by its pass (beyond the root)."""
    return replace(failure, where=f"pass {k + 1}: {failure.where}") if k else failure


def _travel(search: SeamSearch, X: FloatArray, q0: FloatArray) -> FloatArray:
    """The joints at every 8th knot of X (n, 4, 4) from q0 (dof,), warm-started, A4..A6 unwrapped (the travel
    the whole-turn centring needs); stops where IK fails."""
    qs = [q0]
    for Xk in X[8::8]:
        try:
            qs.append(np.asarray(solve_ik(search.robot, Xk, qs[-1], options=search.opt.ik)))
        except IKError:
            break
    Q = np.array(qs)
    Q[:, -3:] = np.unwrap(Q[:, -3:], axis=0)
    return Q
