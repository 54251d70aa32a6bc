"""Welding: plan the found seams, run the safety gate, drive the arm, and say what became of every seam."""

from __future__ import annotations

import time
from collections.abc import Collection
from contextlib import nullcontext
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from cell.errors import CellError, ScenarioError
from cell.journal import NO_LOG, SideLog
from cell.pipeline.curved import curve_seam_welds, curves_to_plan
from cell.pipeline.curved.rescan import curves_rescanned
from cell.pipeline.detect import AlignStart, Progress, detect, quiet, read_weldmap
from cell.pipeline.gated import TackRule, plan_for
from cell.pipeline.geometry import motion_scene, open_cell
from cell.pipeline.job import WeldJob
from cell.pipeline.last_check import joined, last_checked
from cell.pipeline.outcomes import doubt, seam_welds, torch_paths
from cell.pipeline.placeable import rescan_weldable
from cell.pipeline.playback import Measure, log_detection, log_plan, measurer, play_by_seam
from cell.pipeline.records import WeldRun
from cell.pipeline.restrict import restricted
from cell.pipeline.scene_view import cell_view
from cell.scenario import Scenario
from cell.station import Station
from cell.types import CheckFail, SeamStatus, Violation
from cell.types.plan import PlanReason

if TYPE_CHECKING:
    from cell.planning.failures import SeamFailure
    from cell.types.execution import Execution
    from cell.types.plan import WeldPlan
    from cell.types.rescan import PlannedCloseup
    from cell.types.trajectory import Trajectory


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
