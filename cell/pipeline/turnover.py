"""The whole part welded (docs/flip.md): side A as ``cell weld`` does it, then, when seams are left
against the table, the turn planned from the aligned map (before anything moves), the part turned over by the
operator, and side B: capture again, align the map from its nominal turned pose (a search of the cloud near it
first: the operator's placement error is not known), locate, re-scan, plan, gate and weld the seams the turn
exposed."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from cell.errors import CellError, UsageError
from cell.geometry import FloatArray, invert, transform_points
from cell.journal import NO_LOG, SideLog
from cell.perception.align.near_pose import near_seed
from cell.pipeline.detect import AlignStart, Progress, quiet, read_weldmap, table_z_R
from cell.pipeline.geometry import open_cell
from cell.pipeline.job import WeldJob
from cell.pipeline.records import Detection, WeldRun
from cell.pipeline.tacks import Tack, choose_tacks, tack_records, tacks_time_s
from cell.pipeline.turnover_run import TurnoverRun
from cell.pipeline.weld import weld
from cell.scenario import Scenario
from cell.station import Station
from cell.types import SeamStatus, WeldMap
from cell.types.plan import SeamTask
from cell.types.turnover import TurnoverPlan, TurnoverResult


def table_box_R(sc: Scenario) -> tuple[FloatArray, FloatArray]:
    """The table top's (min, max) corners (3,) in R [m]."""
    c, size = np.asarray(sc.table.center_m), np.asarray(sc.table.size_m)
    corners = c + np.array([[sx, sy, 0.5] for sx in (-0.5, 0.5) for sy in (-0.5, 0.5)]) * size
    p = transform_points(invert(sc.X_WR), corners)
    return p.min(axis=0), p.max(axis=0)


def plan_turn(run: WeldRun) -> TurnoverPlan | None:
    """The turn for the seams side A left against the table (None when none is left), from side A's aligned map."""
    return _turn_for(run.detection)


def _turn_for(det: Detection) -> TurnoverPlan | None:
    """:func:`plan_turn` from side A's detection (before its welds are planned: the tacks depend on it)."""
    from cell.planning.turnover import plan_turnover

    left = [e.id for e in det.estimates if e.status is SeamStatus.NOT_VISIBLE]
    if not left:
        return None
    sc = det.scenario
    X_RM = det.scene.X_RM if det.scene is not None else invert(sc.X_WR) @ sc.X_WM
    return plan_turnover(
        det.weldmap_R,
        det.joints,
        table_z_R(sc),
        left,
        X_RM,
        allowed=sc.flip.allowed,
        max_tilt_rad=math.radians(sc.flip.max_tilt_deg),
        table_xy=table_box_R(sc),
    )


def turnover_result(plan: TurnoverPlan, run: WeldRun, weldmap_M: WeldMap) -> TurnoverResult | None:
    """The placement the second alignment measured against the plan's nominal turned pose: the shift of the
    part's centre and the turn about the vertical (None: no alignment)."""
    scene = run.detection.scene
    if scene is None:
        return None
    from cell.planning.turnover import pivot

    # The part's centre (the middle of its extent, the turn's pivot) at its nominal turned place and where found.
    nominal_c = pivot(weldmap_M.transformed(plan.X_RM_after, "R"))
    D = scene.X_RM @ invert(plan.X_RM_after)
    found_c = transform_points(D, nominal_c)
    rotation = math.atan2(float(D[1, 0]), float(D[0, 0]))
    offset = float(np.linalg.norm((found_c - nominal_c)[:2]))
    return TurnoverResult(offset, rotation, scene.alignment.fitness, scene.X_RM)


def weld_part(
    scenario: Scenario,
    job: WeldJob | None = None,
    *,
    progress: Progress = quiet,
    log: SideLog = NO_LOG,
    done: Collection[str] = (),
    turned: Mapping[str, Any] | None = None,
) -> TurnoverRun:
    """The whole part: side A (:func:`cell.pipeline.weld.weld`), then with ``job.sides == "all"`` the turn and
    side B (``job``: :class:`~cell.pipeline.job.WeldJob`; None: as the scenario says).

    A preview (``job.execute`` False) moves nothing: it plans side A and the turn, and shows side B's seams at
    their nominal turned place. The turn is not made when side A stopped with an error, when the scenario forbids
    it (``flip.allowed``), or when no stable turn exposes a seam left: the seams keep their reason. A failure on
    side B (an ambiguous second alignment, the gate) is side B's ``error``: nothing of side B is welded, the
    report is still written.

    log : the job's journal (docs/journal.md). A resume (``done``: the seams earlier runs welded, never welded
    again; ``turned``: the journal's ``turned`` record when the part was turned) captures and aligns again and
    welds the rest, on side B alone when the part was turned (the simulator first turns it as that run did).
    """
    t_all = time.perf_counter()
    job = job or WeldJob()
    if scenario.robot.positioner is not None:  # the positioner turns the part, not an operator
        raise UsageError(
            f"scenario {scenario.name!r} clamps its part on robot.positioner: weld it with"
            f" cell.pipeline.positioned.weld_on_positioner (what `cell weld {scenario.name}` runs; no operator turn)"
        )
    sc = scenario.with_noise(job.noise) if job.noise else scenario
    side_a = replace(job, noise=None)  # the noise is in the scenario now
    weldmap = read_weldmap(sc)
    chosen: list[Tack] = []
    spec = sc.flip.tacks
    both = job.sides == "all"
    with open_cell(sc, weldmap, gui=job.gui) as station:
        if turned is not None:  # a resume after the turn: side B's seams left
            b = _resumed_b(station, sc, side_a, turned, weldmap, progress, log.on("B"), done)
            return TurnoverRun(b, timings={"total_s": time.perf_counter() - t_all})
        # Tacks only when asked for and the part will be turned (not again on a resume).
        rule = tack_rule(spec.count, spec.length_mm / 1000.0, chosen) if spec.count and both and not done else None
        a = weld(sc, side_a, progress=progress, station=station, tacks=rule, log=log.on("A"), done=done)
        plan = plan_turn(a) if both else None
        if plan is None:
            return TurnoverRun(a, timings={"total_s": time.perf_counter() - t_all})
        refused = f"not executed: {a.error.message}" if a.error is not None else ""
        base = TurnoverRun(
            a,
            plan,
            operator_s=sc.flip.operator_s,
            positioner_turn_s=_positioner_s(plan),
            tacks_s=tacks_time_s(a.plan) if chosen else 0.0,
            turned_map=weldmap.transformed(plan.X_RM_after, "R"),
            tacks=tack_records(chosen, a.plan, a.execution is not None, refused),
        )

        def ended(**fields: Any) -> TurnoverRun:
            return replace(base, timings={"total_s": time.perf_counter() - t_all}, **fields)

        if not plan.go:
            progress(f"no turn: {plan.reason}")
            return ended()
        if not job.execute or a.error is not None:  # a preview moves nothing; a failed side A is not turned
            return ended(error=a.error if job.execute else None)
        try:
            b = _side_b(station, sc, side_a, plan, weldmap, progress, log.on("B"), done)
        except CellError as e:  # the station cannot turn the part (a recording): side A's run stands, with why
            return ended(error=e)
        return ended(side_b=b, result=turnover_result(plan, b, weldmap))


def _positioner_s(plan: TurnoverPlan) -> float:
    """What a positioner's axis would take for the turn [s] (:mod:`cell.planning.positioner`)."""
    from cell.planning.positioner import positioner_turn_s

    return positioner_turn_s(plan.angle_rad)


def tack_rule(
    count: int, length_m: float, chosen: list[Tack]
) -> Callable[[Detection, Sequence[SeamTask]], Sequence[SeamTask]]:
    """The tacks side A lays (:func:`cell.pipeline.gated.plan_for`'s ``tacks``): ``count`` of ``length_m`` on its
    seams (:func:`cell.pipeline.tacks.choose_tacks`, each pair of parts its first tack before any gets a second)
    when the turn will be made, none otherwise; what it chose is put in ``chosen`` (the run's record of them)."""

    def rule(det: Detection, tasks: Sequence[SeamTask]) -> Sequence[SeamTask]:
        turn = _turn_for(det)
        chosen.clear()
        if turn is not None and turn.go:
            pairs = {i: f"{j.abutting}>{j.receiving}" for i, j in det.joints.items()}
            chosen.extend(choose_tacks(tasks, count, length_m, pairs))
        return [t.task for t in chosen]

    return rule


def _side_b(
    station: Station,
    sc: Scenario,
    job: WeldJob,
    plan: TurnoverPlan,
    weldmap: WeldMap,
    progress: Progress,
    log: SideLog,
    done: Collection[str],
) -> WeldRun:
    """Turn the part (the operator) and weld the seams the turn exposed."""
    X_WR = sc.X_WR
    progress(
        f"operator: turn the part {math.degrees(plan.angle_rad):+.0f} deg about its {plan.axis} axis "
        f"for {len(plan.exposed)} seams ({', '.join(plan.exposed)})"
    )
    station.turn_part(X_WR @ plan.X_R_turn @ invert(X_WR))  # the nominal turn, carried from R into W
    log.write(
        "turned",
        axis=plan.axis,
        rotation_deg=round(math.degrees(plan.angle_rad), 3),
        tilt_deg=round(math.degrees(plan.tilt_rad), 3),
        exposed=list(plan.exposed),
        X_R_turn=np.round(plan.X_R_turn, 9),
        X_RM_after=np.round(plan.X_RM_after, 9),
    )
    start = AlignStart(plan.X_RM_after, near_seed(weldmap, table_z_R(sc)))
    return weld(sc, job, progress=progress, station=station, start=start, only=plan.exposed, log=log, done=done)


def _resumed_b(
    station: Station,
    sc: Scenario,
    job: WeldJob,
    turned: Mapping[str, Any],
    weldmap: WeldMap,
    progress: Progress,
    log: SideLog,
    done: Collection[str],
) -> WeldRun:
    """Side B of a resumed job whose part was turned: the simulated part turned as the journal says (a real part
    lies where the operator left it), captured, aligned from its nominal turned pose, its seams left welded."""
    X_WR = sc.X_WR
    progress(f"resuming on side B: the part was turned {turned['rotation_deg']:+.0f} deg about {turned['axis']}")
    station.turn_part(X_WR @ np.asarray(turned["X_R_turn"], float) @ invert(X_WR))
    X_RM_after = np.asarray(turned["X_RM_after"], float)
    start = AlignStart(X_RM_after, near_seed(weldmap, table_z_R(sc)))
    return weld(sc, job, progress=progress, station=station, start=start, only=turned["exposed"], log=log, done=done)
