"""One arc of a curved seam solved along its whole length (its torch setting from the reach map, its approach and
depart, its passes, timed), what is left of it when it fails, and what stops the torch settings along a stretch of
the curve in words (docs/curves-welding.md section 10).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import replace

import numpy as np

from cell.errors import IKError, TimingError
from cell.geometry import FloatArray, readonly
from cell.motion.ik import solve_ik
from cell.planning.curves.graph import settings_along
from cell.planning.curves.path import CurvePath, curve_path, curve_poses
from cell.planning.curves.reach import Miss, Run
from cell.planning.curves.search import CurveTask, _Preview, _preview, _solved, _turns, curve_task
from cell.planning.curves.timing import curve_lines
from cell.planning.curves.weave import woven
from cell.planning.failures import SeamFailure, unreachable
from cell.planning.seam_search import SeamSearch, SeamSolution
from cell.planning.transfers import Piece
from cell.process.weave import pass_speed
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import PlanReason
from cell.types.procedure import WeldProcedure

TRIES = 10  # covers tried per map (an arc that fails its full solve is trimmed or dropped, the cover found again)
TRIM_M = 0.015  # [m] an arc whose approach or depart fails is shortened by this much at that end
MIN_ARC_M = 0.02  # [m] no shorter arc is kept
# [m] the timed weld's TCP stays this close to its planned path between the IK knots: the 0.5 mm a weld's TCP is
# held to against the true curve, less the controller's tracking (0.01-0.05 mm measured)
PATH_TOL_M = 0.0004


def same_stretch(a: Run, b: Run, total: float) -> bool:
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


def trimmed(run: Run, failure: SeamFailure, arc: CurveEstimate) -> list[Run]:
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


def why_stopped(misses: list[Miss], lo: float, hi: float, total: float, closed: bool) -> tuple[PlanReason, str]:
    """What stops the torch settings from lo to hi [m] along a curve ``total`` long: the commonest reason of the
    stations there (every station's where none lies there) as the code, and the two commonest in words."""
    there = [m for m in misses if _within(m.at_m, lo, hi, total, closed)] or misses
    counts = Counter((m.code, m.what) for m in there).most_common(2)
    why = ", ".join(f"{k} of {len(there)} tries {w or c.value}" for (c, w), k in counts) or "no setting tried"
    return (counts[0][0][0] if counts else PlanReason.IK_FAILED), why


def _within(x: float, lo: float, hi: float, total: float, closed: bool) -> bool:
    """Whether x [m] along a curve ``total`` long lies in [lo, hi] (round a closed one's start)."""
    return 0.0 <= ((x - lo) % total if closed else x - lo) <= hi - lo


def arc_solution(
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
    """Every pass of ``procedure`` along the root poses X0 (n, 4, 4), solved and timed (:func:`arc_solution`)."""
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
        fault = _singular(search, pieces, task.length) or _outside_limits(search, pieces, task.length)
        if fault is not None:
            return _pass(fault, k)
        off = _off_path(search, pieces, X)
        if off is not None:
            return _pass(off, k)
        out.append(got)
    return tuple(out)


def _off_path(search: SeamSearch, pieces: list[Piece], X: FloatArray) -> SeamFailure | None:
    """Where the timed weld's TCP (every 5th sample of its joint spline, between the IK knots too) leaves the planned
    path X (n, 4, 4) by more than :data:`PATH_TOL_M`, worst first, its progress along the weld (the arc cut short
    of there: :func:`trimmed`); None when it keeps within. Near a wrist singularity the knots lie on the curve
    but the joints swing between them (railing's posts: 0.6-0.8 mm off the true curve between knots 0.8 mm
    apart)."""
    from cell.process.curve_quality import nearest_on_curve

    weld = next(p for p in pieces if p.kind == "weld")
    q = weld.trajectory.q[::5]
    tcp = np.array([search.robot.fk(qk)[:3, 3] for qk in q])
    d, s = nearest_on_curve(tcp, X[:, :3, 3], False)
    k = int(np.argmax(d))
    if d[k] <= PATH_TOL_M:
        return None
    where = (f"the timed weld leaves the curve by {d[k] * 1000:.2f} mm > {PATH_TOL_M * 1000:g} mm between its "
             f"knots at {s[k] * 1000:.1f} mm along it (the joints swing between the knots)")  # fmt: skip
    return SeamFailure(PlanReason.FLIP, where, tcp[k].copy(), float(s[k]))


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


def _outside_limits(search: SeamSearch, pieces: list[Piece], length: float) -> SeamFailure | None:
    """The first sample of the timed approach, weld or depart where a joint leaves its position limits (the safety
    gate's test), or None; its progress as :func:`_singular`'s. Every IK knot lies within the limits, but the timed
    spline between two knots of a joint held at its limit can swing past it (docs/curves-welding.md section 10)."""
    lim = search.robot.limits
    for piece in pieces:
        q = piece.trajectory.q
        out = np.maximum(lim.q_min - q, q - lim.q_max)
        bad = np.flatnonzero(np.any(out > 1e-9, axis=1))
        if len(bad):
            i = int(bad[0])
            j = int(np.argmax(out[i]))
            past = math.degrees(float(out[i, j]))
            where = f"{search.robot.joint_names[j]} {past:.3g} deg past its limit between the knots of the {piece.kind}"
            p_R = search.robot.fk(q[i])[:3, 3].copy()
            return SeamFailure(PlanReason.TIMING, where, p_R, 0.0 if piece.kind == "weld" else length)
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
