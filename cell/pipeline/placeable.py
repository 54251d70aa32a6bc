"""Which found seams no torch can be placed on (:func:`unweldable`), so the arm spends no close-up re-scan on
them (:func:`rescan_weldable`): the planner would refuse them whatever the close-up found (out of reach, or the
torch against a part or the table at a weld end for every torch orientation the process allows; a few mm of seam
position change neither). And the weld procedure of every task (:func:`seam_procedures`)."""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from typing import TYPE_CHECKING

import numpy as np

from cell.pipeline.detect import Progress, quiet
from cell.pipeline.geometry import MotionScene
from cell.pipeline.records import Detection
from cell.pipeline.rescan import RescanMode, end_shift_m, escalated, rescan_detection
from cell.rescan import seams_to_rescan
from cell.scenario import Scenario
from cell.station import Arm, Station

if TYPE_CHECKING:
    from cell.motion.failures import SeamFailure
    from cell.motion.process.procedures import NoProcedure, SeamProcedure
    from cell.types.plan import SeamTask
    from cell.types.rescan import Rescan


def unweldable(arm: Arm, det: Detection, seam_ids: Collection[str], motion: MotionScene) -> dict[str, SeamFailure]:
    """Seam id -> the planner's failure (its code, where), for those of ``seam_ids`` (found seams only) no torch
    can be placed on."""
    from cell.motion.plan import seam_tasks, unplaceable
    from cell.motion.process.torch import WeldProcess

    if det.scene is None:
        return {}
    sc, ss = det.scenario, det.scene.seam_scene
    wanted = [e for e in det.estimates if e.id in seam_ids]
    tasks = seam_tasks(wanted, ss.weldmap, ss.joints, ss.table_z)
    process = WeldProcess.from_spec(sc.process, sc.robot.stickout_mm)
    procs = seam_procedures(sc, det, tasks)
    return unplaceable(
        arm.model,
        tasks,
        arm.q_home,
        process,
        motion.checker,
        options=sc.motion.plan,
        procedures=procs,
        table_z=ss.table_z,  # a seam the table stand-off lets a torch reach is placeable, as the planner has it
    )


def seam_procedures(sc: Scenario, det: Detection, tasks: Sequence[SeamTask]) -> dict[str, SeamProcedure | NoProcedure]:
    """The weld procedure of every task (the scenario's WPS table, or its one row from ``process:``): by the
    joint type the aligned map gives, the position against gravity in R, the leg ``process.leg_mm`` (or
    ``process.seam_leg_mm`` of the seam)."""
    from cell.motion.process.procedures import joint_type, select_procedures

    ss = det.scene.seam_scene if det.scene is not None else None
    kinds = {t.id: joint_type(ss.weldmap, ss.joints[t.id]) for t in tasks if ss and t.id in ss.joints}
    legs = {t.id: sc.process.seam_leg_mm.get(t.id, sc.process.leg_mm) for t in tasks}
    up_R = np.asarray(sc.X_WR[:3, :3]).T @ np.array([0.0, 0.0, 1.0])  # against gravity (W's z) in R
    return select_procedures(tasks, kinds, legs, sc.weld_procedures(), up_R)


def rescan_weldable(
    station: Station,
    det: Detection,
    mode: RescanMode,
    *,
    motion: MotionScene,
    progress: Progress = quiet,
) -> tuple[Rescan | None, Detection, dict[str, SeamFailure]]:
    """:func:`~cell.pipeline.rescan.rescan_detection` without the seams no torch can be placed on: neither the
    mode's choice nor an escalation re-scans them. Returns the re-scan (None when nothing was left to re-scan),
    the detection after it, and those seams (id -> the planner's failure)."""
    sc = det.scenario
    arm = station.arm
    if arm is None:  # rescan_detection says so
        return (*rescan_detection(station, det, mode, motion=motion, progress=progress), {})
    threshold = math.inf if mode == "all" else sc.rescan.confidence_threshold
    chosen = seams_to_rescan(det.estimates, threshold, sc.rescan.max_sigma_m, sc.rescan.max_end_sigma_m)
    hopeless = _hopeless(arm, det, chosen, motion, progress)
    ids = [i for i in chosen if i not in hopeless]
    if mode == "all" or not hopeless:  # nothing left out: rescan_detection's own selection and escalation
        rs, after = rescan_detection(station, det, mode, seam_ids=ids, motion=motion, progress=progress)
        return rs, after, hopeless
    if not ids:
        return None, det, hopeless
    # "all" with the seams given: the same re-scan, without its escalation (done here, without the hopeless)
    rs, after = rescan_detection(station, det, "all", seam_ids=ids, motion=motion, progress=progress)
    shift_mm = max((end_shift_m(r.before, r.closeup) * 1000.0 for r in rs.seams if r.used), default=0.0)
    rest = [i for i in seams_to_rescan(after.estimates, math.inf) if i not in ids and i not in hopeless]
    if shift_mm <= sc.rescan.escalate_mm or not rest:
        return rs, after, hopeless
    more_hopeless = _hopeless(arm, after, rest, motion, progress)
    hopeless |= more_hopeless
    rest = [i for i in rest if i not in more_hopeless]
    if not rest:
        return rs, after, hopeless
    progress(
        f"a close-up moved its seam {shift_mm:.2f} mm from the fixed cameras' estimate: re-scanning the other"
        f" {len(rest)} seams a torch can be placed on too"
    )
    more, after = rescan_detection(station, after, "all", seam_ids=rest, motion=motion, progress=progress)
    return escalated(rs, more, shift_mm), after, hopeless


def _hopeless(
    arm: Arm, det: Detection, ids: Sequence[str], motion: MotionScene, progress: Progress
) -> dict[str, SeamFailure]:
    """:func:`unweldable` of ``ids``, said on ``progress`` when there are any."""
    found = unweldable(arm, det, ids, motion)
    if found:
        progress(f"not re-scanning {len(found)} of {len(ids)} seams no torch can be placed on (planned to say why)")
    return found
