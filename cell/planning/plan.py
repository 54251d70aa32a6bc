"""Detected seams -> an executable welding plan for the arm (values in, a frozen :class:`WeldPlan` out): per seam the
reach pre-check, the torch search, timing, then the order of the seams (docs/planning.md section 1).

Frames: everything in the robot base frame R [m]; joints [rad]; time [s]."""

from __future__ import annotations

import time
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import replace

import numpy as np
import numpy.typing as npt

from cell.config.motion import PlanOptions
from cell.errors import MotionError, PlanError, TimingError
from cell.geometry import readonly
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning.access.home import first_cut_off
from cell.planning.access.openings import RETREATS, WAYS
from cell.planning.access.screen import first_unjoined
from cell.planning.assembly import assemble, seam_pieces
from cell.planning.blend import blend_plan
from cell.planning.curves import arc_spans, cover_curves, curve_pieces, in_part, weldable, whole_or_none, with_paths
from cell.planning.curves.refused import exit_at_fault
from cell.planning.curves.split import seam_of
from cell.planning.curves.timing import curve_lines
from cell.planning.failures import SeamFailure, reason_text
from cell.planning.memo import PlanMemo
from cell.planning.order import seam_order
from cell.planning.passes import pass_pieces, solve_passes
from cell.planning.reach import ReachModel
from cell.planning.seam_search import SeamSearch, SeamSolution, seam_process
from cell.planning.short_lines import seam_lines
from cell.planning.stand_off import as_is, blocked_by_table, shortened_plan, stand_off, table_top
from cell.planning.transfers import Piece, TransferFail, Transfers
from cell.process.torch import WeldProcess
from cell.types import Part
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import NoProcedure, PlanReason, Remainder, SeamOutcome, SeamProcedure, SeamTask, WeldPlan


def plan_welds(
    robot: RobotModel,
    tasks: Sequence[SeamTask],
    q_home: npt.ArrayLike,
    process: WeldProcess,
    obstacles: Sequence[Part] = (),
    *,
    options: PlanOptions | None = None,
    rng: np.random.Generator | None = None,
    checker: CollisionChecker | None = None,
    procedures: Mapping[str, SeamProcedure | NoProcedure] | None = None,
    on_seam: Callable[[int, int], None] | None = None,
    first: Collection[str] = (),
    curves: Sequence[CurveEstimate] = (),
    elsewhere: bool = False,
    avoid: Collection[tuple[str, str]] = (),
    refused: Mapping[str, Sequence[Remainder]] | None = None,
    memo: PlanMemo | None = None,
) -> WeldPlan:
    """Plan every seam that can be welded, skip and report the others (see the module docstring).

    tasks : the seams, in R (underside seams are not passed in: the caller marks them for the turnover).
    q_home : (dof,) [rad] where the program starts and ends. obstacles : parts and table, boxes in R.
    rng : for IK restarts (deterministic for a seeded generator; default seed 0).
    procedures : seam id -> the weld procedure it got (:mod:`cell.process.procedures`): its travel speed and
        torch angles drive the search, its direction fixes a vertical seam's, its passes and weave become one
        weld segment per pass; a NoProcedure is the seam's reason (no_procedure). A seam not in it is welded
        with ``process`` alone, one pass on the seam line.
    on_seam : called with (seams searched, seams in all) after each seam's torch search (a progress bar).
    first : task ids welded before all the others (tack welds, :mod:`cell.pipeline.tacks`).
    avoid : (from id, to id) transfers ("" = home) the order takes only when no order does without them (the
        safety gate found the move along one, blended into the next approach, at fault).
    curves : located curved seams (:class:`CurveEstimate`, in R; those not found are left out), each welded along
        its curve (:mod:`cell.planning.curves`: a closed one all round with the process's start/stop overlap), its
        procedure from ``procedures`` too; their outcomes follow the tasks'.
    refused : curved seam id -> stretches along it (from, to [m], code, why) whose arc the safety gate refused:
        that arc is left out alone, its stretch left for a manual weld (:func:`cell.planning.curves.cover_curves`).
    memo : the answers kept from an earlier plan of the same job (the safety gate's rounds): the curves' reach-map
        IK and the transfers' searches (:class:`~cell.planning.memo.PlanMemo`); what this plan asks is kept in it.
    elsewhere : another place may hold a seam (a positioner's other poses): one whose transfer fails and that no
        transfer joins to home either way is refused at once (:mod:`cell.planning.access.home`), not tried from
        every other seam in turn; and the order search leaves out a transfer that no strategy makes between the
        planned lines before searching it in full (:mod:`cell.planning.access.screen`).
    Raises PlanError when q_home is outside the limits or in collision; a seam that cannot be planned is a
    SeamOutcome with ``feasible=False``, its code and its reason, never an exception.
    """
    t_start = time.perf_counter()
    opt = options or PlanOptions()
    q0 = np.asarray(q_home, dtype=float)
    if q0.shape != (robot.dof,) or not robot.limits.contains(q0):
        raise PlanError(f"home configuration {np.round(np.degrees(q0), 2).tolist()} deg is outside the joint limits")
    checker = checker or CollisionChecker(robot, obstacles, opt.collision)
    hit = checker.check(q0)
    if hit is not None:
        raise PlanError(f"home configuration is in collision: {hit.describe()}")
    rng = rng or np.random.default_rng(0)
    chosen = dict(procedures or {})
    outcomes: dict[str, SeamOutcome] = {}
    solved: dict[str, tuple[SeamSolution, ...]] = {}  # per pass
    searches: dict[str, SeamSearch] = {}
    reach = reach_model(robot)
    table_z = table_top(obstacles, opt.collision.table_name)
    trims: dict[str, float] = {}  # seam id -> the stand-off [m] it is welded from at its table end
    for n_done, task in enumerate(tasks, 1):
        if on_seam is not None and n_done > 1:
            on_seam(n_done - 1, len(tasks))
        sel = chosen.get(task.id)
        if isinstance(sel, NoProcedure):
            outcomes[task.id] = _failed(task.id, PlanReason.NO_PROCEDURE, sel.reason, task.p_start)
            continue
        search = searches[task.id] = SeamSearch(robot, seam_process(process, sel), checker, opt, rng, reach)
        found = search.plan_seam(sel.oriented(task) if sel else task, q0)
        if isinstance(found, SeamFailure) and table_z is not None:
            short = shortened_plan(search, task, found, table_z, opt, sel, q0)
            if short is not None:
                found, trims[task.id] = short
        res = found if isinstance(found, SeamFailure) or sel is None else solve_passes(search, found, sel.procedure)
        if isinstance(res, SeamFailure):
            outcomes[task.id] = _failed(task.id, res.code, res.where, res.p_R)
        else:
            solved[task.id] = res if isinstance(res, tuple) else (res,)
    if on_seam is not None and tasks:
        on_seam(len(tasks), len(tasks))
    found_curves = weldable(curves)
    for curve in found_curves:
        sel = chosen.get(curve.id)
        if isinstance(sel, NoProcedure):
            outcomes[curve.id] = _failed(curve.id, PlanReason.NO_PROCEDURE, sel.reason, curve.p_RS[0])
            continue
        searches[curve.id] = SeamSearch(
            robot, seam_process(process, sel), checker, opt, rng, reach, memo.ik if memo else None
        )
    curve_ids = {e.id for e in found_curves if e.id not in outcomes}
    curve_procs = {i: p.procedure for i, p in chosen.items() if isinstance(p, SeamProcedure)}
    to_search = [e for e in found_curves if e.id in curve_ids]
    arcs, still, in_parts, spans = cover_curves(to_search, searches, q0, curve_procs, refused)  # one go, arcs, part
    for cid, res in still.items():
        outcomes[cid] = _failed(cid, res.code, res.where, res.p_R)
    for aid, sols in arcs.items():  # each arc welded as an open curve of its own, the seam's search and procedure
        solved[aid], searches[aid] = sols, searches[seam_of(aid)]
        if seam_of(aid) in chosen:
            chosen[aid] = chosen[seam_of(aid)]
        curve_ids.add(aid)

    transfers = Transfers(robot, process, checker, opt, obstacles, q0, WAYS, memo.transfers if memo else None)
    seam_parts: dict[str, list[Piece]] = {}
    for sid in list(solved):
        sel = chosen.get(sid)
        proc = sel.procedure if isinstance(sel, SeamProcedure) else None
        try:
            pr = searches[sid].process
            timed = curve_lines if sid in curve_ids else seam_pieces
            parts: list[Piece] | TransferFail = (
                curve_pieces(robot, pr, opt, solved[sid][0], None)  # one pass, the controller's crater
                if sid in curve_ids and proc is None
                else pass_pieces(robot, pr, opt, transfers, solved[sid], proc, timed)
            )
        except TimingError as exc:
            sols = solved.pop(sid)
            outcomes[sid] = _failed(sid, PlanReason.TIMING, exc.message, sols[0].X_weld[0][:3, 3])
            continue
        if isinstance(parts, TransferFail):
            solved.pop(sid)
            detail = f"no free move between two passes: {parts.reason}"
            outcomes[sid] = _failed(sid, PlanReason.TRANSFER_COLLISION, detail, parts.p_R)
            continue
        seam_parts[sid] = parts
    whole_or_none(solved, outcomes, seam_parts, parts=in_parts)
    ends = {sid: (sols[0].q_approach[0], sols[-1].q_depart[-1]) for sid, sols in solved.items()}
    lines = {sid: seam_lines(sols[0], sols[-1], process, opt.short_lines) for sid, sols in solved.items()}
    seam_procs = {sid: sel.procedure for sid, sel in chosen.items() if isinstance(sel, SeamProcedure)}
    forbidden = _expand(avoid, solved)
    failed_out: set[tuple[str, str]] = set()  # the transfers (from, to) found with no free way so far
    while True:
        ids = list(solved)
        order = seam_order(ids, [ends[i][0] for i in ids], [ends[i][1] for i in ids], q0, robot, forbidden, first)
        ordered = [ids[k] for k in order]
        # elsewhere: a transfer no strategy makes between the planned lines is left out before any full search
        failed = first_unjoined(transfers, ordered, lines, q0, forbidden) if elsewhere and len(ids) > 1 else None
        if failed is None:
            segments, failed = assemble(transfers, ordered, lines, seam_parts, q0, seam_procs)
            if failed is None:
                break
        a, b, why = failed
        failed_out.add((a, b))
        fault = exit_at_fault(a, b, failed_out, in_parts)  # the move out of arc a failed towards two places
        if fault and transfers.retreat_from([e.q for e in lines[a].exits], RETREATS):  # other ways out of it
            forbidden -= {(x, y) for x, y in forbidden if x == a} - _expand(avoid, solved)
            continue
        again = (a, b) not in forbidden and len(ids) > 1  # another order may do without this transfer
        cut = first_cut_off(transfers, lines, q0, (b, a)) if elsewhere and again else None
        if cut is None and again:
            forbidden.add((a, b))  # try an order without this transfer first
            continue
        drop = b or a  # the seam this transfer leads to (or, on the way home, comes from)
        move = f"transfer move {'to' if b else 'from'} the seam"
        if cut is not None:
            (drop, why), move = cut, "transfer move between home and the seam, either way"
        solved.pop(drop)
        detail = f"no free {move}: {why.reason}"
        outcomes[drop] = _failed(drop, PlanReason.TRANSFER_COLLISION, detail, why.p_R)
        whole_or_none(solved, outcomes, parts=in_parts)  # a seam's other arcs with it (a partial seam's: that arc)
    if opt.blend > 0.0:
        segments = blend_plan(
            segments, robot.limits, lambda q: robot.fk(q)[:3, 3], transfers.clear, fraction=opt.blend, dt=opt.dt
        )
    segments = with_paths(segments, {sid: [p.X_weld for p in solved[sid]] for sid in curve_ids if sid in solved})
    welded_in_part = {sid for sid, part in in_parts.items() if part.remainder}
    timed_arcs = arc_spans(segments, {aid: s for aid, s in spans.items() if aid in solved}, welded_in_part)
    segments = [replace(g, seam_id=seam_of(g.seam_id)) for g in segments]  # a split seam's arcs: its welds
    for sid, sols in solved.items():
        c, pr, sel = sols[0].cand, searches[sid].process, chosen.get(sid)
        swapped = isinstance(sel, SeamProcedure) and sel.reverse  # the search saw the task's ends swapped
        outcomes[sid] = SeamOutcome(
            sid,
            True,
            "",
            np.zeros(0),
            c.reversed != swapped,
            c.spin,
            pr.work_angle + c.work_offset,
            pr.travel_angle + c.travel_offset,
            trimmed=trims.get(sid, 0.0),
        )
    for aid in sorted(a for a in solved if a != seam_of(a)):  # a split seam: feasible, as its first arc
        sid = seam_of(aid)
        if sid not in outcomes or not outcomes[sid].feasible:
            n = sum(seam_of(a) == sid for a in solved)
            outcomes[sid] = replace(outcomes[aid], seam_id=sid, reason=f"welded in {n} arcs" if n > 1 else "")
            if sid in in_parts and in_parts[sid].remainder:  # welded in part: what is left for a manual weld
                outcomes[sid] = in_part(outcomes[sid], in_parts[sid], n)
    return WeldPlan(
        joint_names=robot.joint_names,
        q_home=readonly(q0),
        segments=tuple(segments),
        seams=tuple(outcomes[i] for i in [*(t.id for t in tasks), *(e.id for e in found_curves)]),
        order=tuple(dict.fromkeys(seam_of(i) for i in ordered)),
        planning_s=time.perf_counter() - t_start,
        arcs=timed_arcs,
    )


def unplaceable(
    robot: RobotModel,
    tasks: Sequence[SeamTask],
    q_home: npt.ArrayLike,
    process: WeldProcess,
    checker: CollisionChecker,
    *,
    options: PlanOptions | None = None,
    procedures: Mapping[str, SeamProcedure | NoProcedure] | None = None,
    table_z: float | None = None,
) -> dict[str, SeamFailure]:
    """Seam id -> the failure :func:`plan_welds` would give (its code, where), for the seams no torch can be placed
    on (out of reach, or the torch against a part or the table at a weld end for every candidate): found without
    IK, the same search's first steps with the same process per seam. A seam with no procedure is not judged here."""
    reach, opt, chosen = reach_model(robot), options or PlanOptions(), procedures or {}
    q0 = np.asarray(q_home, dtype=float)
    out: dict[str, SeamFailure] = {}
    for task in tasks:
        sel = chosen.get(task.id)
        if isinstance(sel, NoProcedure):
            continue
        search = SeamSearch(robot, seam_process(process, sel), checker, opt, np.random.default_rng(0), reach)
        fail = search.placeable(sel.oriented(task) if sel else task, q0)
        if fail is not None and table_z is not None and blocked_by_table(fail, opt.collision.table_name):
            orient = sel.oriented if sel else as_is
            if stand_off(search, task, table_z, opt.table_stand_off_max, orient, q0) is not None:
                fail = None  # placed from the table stand-off, as plan_welds would
        if fail is not None:
            out[task.id] = fail
    return out


def reach_model(robot: RobotModel) -> ReachModel | None:
    """The arm's reach pre-check (:mod:`cell.planning.reach`, about 10 ms to build), None for an arm it does not
    fit (no spherical wrist, other frame names): the search then goes straight to IK."""
    try:
        return ReachModel.from_robot(robot)
    except (ValueError, MotionError):
        return None


def _expand(avoid: Collection[tuple[str, str]], solved: Collection[str]) -> set[tuple[str, str]]:
    """The transfers (from, to; "" = home) ``avoid`` names, a curved seam's named as each of its arcs in ``solved``."""
    pieces = {sid: [k for k in solved if seam_of(k) == sid] or [sid] for pair in avoid for sid in pair if sid}
    return {(x, y) for a, b in avoid for x in pieces.get(a, [a]) for y in pieces.get(b, [b])}


def _failed(seam_id: str, code: PlanReason, detail: str, p_R: npt.ArrayLike) -> SeamOutcome:
    return SeamOutcome(seam_id, False, reason_text(code, detail), readonly(p_R), code=code)


__all__ = ["plan_welds", "reach_model", "unplaceable"]
