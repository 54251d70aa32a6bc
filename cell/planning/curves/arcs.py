"""A curved seam planned from its reach map: the fewest arcs that cover it whole with their overlaps (one, when a
torch setting holds all round), each solved along its whole length with its approach and depart; or the share of
it the arm can reach (docs/curves-welding.md section 10).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from cell.errors import IKError
from cell.geometry import FloatArray, readonly
from cell.motion.ik import solve_ik
from cell.planning.curves.path import curve_path, curve_poses
from cell.planning.curves.reach import Run, cover, reach_map, settings, share, station_spacing
from cell.planning.curves.search import _flange_axes, _Preview, _solved, _turns, curve_task, knot_spacing
from cell.planning.curves.split import MAX_ARCS, Split, sub_arc
from cell.planning.curves.weave import woven
from cell.planning.failures import SeamFailure, better, unreachable
from cell.planning.seam_search import SeamSearch, SeamSolution
from cell.process.weave import knot_spacing as weave_spacing
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason
from cell.types.procedure import WeldProcedure

TRIES = 10  # covers tried per map (an arc that fails its full solve is trimmed or dropped, the cover found again)
TRIM_M = 0.015  # [m] an arc whose approach or depart fails is shortened by this much at that end
MIN_ARC_M = 0.02  # [m] no shorter arc is kept


def plan_arcs(
    search: SeamSearch, est: CurveEstimate, q_seed: FloatArray, procedure: WeldProcedure | None = None
) -> Split:
    """The arcs that weld ``est`` whole (a closed curve all round and over its overlap; an open one end to end),
    fewest first, at most :data:`MAX_ARCS`, each solved (:class:`SeamSolution`, its task an open arc of the
    curve, id ``<seam>#arcK``); else the share of the curve some torch setting reaches and the failure of the
    arc that got furthest. The map walks the nominal angles first, then the tolerance's widened ones."""
    pr, opt = search.process, search.opt
    knot = knot_spacing(est, opt.spacing)
    if procedure is not None:
        knot = weave_spacing(procedure, 0, knot)
    overlap = pr.closed_overlap if est.closed else 0.0
    probe = curve_path(est, station_spacing(est))
    flange = _flange_axes(search, q_seed, curve_poses(probe, pr)[:, :3, 2])
    runs: list[Run] = []
    failure: SeamFailure | None = None
    for widened in (False, True):
        runs += reach_map(search, est, settings(search, widened), flange, q_seed, knot, overlap)
        for _ in range(TRIES):
            chosen = cover(runs, est.length_m, est.closed, overlap, MAX_ARCS)
            if chosen is None:
                break
            solved: list[tuple[CurveEstimate, SeamSolution]] = []
            for k, run in enumerate(chosen, 1):
                arc = sub_arc(est, run.a_m, run.b_m, k)
                got = _arc_solution(search, arc, run, flange, knot, procedure)
                if isinstance(got, SeamFailure):
                    failure = better(failure, got)
                    runs = [r for r in runs if not _same(r, run)] + _trimmed(run, got, arc)
                    break
                solved.append((arc, got))
            else:
                return Split(tuple(solved), 1.0, None)
    reached = share(runs, est.length_m, est.closed)
    if failure is None:
        where = "no torch setting holds it (IK, collisions, singular)" if not runs else _gap(runs, est)
        code = PlanReason.IK_FAILED if not runs else PlanReason.COLLISION
        failure = SeamFailure(code, where, np.asarray(est.p_RS[0]), 0.0)
    return Split((), reached, failure)


def _same(a: Run, b: Run) -> bool:
    return a.cand == b.cand and abs(a.length - b.length) < 1e-9 and abs(math.remainder(a.a_m - b.a_m, 1.0)) < 1e-9


def _trimmed(run: Run, failure: SeamFailure, arc: CurveEstimate) -> list[Run]:
    """What is left of a stretch whose arc failed its full solve: cut short of where the weld itself failed
    (``failure.progress`` along it), else (its approach or depart) without :data:`TRIM_M` at the end nearer the
    failure; nothing when less than :data:`MIN_ARC_M` would be left. Lengths along the located curve."""
    length = arc.length_m
    if failure.progress < length:  # the curve itself: keep the weld up to short of there
        cut_start, cut_end = 0.0, length - (failure.progress - TRIM_M)
    else:
        ends = np.asarray(arc.p_RS)[[-1, 0] if run.cand.reversed else [0, -1]]  # the weld's start and end
        near_start = np.linalg.norm(ends[0] - failure.p_R) < np.linalg.norm(ends[1] - failure.p_R)
        cut_start, cut_end = (TRIM_M, 0.0) if near_start else (0.0, TRIM_M)
    if run.length - cut_start - cut_end < MIN_ARC_M:
        return []
    if run.cand.reversed:
        cut_start, cut_end = cut_end, cut_start
    return [replace(run, a_m=run.a_m + cut_start, b_m=run.b_m - cut_end)]


def _gap(runs: list[Run], est: CurveEstimate) -> str:
    """Words for the part of ``est`` no stretch holds: where its widest gap starts."""
    total = est.length_m
    bins = np.zeros(max(1, math.ceil(total / 0.001)), dtype=bool)
    for r in runs:
        idx = np.arange(math.floor(r.a_m / 0.001), math.ceil(r.b_m / 0.001))
        bins[np.mod(idx, len(bins)) if est.closed else idx[(idx >= 0) & (idx < len(bins))]] = True
    free = np.flatnonzero(~bins)
    if len(free) == 0:
        return f"no {MAX_ARCS} arcs overlap all round"
    return f"no torch setting holds it from {free[0]:.0f} mm along it ({(~bins).sum():.0f} mm unreached)"


def _arc_solution(
    search: SeamSearch,
    arc: CurveEstimate,
    run: Run,
    flange: tuple[FloatArray, FloatArray],
    knot: float,
    procedure: WeldProcedure | None,
) -> SeamSolution | SeamFailure:
    """One arc (an open piece of the curve) solved with the torch setting ``run`` held along it: IK at its weld
    start from the map's, A4 and A6 turned whole turns to centre their travel, then the straight search's full
    solve with its approach and depart (shortened where they fail)."""
    c, pr = run.cand, search.process
    path = curve_path(arc, knot, reverse=c.reversed)
    X = curve_poses(path, pr, spin=c.spin, work_offset=c.work_offset, travel_offset=c.travel_offset, flange=flange)
    X = woven(X, path, procedure)
    task = curve_task(arc.id, path)
    try:
        q0 = np.asarray(solve_ik(search.robot, X[0], run.q_start, options=search.opt.ik))
    except IKError as exc:
        return unreachable(exc, X[0], 0.0, 0.0)
    q0 = q0 + _turns(_travel(search, X, q0), search.window.center, search.robot.limits)
    return _solved(search, _Preview(c, task, X, readonly(q0), 0.0, 1.0))


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
