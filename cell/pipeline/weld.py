"""Welding: plan the found seams, run the safety gate, drive the arm, and say what became of every seam."""

from __future__ import annotations

import time
from collections.abc import Callable, Collection, Sequence
from contextlib import nullcontext
from dataclasses import replace
from functools import partial
from typing import TYPE_CHECKING

import numpy as np

from cell.errors import CellError, PlanError, ScenarioError
from cell.geometry import FloatArray
from cell.journal import NO_LOG, SideLog
from cell.pipeline.curved import curve_seam_welds, curves_to_plan
from cell.pipeline.curved.rescan import curves_rescanned
from cell.pipeline.detect import AlignStart, Progress, detect, quiet, read_weldmap
from cell.pipeline.geometry import MotionScene, motion_scene, open_cell
from cell.pipeline.job import WeldJob
from cell.pipeline.last_check import joined, last_checked
from cell.pipeline.outcomes import doubt, seam_welds, torch_paths
from cell.pipeline.placeable import curve_procedures_for, joint_parts, rescan_weldable, seam_procedures
from cell.pipeline.playback import Measure, log_detection, log_plan, measurer, play_by_seam
from cell.pipeline.progress import seam_counter
from cell.pipeline.records import Detection, WeldRun
from cell.pipeline.restrict import restricted
from cell.pipeline.scene_view import cell_view
from cell.scenario import Scenario
from cell.station import Station
from cell.types import CheckFail, SeamStatus, Violation, ViolationKind
from cell.types.plan import PlanReason, Remainder

TackRule = Callable[[Detection, Sequence["SeamTask"]], Sequence["SeamTask"]]  # seam tasks -> tack tasks (tacks.py)

if TYPE_CHECKING:
    from cell.planning.failures import SeamFailure
    from cell.types.curve_estimate import CurveEstimate
    from cell.types.execution import Execution
    from cell.types.plan import SeamOutcome, SeamTask, WeldPlan
    from cell.types.rescan import PlannedCloseup
    from cell.types.trajectory import Trajectory


def plan_for(
    station: Station,
    det: Detection,
    *,
    skip: Collection[str] = (),
    q_start: FloatArray | None = None,
    motion: MotionScene | None = None,
    progress: Progress = quiet,
    tacks: TackRule | None = None,
    curves: Sequence[CurveEstimate] = (),
    elsewhere: bool = False,
) -> tuple[WeldPlan, Trajectory, tuple[Violation, ...]]:
    """Plan the found seams of a detection (but those in ``skip``) and run the safety gate (docs/reference.md
    section 7).

    q_start : where the arm is now (default: its scan configuration). motion : the run's obstacles and checker
    (built here when not given). Returns the plan, the move from q_start to
    home that precedes it, and the gate's violations (empty when the plan may run). PlanError when nothing can be
    planned at all.
    tacks : the tack welds to lay first (:mod:`cell.pipeline.tacks`, from the seam tasks): welded before every
        seam, each with its seam's procedure; the plan's outcomes list them after the seams (an arm on a track
        lays none).
    curves : located curved seams (in R) to weld too (:func:`cell.planning.plan.plan_welds`; on a track too).
    elsewhere : another pose may hold a seam (a positioner's): :func:`~cell.planning.plan.plan_welds`'s.
    """
    from cell.gate import find_violations
    from cell.gate.answer import gate_answer
    from cell.motion.timing import ptp
    from cell.pipeline.tacks import tack_procedures
    from cell.planning.curves.split import seam_of
    from cell.planning.plan import plan_welds
    from cell.planning.tasks import seam_tasks
    from cell.planning.track import plan_on_track
    from cell.planning.transfers import TransferFail, Transfers, joined
    from cell.process.torch import WeldProcess

    sc = det.scenario
    arm = station.arm
    if arm is None:
        raise ScenarioError(f"scenario {sc.name!r} has no robot to weld with: set robot.urdf and robot.X_WR")
    if det.scene is None:
        raise PlanError(f"nothing to plan: the detection of {sc.name!r} kept no scene ({det.error})")
    ss = det.scene.seam_scene
    tasks = seam_tasks([e for e in det.estimates if e.id not in skip], ss.weldmap, ss.joints, ss.table_z)
    motion = motion or motion_scene(arm, det)
    obstacles, checker = motion.obstacles, motion.checker
    track = sc.robot.track.track(sc.X_WR) if sc.robot.track is not None else None
    tack_tasks = tuple(tacks(det, tasks)) if tacks is not None and track is None else ()
    progress(
        f"planning {len(tasks)} seams{f' and {len(tack_tasks)} tacks' if tack_tasks else ''} (IK, timing, collisions)"
    )
    process = WeldProcess.from_spec(sc.process, sc.robot.stickout_mm)
    q_now = arm.q_scan if q_start is None else q_start
    problems: list[Violation] = []
    # The move home takes the transfers' ways (direct, lifted over the parts): a close-up view can leave the
    # torch low between parts, where the direct move collides. When no way is free, nothing can move: the whole
    # plan is refused (the start state, not a seam).
    way = Transfers(arm.model, process, checker, sc.motion.plan, obstacles, arm.q_home).move(q_now, arm.q_home)
    if isinstance(way, TransferFail):
        pre = ptp(q_now, arm.q_home, arm.model.limits, dt=0.001)
        why = f"move from the arm's position to home collides whichever way: {way.reason}"
        problems.append(Violation(ViolationKind.COLLISION, why, 0.0))
    else:
        pre = joined(way) if way else ptp(q_now, arm.q_home, arm.model.limits, dt=0.001)
    dropped: dict[str, SeamOutcome] = {}
    avoid: set[tuple[str, str]] = set()  # transfers the gate found at fault: another order is tried first
    refused: dict[str, list[Remainder]] = {}  # curved seam -> its arcs' stretches the gate found at fault
    for _ in range(_GATE_ROUNDS):
        kept = [t for t in tasks if t.id not in dropped]
        kept_tacks = [t for t in tack_tasks if t.id not in dropped]
        procs = seam_procedures(sc, det, kept) | curve_procedures_for(sc, ss.weldmap, curves)
        first = {t.id for t in kept_tacks}  # the tacks before every seam
        fixed = partial(plan_welds, first=first, elsewhere=elsewhere, avoid=set(avoid), refused=dict(refused))
        planner = fixed if track is None else partial(plan_on_track, track=track)
        plan = planner(
            arm.model,
            [*kept, *kept_tacks],
            arm.q_home,
            process,
            obstacles,
            options=sc.motion.plan,
            rng=sc.rng("plan"),
            checker=checker,
            procedures=procs | tack_procedures(procs, kept_tacks),
            on_seam=seam_counter(progress) if not dropped and not avoid and not refused else None,
            curves=[c for c in curves if c.id not in dropped],
        )
        progress(
            "safety gate: limits at 1 kHz, collisions along the path, singularities, arc at exact stops, the wire"
            " clear of every part's body"
        )
        found = find_violations(
            arm.model,
            plan,
            arm.q_home,
            checker=checker,
            options=sc.motion.gate,
            bodies=ss.weldmap.parts,  # no TCP or wire inside a part's body (the aligned map's)
            wire_m=process.stickout,
            joint_parts=joint_parts(ss.joints, [t.id for t in (*kept, *kept_tacks)], ss.weldmap, curves),
        )
        # Another order first for a move into a seam; an arc of a curve welded in arcs left out alone (its stretch
        # for a manual weld, with the gate's reason); else the seam dropped (at most _GATE_ROUNDS plans in all).
        manual = process.curve_remainder == "manual" and track is None
        got = gate_answer(plan, found, avoid, by_arc=manual, reorder=track is None)
        if got is None:  # none, or one that concerns the whole plan
            break
        if got.moves:
            progress(f"safety gate: {', '.join(got.moves)} again in another order (the move into it violates it)")
            avoid |= set(got.moves.values())
        if got.arcs:
            progress(f"safety gate: leaving out {', '.join(got.arcs)} (its own motions violate it), planning the rest")
            for aid, r in got.arcs.items():
                refused.setdefault(seam_of(aid), []).append(r)
        if got.drop:
            progress(f"safety gate: dropping {', '.join(got.drop)} (their own motions violate it), planning the rest")
            dropped.update(got.drop)
    outcomes = {o.seam_id: o for o in plan.seams} | dropped
    ids = [*(t.id for t in (*tasks, *tack_tasks)), *(c.id for c in curves)]
    plan = replace(plan, seams=tuple(outcomes[i] for i in ids if i in outcomes))
    problems += found
    return plan, pre, tuple(problems)


_GATE_ROUNDS = 6  # plans tried: after the fifth round of other orders and drops the gate's word is final


def execute(
    station: Station,
    plan: WeldPlan,
    pre: Trajectory,
    *,
    progress: Progress = quiet,
    log: SideLog = NO_LOG,
    measure: Measure | None = None,
) -> Execution:
    """Drive the simulated arm: the move from the scan pose to home, then the welding program; arc where planned,
    seam by seam, each weld's arc on and off in the journal (``log``; ``measure``: its TCP error, where known)."""
    traj, arc = plan.joint_trajectory()
    times = np.concatenate([pre.times, traj.times[1:] + pre.duration])
    q = np.concatenate([pre.q, traj.q[1:]])
    arc_on = np.concatenate([np.zeros(len(pre.times), bool), arc[1:]])
    marks = [(0.0, "move scan -> home")] + [
        (pre.duration + seg.t0, f"{seg.kind} {seg.seam_id}".strip()) for seg in plan.segments
    ]
    progress(f"executing {plan.cycle_time + pre.duration:.1f} s of robot motion in the simulator")
    e1 = None if traj.e1 is None else np.concatenate([np.zeros(len(pre.times)), traj.e1[1:]])  # the track's E1
    return play_by_seam(station, times, q, arc_on, marks, e1, plan, pre.duration, log, measure or (lambda *_: None))


def weld(
    scenario: Scenario,
    job: WeldJob | None = None,
    *,
    progress: Progress = quiet,
    station: Station | None = None,
    start: AlignStart | None = None,
    only: Collection[str] | None = None,
    tacks: TackRule | None = None,
    log: SideLog = NO_LOG,
    done: Collection[str] = (),
) -> WeldRun:
    """The whole cell: capture, detect, re-scan up close, plan, gate and (unless ``job.execute`` is False: a
    preview) weld. ``job`` (:class:`~cell.pipeline.job.WeldJob`; None: as the scenario says) overrides the
    scenario's locator, noise and ``rescan.mode``; its ``sides`` is :func:`cell.pipeline.turnover.weld_part`'s.

    A failure after detection (planning, the gate) does not lose the detection: it is returned in ``error`` with
    every seam's reason, so the report can still be written. A seam whose confidence stays below
    ``rescan.weld_min_confidence``, or whose bound (``rescan.bound_sigmas`` times its calibrated sigma) stays over
    ``rescan.weld_tolerance_mm``, after the re-scan is not welded (``low_confidence``); nor is one whose end bound
    (``rescan.bound_sigmas`` times an end's sigma along the seam) stays over ``rescan.end_tolerance_mm``
    (``end_uncertain``).

    station : a running cell to weld on (left open; built and closed here when None). start : where the map's
    alignment starts (a turned part's nominal pose and a search near it). only : the seam ids this run is about
    (a second side's: the others are neither re-scanned, planned nor reported). tacks : tack welds laid before
    the seams (:func:`plan_for`). log : the job's journal, from this side (docs/journal.md). done : seams an
    earlier run of the job welded (a resume): neither re-scanned, planned nor reported.
    """
    t_all = time.perf_counter()
    job = job or WeldJob()
    sc = scenario.with_noise(job.noise) if job.noise else scenario
    if job.rescan is not None:  # the override is what ran: the report's configuration says so
        sc = sc.model_copy(update={"rescan": sc.rescan.model_copy(update={"mode": job.rescan})})
    execute_plan = job.execute
    weldmap = read_weldmap(sc)
    with open_cell(sc, weldmap, gui=job.gui) if station is None else nullcontext(station) as station:
        X_RM, seed = (start.X_RM, start.seed) if start is not None else (None, None)
        det = detect(sc, job.method, progress=progress, station=station, weldmap=weldmap, X_RM_nominal=X_RM, seed=seed)
        if only is not None or done:
            det = restricted(det, set(only if only is not None else (e.id for e in det.estimates)) - set(done))
        log_detection(log, det)
        first, rs = det, None
        timings = dict(det.timings)
        plan = pre = ex = None
        violations: tuple[Violation, ...] = ()
        error: CellError | None = None
        hopeless: dict[str, SeamFailure] = {}  # seams no torch can be placed on (not re-scanned; the plan says why)
        closeups: tuple[PlannedCloseup, ...] = ()  # a preview's: the views the re-scan would take
        checked: dict[str, CheckFail] = {}  # seams that failed the last check before the arc, re-scanned or not
        try:
            if det.error is not None:
                raise det.error
            if station.arm is None:
                raise ScenarioError(f"scenario {sc.name!r} has no robot to weld with: set robot.urdf and robot.X_WR")
            t = time.perf_counter()
            motion = motion_scene(station.arm, det)  # once: every re-scan view, the plan and the gate use it
            setup_s = time.perf_counter() - t
            mode = sc.rescan.mode
            if mode != "none" and execute_plan:
                rs, det, hopeless = rescan_weldable(station, det, mode, motion=motion, progress=progress)
                rs, det = curves_rescanned(
                    station, det, rs, mode=mode, motion=motion, progress=progress
                )  # E1 back at 0
                if sc.robot.track is not None:  # out of reach at E1 = 0 only: the track may bring it in reach
                    hopeless = {i: f for i, f in hopeless.items() if f.code is not PlanReason.BEYOND_REACH}
                if rs is not None:
                    timings["rescan_s"] = rs.timings.get("rescan_s", 0.0)
            if mode != "none" and not execute_plan:  # a preview plans the close-ups it cannot take
                from cell.pipeline.closeup_plan import preview_closeups
                from cell.pipeline.curved.rescan import preview_curve_closeups

                progress("planning the close-up views cell weld would take (the arm does not move)")
                closeups = preview_closeups(station, det, mode, motion)
                closeups += preview_curve_closeups(station, det, motion, closeups, mode)
            if execute_plan:  # the last check before the arc: re-scanned, then refused (cell/pipeline/last_check.py)
                det, more, checked = last_checked(station, det, skip=hopeless, motion=motion, progress=progress)
                rs = joined(rs, more)
                if rs is not None:
                    timings["rescan_s"] = rs.timings.get("rescan_s", 0.0)
            # A preview moves nothing, so it cannot re-scan: it plans doubtful seams too and says so. A seam no
            # torch can be placed on is planned too: the planner refuses it with its own reason.
            low = {
                e.id
                for e in det.estimates
                if e.status is SeamStatus.FOUND and doubt(e, sc) is not None and execute_plan and e.id not in hopeless
            }
            t = time.perf_counter()
            q_start = rs.q_end if rs is not None else None
            curves = curves_to_plan(det, skip=list(checked))
            straight = any(e.status is SeamStatus.FOUND and e.id not in low for e in det.estimates)
            if (low or done) and not straight and not curves:
                progress(f"nothing to weld: all {len(low)} found seams too uncertain (low_confidence)" if low else
                         "nothing left to weld on this side: the journal's earlier runs welded it")  # fmt: skip
            else:
                plan, pre, violations = plan_for(
                    station,
                    det,
                    skip=low | set(checked),
                    q_start=q_start,
                    motion=motion,
                    progress=progress,
                    tacks=tacks,
                    curves=curves,
                )
                timings["plan_s"] = setup_s + time.perf_counter() - t
                if violations:
                    from cell.gate import GateRefusedError

                    why = f"the safety gate refused the plan: {violations[0]} (+{len(violations) - 1} more)"
                    raise GateRefusedError(why, violations=violations)
                log_plan(log, plan)
                if execute_plan:
                    t = time.perf_counter()
                    ex = execute(station, plan, pre, progress=progress, log=log, measure=measurer(det, plan, pre, sc))
                    timings["execute_s"] = time.perf_counter() - t
        except CellError as e:
            error = e
            log.write("side_error", type=type(e).__name__, message=e.message, exit_code=e.exit_code)
        refused = f"not executed: {error.message}" if error is not None else ""
        pre_s = pre.duration if pre is not None else 0.0
        seams = seam_welds(det, plan, ex, pre_s, refused, sc, execute_plan, hopeless, checked)
        det = replace(det, curve_welds=curve_seam_welds(det, plan, ex, pre_s, refused))
        if closeups:
            from cell.pipeline.closeup_plan import with_closeups

            seams = with_closeups(seams, closeups)
            det = replace(det, curve_welds={w.id: w for w in with_closeups(tuple(det.curve_welds.values()), closeups)})
        paths = torch_paths(station, plan) if plan is not None else {}
        timings["total_s"] = time.perf_counter() - t_all
        view = cell_view(sc, station.arm, plan, pre, ex)
        return WeldRun(
            detection=det,
            seams=seams,
            plan=plan,
            pre_move=pre,
            execution=ex,
            violations=violations,
            error=error,
            timings=timings,
            torch_paths=paths,
            arm=station.arm,
            first_detection=first,
            rescan=rs,
            view=view,
            closeups=closeups,
        )
